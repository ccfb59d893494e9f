#!/bin/sh
# A run directory replayed from controls.bin (evaluations.bin removed), one evaluation each: under the step
# schedule the run stored (schedule.bin) and without it (chosen anew, as before it was stored). Prints one CSV row
# per directory: the worst keyframe's miss in tolerances, the objective, and whether trajectory.bin is the run's.
#   sh tests/results/reachable/replay/replay.sh tests/results/reachable/scenes/drop-collider-9.json OUT > tests/results/reachable/replay/drop-collider-9.csv
set -e
K=${KEYFRAME:-build/release/keyframe}
scene=$1
out=$2
rm -rf "$out"
mkdir -p "$out"
"$K" --threads 1 optimize "$scene" --quiet --out "$out/run" >/dev/null 2>&1 || true
for v in with-schedule without-schedule; do
  cp -r "$out/run" "$out/$v"
  rm -f "$out/$v/evaluations.bin"
  if [ "$v" = without-schedule ]; then rm -f "$out/$v/schedule.bin"; fi
  "$K" --threads 1 optimize --resume "$out/$v" --quiet --max-evaluations 1 >"$out/$v.out" 2>&1 || true
done
python3 - "$out" "$(git rev-parse --short HEAD)" <<'PY'
import hashlib, json, os, sys
out, commit = sys.argv[1], sys.argv[2]
def sha(p):
    return hashlib.sha256(open(p, "rb").read()).hexdigest()[:16]
run_traj = sha(os.path.join(out, "run", "trajectory.bin"))
print("commit,directory,schedule,worst_miss_tolerances,final_objective,trajectory_sha,trajectory_is_the_runs")
held = {"run": "the run's own", "with-schedule": "schedule.bin", "without-schedule": "chosen anew"}
for d in ["run", "with-schedule", "without-schedule"]:
    r = json.load(open(os.path.join(out, d, "report.json")))
    worst = max(k["miss_after"] for k in r["keyframe_errors"] if k.get("judged", True))
    t = sha(os.path.join(out, d, "trajectory.bin"))
    print(f"{commit},{d},{held[d]},{worst:.4g},{r['final_objective']:.10g},{t},{'yes' if t == run_traj else 'no'}")
PY
