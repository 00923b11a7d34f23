#!/usr/bin/env bash
# The batch on many processes (issue 14, item 6): the ten bundled tuber scans through
# `clumpforge batch` as one process with one thread, under `mpirun -np 1` and `-np 2` with one
# thread per rank (the MPI layer's own scaling), and as one process with every core (threads);
# the speed-ups measured in this one run, the population bytes compared, and each stage's cost
# per scan (median over the scans, from the items' stage_seconds). Not a test: timings on a
# shared machine are noisy; run it on an idle one.
#
#   bash bench/bench_batch.sh [BUILD_DIR] [OUT_DIR] [-- extra batch options]
# Writes OUT_DIR/summary.md and OUT_DIR/summary.json (default bench-out/batch).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
out="${2:-$here/bench-out/batch}"
shift $(( $# >= 2 ? 2 : $# ))
[ "${1:-}" = "--" ] && shift
cli="$build/tools/clumpforge"
[ -x "$cli" ] || { echo "bench_batch: no $cli (build first)" >&2; exit 1; }
command -v mpirun > /dev/null || { echo "bench_batch: no mpirun (apt-get install openmpi-bin)" >&2; exit 1; }
# Open MPI refuses root and more ranks than cores unless told; set here, for this benchmark only.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# The study's clumps and tests, at fewer trials: every stage of an item, ten scans in minutes.
options=(--diameters 2mm,4mm --budgets 64 --validate lattice-2mm,adaptive-64 --tests drop,tilt,roll
         --surfaces Q235,soil --trials 4 --seed 1 "$@")
scans=("$here"/meshes/tuber-[0-9][0-9].stl)
rm -rf "$out" && mkdir -p "$out"
run() {  # name, command...
  local name=$1; shift
  local start end
  start=$(date +%s.%N)
  "$@" "${scans[@]}" -o "$out/$name" "${options[@]}" > "$out/$name.log" 2>&1 || [ $? -eq 3 ]
  end=$(date +%s.%N)
  echo "$name $(echo "$end - $start" | bc)" >> "$out/times.txt"
  echo "bench_batch: $name $(echo "$end - $start" | bc) s" >&2
}
run plain-1thread "$cli" batch --threads 1
run np1-1thread mpirun -np 1 "$cli" batch --threads 1
run np2-1thread mpirun -np 2 "$cli" batch --threads 1
run plain-threads "$cli" batch
/usr/bin/python3 - "$out" "${#scans[@]}" "$(nproc)" "$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)" <<'PY'
import json, statistics, sys, pathlib, filecmp
out, n, cores, commit = pathlib.Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
times = dict((l.split()[0], float(l.split()[1])) for l in (out / "times.txt").read_text().split("\n") if l)
same = all(filecmp.cmp(out / "plain-1thread" / f, out / r / f, shallow=False)
           for r in times if r != "plain-1thread" for f in ("library.h5", "population.csv", "population.json"))
stages = {}
for item in sorted((out / "np2-1thread" / "items").glob("*.json")):
    for stage, s in json.load(open(item)).get("stage_seconds", {}).items():
        key = "dem " + stage.split()[1].split("/")[0] + " " + stage.split("/")[1] if stage.startswith("dem ") else stage
        stages.setdefault(key, []).append(s)
summary = {
    "commit": commit, "scans": n, "cores": cores, "seconds": times,
    "speedup_np2_over_np1": times["np1-1thread"] / times["np2-1thread"],
    "speedup_np2_over_one_thread": times["plain-1thread"] / times["np2-1thread"],
    "speedup_threads_over_one_thread": times["plain-1thread"] / times["plain-threads"],
    "mpi_overhead_np1_over_plain": times["np1-1thread"] / times["plain-1thread"],
    "same_bytes": same,
    "stage_median_seconds_per_scan": {k: statistics.median(v) for k, v in sorted(stages.items())},
}
(out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
lines = [f"# clumpforge batch: {n} scans, {cores} cores (commit {commit})", "",
         "| run | wall [s] |", "|---|---:|"] + [f"| {k} | {v:.1f} |" for k, v in times.items()] + [
         "", f"speed-up -np 2 over -np 1 (one thread per rank): {summary['speedup_np2_over_np1']:.2f}x",
         f"speed-up -np 2 over one process with one thread: {summary['speedup_np2_over_one_thread']:.2f}x",
         f"speed-up of one process's threads over one thread: {summary['speedup_threads_over_one_thread']:.2f}x",
         f"mpirun -np 1 against a plain run: {summary['mpi_overhead_np1_over_plain']:.3f}x the time",
         f"population bytes identical in every run: {same}", "",
         "| stage | median per scan [s] |", "|---|---:|"] + [
         f"| {k} | {v:.3f} |" for k, v in summary["stage_median_seconds_per_scan"].items()]
(out / "summary.md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
PY
