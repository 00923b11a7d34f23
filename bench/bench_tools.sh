# Sourced by the bench scripts after they shift off their own arguments: reads an optional
# BUILD_DIR and a "--" from the script's remaining arguments (what is left is bench_diagnose's
# options), and sets build, cli and bench, checked to exist. $here is the project's root and
# $script the caller's name, for its messages.
build="$here/build"
if [ $# -ge 1 ] && [ "$1" != "--" ]; then build=$1; shift; fi
[ "${1:-}" = "--" ] && shift
cli="$build/tools/clumpforge"
bench="$build/bench/bench_diagnose"
for f in "$cli" "$bench"; do [ -x "$f" ] || { echo "$script: no $f (build first)" >&2; exit 1; }; done
