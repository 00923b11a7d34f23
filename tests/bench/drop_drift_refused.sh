#!/bin/bash
# An absurd --drop-drift is refused by bench_diagnose and by clumpforge diagnose with a message
# naming the option, a non-zero exit, and nothing written to the output folder.
set -u
bench=$1 clumpforge=$2 recordings=$3 library=$4
out=$(mktemp -d)/never-made
for bad in rest "" after_impact; do
  err=$("$bench" --drop-drift "$bad" --controls 0 --generate-only -o "$out" 2>&1 >/dev/null)
  if [ $? -eq 0 ]; then echo "bench --drop-drift '$bad': exit 0"; exit 1; fi
  case "$err" in *--drop-drift*) ;; *) echo "bench --drop-drift '$bad': message does not name the option: $err"; exit 1 ;; esac
  err=$("$clumpforge" diagnose --recordings "$recordings" --library "$library" --drop-drift "$bad" --output "$out" 2>&1 >/dev/null)
  if [ $? -eq 0 ]; then echo "diagnose --drop-drift '$bad': exit 0"; exit 1; fi
  case "$err" in *--drop-drift*) ;; *) echo "diagnose --drop-drift '$bad': message does not name the option: $err"; exit 1 ;; esac
  if [ -e "$out" ]; then echo "--drop-drift '$bad': $out was written"; exit 1; fi
done
echo ok
