#!/bin/bash
# bench_diagnose refuses an absurd --finer-clumps with a message naming the option, a non-zero
# exit, and nothing written to its output folder.
set -u
bench=$1
out=$(mktemp -d)/never-made
for bad in 9 -1 many; do
  err=$("$bench" --finer-clumps "$bad" -o "$out" 2>&1 >/dev/null)
  code=$?
  if [ "$code" -eq 0 ]; then echo "--finer-clumps $bad: exit 0"; exit 1; fi
  case "$err" in *--finer-clumps*) ;; *) echo "--finer-clumps $bad: message does not name the option: $err"; exit 1 ;; esac
  if [ -e "$out" ]; then echo "--finer-clumps $bad: $out was written"; exit 1; fi
done
echo ok
