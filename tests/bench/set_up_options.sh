#!/bin/bash
# bench_diagnose refuses --nine-set-ups with --full-set (two layouts at once): a clear message
# naming both, a non-zero exit, and no output folder.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
if "$bench" --nine-set-ups --full-set --controls 1 -o "$dir/out" >"$dir/log" 2>&1; then
  echo "expected a refusal"; cat "$dir/log"; exit 1
fi
grep -q -- "--nine-set-ups" "$dir/log" && grep -q -- "--full-set" "$dir/log" || { echo "message:"; cat "$dir/log"; exit 1; }
[ ! -e "$dir/out" ] || { echo "output written on refusal"; exit 1; }
echo ok
