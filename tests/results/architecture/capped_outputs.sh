#!/usr/bin/env bash
# Optimises every shipped scene (scenes/*.json) and every robustness scene (scenes/robustness/*.json) with two
# keyframe binaries, both at once scene by scene, each run capped at EVALS evaluations per stage
# (--max-evaluations; default 6) and TIMEOUT seconds of wall time (default 600; a run cut there is "timeout"
# and its scene is not compared). Prints per scene the exit codes and the sha256 of controls.bin and
# trajectory.bin (first 16 hex digits) of both, and whether all three agree (keyframe_kinds.csv holds one
# such comparison).
# Usage: [SCENES="a.json b.json ..."] [SIDES=before|after] tests/results/architecture/capped_outputs.sh BEFORE AFTER OUT_ROOT [EVALS] [TIMEOUT]
# (from the repository's root; SCENES sets the order, e.g. the quick ones first). SIDES=before runs only the
# BEFORE binary (printing no rows), so it can start while AFTER is still being built; a later SIDES=after
# with the same OUT_ROOT runs the other and prints the rows. By default both run at once, scene by scene.
set -u
before=$1; after=$2; root=$3; evals=${4:-6}; limit=${5:-600}; mkdir -p "$root"
echo "scene,evaluations_cap,exit_before,exit_after,controls_sha256_16_before,controls_sha256_16_after,trajectory_sha256_16_before,trajectory_sha256_16_after,identical"
run() {  # binary scene out: prints "exit,controls,trajectory"
  rm -rf "${3:?}"
  nice -n 10 timeout -k 20 "$limit" "$1" optimize "$2" --out "$3" --max-evaluations "$evals" --quiet > "$3.stdout" 2>&1
  local rc=$?
  { [ $rc = 124 ] || [ $rc = 137 ]; } && rc=timeout  # 137: killed 20 s after the timeout's TERM
  echo "$rc,$(sha256sum "$3/controls.bin" 2>/dev/null | cut -c1-16),$(sha256sum "$3/trajectory.bin" 2>/dev/null | cut -c1-16)"
}
for s in ${SCENES:-scenes/*.json scenes/robustness/*.json}; do
  [ "$(basename "$s")" = scene.schema.json ] && continue
  n=$(echo "$s" | tr / _ | sed 's/\.json$//')
  case ${SIDES:-both} in
    before) run "$before" "$s" "$root/before_$n" > "$root/before_$n.row"; continue ;;
    after) run "$after" "$s" "$root/after_$n" > "$root/after_$n.row" ;;
    *) run "$before" "$s" "$root/before_$n" > "$root/before_$n.row" &
       run "$after" "$s" "$root/after_$n" > "$root/after_$n.row"
       wait ;;
  esac
  IFS=, read -r e0 c0 t0 < "$root/before_$n.row"
  IFS=, read -r e1 c1 t1 < "$root/after_$n.row"
  same=no
  [ "$e0" = timeout ] || [ "$e1" = timeout ] && same=not_compared
  [ "$e0" = "$e1" ] && [ "$c0" = "$c1" ] && [ "$t0" = "$t1" ] && [ "$e0" != timeout ] && same=yes
  echo "$s,$evals,$e0,$e1,$c0,$c1,$t0,$t1,$same"
done
