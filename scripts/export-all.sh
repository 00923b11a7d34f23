# Sourced by main.sh and make-clumps.sh: export_all LIBRARY CLUMP DIR writes the clump in
# every format under DIR/CLUMP/ with one naming scheme.
export_all() {
  local cf=${CF:-build/tools/clumpforge} lib=$1 clump=$2 dir=$3/$2
  mkdir -p "$dir"
  $cf export "$lib" --clump "$clump" --format liggghts -o "$dir/$clump.multisphere" > /dev/null
  $cf export "$lib" --clump "$clump" --format yade -o "$dir/$clump.yade.txt" > /dev/null
  $cf export "$lib" --clump "$clump" --format edem -o "$dir/$clump.edem.tsv" > /dev/null
  $cf export "$lib" --clump "$clump" --format pfc -o "$dir/$clump.p3dat" > /dev/null
  $cf export "$lib" --clump "$clump" --format mercurydpm -o "$dir/mercurydpm" > /dev/null
  $cf export "$lib" --clump "$clump" --format chrono -o "$dir/$clump.chrono.csv" > /dev/null
  $cf export "$lib" --clump "$clump" --format vtk -o "$dir/$clump.vtp" > /dev/null
  $cf export "$lib" --clump "$clump" --format csv -o "$dir/$clump.csv" > /dev/null
}
