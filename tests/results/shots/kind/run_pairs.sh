#!/bin/sh
# Each listed robustness scene optimised as shipped (per_frame) and with controls.kind per_step, nothing else
# changed; one line per run in pairs.csv. Scenes with substeps > 1 only (at one substep the kinds coincide).
#   sh tests/results/shots/kind/run_pairs.sh KEYFRAME SCENE_NAME...
set -e
keyframe=$1; shift
here=$(dirname "$0")
work=$(mktemp -d)
echo "scene,kind,miss_before_cm,miss_after_cm,evaluations,seconds,exit" > "$here/pairs.csv"
for name in "$@"; do
  for kind in per_frame per_step; do
    python3 -c "import json,sys; d=json.load(open('scenes/robustness/$name.json')); d.pop('\$schema',None); d['controls']['kind']='$kind'; json.dump(d,open('$work/$name-$kind.json','w'),indent=1)"
    rc=0
    nice -n 10 "$keyframe" --threads 1 optimize "$work/$name-$kind.json" --out "$work/$name-$kind" --quiet > /dev/null 2>&1 || rc=$?
    cp "$work/$name-$kind/report.json" "$here/$name-$kind.report.json"
    python3 -c "
import json; r=json.load(open('$here/$name-$kind.report.json')); e=r['keyframe_errors']
print('$name,$kind,' + ' '.join('%.2f' % k.get('miss_before', float('nan')) for k in e) + ',' + ' '.join('%.2f' % k.get('miss_after', float('nan')) for k in e)
      + ',%s,%.1f,$rc' % (r.get('evaluations', ''), r.get('seconds', r.get('wall_seconds', 0))))" >> "$here/pairs.csv"
  done
done
rm -rf "$work"
