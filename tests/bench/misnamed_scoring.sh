#!/bin/bash
# bench_diagnose counts the effects named as another effect (a wrong cause given to the user), on
# stored reports (--existing-only), in both scorers: a name that is not the concealed effect
# counts; an ambiguous verdict, a `none`, a right name (a speed-dependent restitution is right
# under either law on an independent set) and a control named as an effect (counted apart) do
# not.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
report='{"verdict":"%s","candidates":[],"undecidable":[],"seconds":1,"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n'
case_dir() {  # name effect verdict
  mkdir -p "$dir/gen/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/gen/$1/answer.json"
  printf "$report" "$3" >"$dir/gen/$1/report.json"
}
case_dir elastic_plastic_restitution-strong elastic_plastic_restitution static_kinetic_friction
case_dir adhesion-strong adhesion ambiguous
case_dir air_drag-strong air_drag air_drag
case_dir control-01 none air_drag
"$bench" -o "$dir/gen" --full-set --controls 1 --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "effects named as another effect" "$dir/gen/summary.md")
expected="effects named as another effect (a wrong name): 1/3 (elastic_plastic_restitution (strong) as static_kinetic_friction)"
[ "$line" = "$expected" ] || { echo "generated: $line"; exit 1; }
# An independent set scored with --recordings-set.
for c in a b c d; do mkdir -p "$dir/set/case-$c" "$dir/out/case-$c"; done
printf '{"cases":{"case-a":{"effect":"speed_restitution"},"case-b":{"effect":"adhesion"},"case-c":{"effect":"none"},"case-d":{"effect":"air_drag"}}}\n' \
  >"$dir/set/ANSWERS.json"
printf "$report" elastic_plastic_restitution >"$dir/out/case-a/report.json"
printf "$report" viscous_rolling >"$dir/out/case-b/report.json"
printf "$report" air_drag >"$dir/out/case-c/report.json"
printf "$report" none >"$dir/out/case-d/report.json"
"$bench" --recordings-set "$dir/set" -o "$dir/out" --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "effects named as another effect" "$dir/out/summary.md")
[ "$line" = "effects named as another effect (a wrong name): 1/3 (case-b as viscous_rolling)" ] ||
  { echo "recordings set: $line"; exit 1; }
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
assert s["effects_named_as_another"] == [{"case": "case-b", "verdict": "viscous_rolling"}], s["effects_named_as_another"]
assert s["controls_named"] == 1, s["controls_named"]
PY
echo ok
