# Shared by the scorer tests (sourced; needs $bench and $dir): score stored reports with
# --existing-only and read one summary line back; and a one-case set that diagnoses at once.

# score_generated OUT: the generated-set scorer over OUT (a --full-set run with 2 controls).
score_generated() {
  "$bench" -o "$1" --full-set --controls 2 --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
}

# two_case_set: an independent set (case-a a control, case-b air drag) in $dir/set, its reports'
# folders in $dir/out.
two_case_set() {
  for c in a b; do mkdir -p "$dir/set/case-$c" "$dir/out/case-$c"; done
  printf '{"cases":{"case-a":{"effect":"none"},"case-b":{"effect":"air_drag"}}}\n' >"$dir/set/ANSWERS.json"
}

# score_set: the --recordings-set scorer over two_case_set's reports.
score_set() {
  "$bench" --recordings-set "$dir/set" -o "$dir/out" --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
}

# expect_line FILE PREFIX EXPECTED: FILE's line starting with PREFIX is EXPECTED.
expect_line() {
  local line
  line=$(grep "^$2" "$1")
  [ "$line" = "$3" ] || { echo "$1: $line"; exit 1; }
}

# short_drop_case SET CASE MESH: SET/CASE, one drop of MESH (copied to SET/meshes) whose one track
# is too short to decide anything, so diagnosed `undecidable` at once.
short_drop_case() {
  mkdir -p "$1/meshes" "$1/$2/drop"
  cp "$3" "$1/meshes/sphere.stl"
  cat >"$1/$2/drop/recording.json" <<'JSON'
{"format": "recording/1", "test": "drop", "surface": "Q235",
 "particle": {"mesh": "../../meshes/sphere.stl", "mesh_units": "mm", "density_kg_m3": 1085.0},
 "setup": {"release_height_m": 0.2}, "camera": {"frame_rate_hz": 1000},
 "trials": [{"id": "01", "track": "trial-01.csv"}]}
JSON
  printf 't_s,x_m,z_m\n0.000,0,0.21\n0.001,0,0.21\n' >"$1/$2/drop/trial-01.csv"
}
