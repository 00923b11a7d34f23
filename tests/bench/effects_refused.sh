#!/bin/bash
# bench_diagnose refuses an --effects name the library lacks (a comma-separated list is split, so
# its second name is checked too) with a message naming the option and the name, a non-zero exit,
# and nothing written to its output folder. Before, an unknown name (or a comma-separated list
# read as one name) picked no effect and the run made controls only.
set -u
bench=$1
out=$(mktemp -d)/never-made
for bad in "viscous_rollin" "air_drag,elastic_plastc_restitution" "air_drag elastic_plastc_restitution"; do
  # shellcheck disable=SC2086  # the space-separated form is two words on purpose
  err=$("$bench" --effects $bad --controls 0 --generate-only -o "$out" 2>&1 >/dev/null)
  code=$?
  if [ "$code" -eq 0 ]; then echo "--effects $bad: exit 0"; exit 1; fi
  case "$err" in *--effects*) ;; *) echo "--effects $bad: message does not name the option: $err"; exit 1 ;; esac
  case "$err" in *_rollin\'*|*plastc_restitution\'*) ;; *) echo "--effects $bad: message does not name the unknown effect: $err"; exit 1 ;; esac
  if [ -e "$out" ]; then echo "--effects $bad: $out was written"; exit 1; fi
done
echo ok
