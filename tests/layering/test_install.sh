#!/bin/bash
# Installs the build to a temporary prefix, then builds and runs examples/consumer against
# it as another project would (find_package(clumpforge CONFIG REQUIRED)), and checks what
# was installed: headers under include/clumpforge/ only, the CMake package, the command
# line and the Python package.   test_install.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$1 build_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build_dir" --prefix "$prefix" > "$work/install.log"

# Headers: only <prefix>/include/clumpforge/*.hpp.
stray=$(find "$prefix/include" -type f ! -path "$prefix/include/clumpforge/*.hpp")
[ -z "$stray" ] || { echo "files outside include/clumpforge/: $stray"; exit 1; }
for h in clumpforge core error run_context units mesh fill dem io; do
  [ -f "$prefix/include/clumpforge/$h.hpp" ] || { echo "missing include/clumpforge/$h.hpp"; exit 1; }
done
# Each installed header compiles alone, with the standard library and the prefix only.
for h in "$prefix"/include/clumpforge/*.hpp; do
  echo "#include <clumpforge/$(basename "$h")>" | g++ -std=c++23 -nostdinc++ -isystem /usr/include/c++/12 \
    -isystem /usr/include/x86_64-linux-gnu/c++/12 -I"$prefix/include" -fsyntax-only -x c++ - \
    || { echo "$h does not compile alone"; exit 1; }
done
[ -f "$prefix/lib/cmake/clumpforge/clumpforgeConfig.cmake" ] || { echo "no clumpforgeConfig.cmake"; exit 1; }

cmake -S "$source_dir/examples/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log"
cmake --build "$work/consumer" > "$work/build.log"
mkdir "$work/export"
out=$("$work/consumer/consumer" "$source_dir/meshes/tuber-default.stl" "$work/export")
echo "$out"
grep -q "^clumpforge [0-9]" <<< "$out"
grep -q "^clump adaptive-" <<< "$out"
[ -f "$work/export/$(sed -n 's/^clump \([^:]*\):.*/\1/p' <<< "$out").multisphere" ]
grep -q "^drop on Q235, 2 trials" <<< "$out"

# The installed command line runs from the prefix and finds its libraries there.
"$prefix/bin/clumpforge" --version
# (ldd's output kept first: with pipefail, grep -q quitting early would fail the pipe on SIGPIPE)
linked=$(ldd "$prefix/bin/clumpforge")
grep -q "libclumpforge_core.so => $prefix/" <<< "$linked" \
  || { echo "installed clumpforge does not use the installed libraries"; exit 1; }
# The installed Python package imports from the prefix alone.
if [ -d "$prefix/lib/python3/dist-packages/clumpforge" ]; then
  PYTHONPATH="$prefix/lib/python3/dist-packages" /usr/bin/python3 -c \
    "import clumpforge, os; assert clumpforge.__file__.startswith('$prefix'), clumpforge.__file__; print('python', clumpforge.__file__)"
fi
echo "install: ok"
