#!/usr/bin/env bash
# Optimises the scenes below with one keyframe binary and prints, per scene, its exit code and the sha256 of
# controls.bin and trajectory.bin (first 16 hex digits). Run with the binary before and after a change that
# must not change results, and compare the two outputs (strategy_move.csv holds one such comparison).
# Usage: tests/results/architecture/strategy_outputs.sh BINARY OUT_ROOT   (from the repository's root)
set -u
bin=$1; root=$2; mkdir -p "$root"
echo "scene,exit,controls_sha256_16,trajectory_sha256_16"
for s in scenes/square.json scenes/cross.json scenes/path.json scenes/arch.json scenes/shapes.json scenes/race.json \
         scenes/robustness/throw-over-bar.json scenes/robustness/drop-sphere.json scenes/robustness/flag-released.json \
         scenes/robustness/towel-rail.json scenes/robustness/flock-star.json scenes/robustness/flock-l-shape.json \
         scenes/robustness/curtain-released.json; do
  n=$(basename "$s" .json); rm -rf "${root:?}/$n"
  nice -n 10 "$bin" optimize "$s" --out "$root/$n" --quiet > "$root/$n.stdout" 2>&1; rc=$?
  c=$(sha256sum "$root/$n/controls.bin" 2>/dev/null | cut -c1-16); t=$(sha256sum "$root/$n/trajectory.bin" 2>/dev/null | cut -c1-16)
  echo "$s,$rc,$c,$t"
done
