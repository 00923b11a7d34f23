#!/bin/bash
# bench_diagnose's count of missed effects whose report gives a smallest detectable magnitude at
# or below the concealed one (a detection limit the truth contradicts), on stored reports
# (--existing-only). The generated strong adhesion hides a work of adhesion of 0.4 J/m^2.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
case_dir() {  # name effect verdict hypotheses-json
  mkdir -p "$dir/out/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/out/$1/answer.json"
  printf '{"verdict":"%s","undecidable":[],"hypotheses":%s,"seconds":1,"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n' \
    "$3" "$4" >"$dir/out/$1/report.json"
}
score() {
  "$bench" -o "$dir/out" --full-set --controls 1 --existing-only 2>&1 | grep "smallest detectable magnitude"
}
case_dir air_drag-strong air_drag air_drag '[{"name":"air_drag","smallest_detectable":0.1}]'
case_dir adhesion-strong adhesion none '[{"name":"adhesion","smallest_detectable":0.23}]'
line=$(score)
case "$line" in *": 1/1") ;; *) echo "expected 1/1 (0.23 claimed, 0.4 hidden and missed): $line"; exit 1 ;; esac
case_dir adhesion-strong adhesion none '[{"name":"adhesion","smallest_detectable":0.6}]'
line=$(score)
case "$line" in *": 0/1") ;; *) echo "expected 0/1 (0.6 claimed, above the 0.4 hidden): $line"; exit 1 ;; esac
case_dir adhesion-strong adhesion none '[{"name":"adhesion","smallest_detectable":null}]'
line=$(score)
case "$line" in *": 0/1") ;; *) echo "expected 0/1 (no figure given): $line"; exit 1 ;; esac
# An `ambiguous` verdict with the concealed effect among its candidates is counted as such (not
# named right, not an overclaim); one without it is not.
ambiguous() {  # candidates-json
  printf '{"verdict":"ambiguous","candidates":%s,"undecidable":[],"hypotheses":[],"seconds":1,"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n' \
    "$1" >"$dir/out/adhesion-strong/report.json"
  "$bench" -o "$dir/out" --full-set --controls 1 --existing-only 2>&1 | grep "as .ambiguous. with"
}
line=$(ambiguous '["adhesion","viscous_rolling"]')
case "$line" in *": 1/1") ;; *) echo "expected 1/1 (adhesion among the candidates): $line"; exit 1 ;; esac
line=$(ambiguous '["viscoelastic_restitution","elastic_plastic_restitution"]')
case "$line" in *": 0/1") ;; *) echo "expected 0/1 (adhesion not among them): $line"; exit 1 ;; esac
echo ok
