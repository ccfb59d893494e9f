#!/usr/bin/env python3
"""The stiff-throw stability cases as a CSV, from what their tests print.

  build/release/keyframe_tests --gtest_filter='StiffThrownSheets/*:ClothLargeStep.*' | scripts/large_step_table.py OUT.csv

Reads the lines `NAME: S substeps for 72 steps, highest energy E J from E0 J` (step splitting on) and
`NAME without splitting: failed at N, highest energy E J from E0 J` (off; N = -1: did not fail), with NAME
x<stiffer>_<fps>fps_<pinned|free>_<body>. Writes one row per case: case, stiffer, fps, pinned, body,
splitting (1/0), substeps, substeps_per_step, failed_at, highest_j, start_j, energy_ratio (highest / start).
Exits 3 when the input has no such line or a test failed."""
import csv, re, sys

NAME = r"x(?P<stiffer>\d+)_(?P<fps>\d+)fps_(?P<pinned>pinned|free)_(?P<body>\w+)"
ON = re.compile(NAME + r": (?P<substeps>\d+) substeps for (?P<steps>\d+) steps, highest energy (?P<high>\S+) J from (?P<start>\S+) J")
OFF = re.compile(NAME + r" without splitting: failed at (?P<failed>-?\d+), highest energy (?P<high>\S+) J from (?P<start>\S+) J")

if len(sys.argv) != 2:
    print(__doc__)
    sys.exit(2)
text = sys.stdin.read()
if "[  FAILED  ]" in text:
    print("scripts/large_step_table.py: a test failed; no table written", file=sys.stderr)
    sys.exit(3)
rows = []
for line in text.splitlines():
    m = ON.match(line) or OFF.match(line)
    if not m:
        continue
    on = m.re is ON
    high, start = float(m["high"]), float(m["start"])
    rows.append({
        "case": line.split(":")[0], "stiffer": m["stiffer"], "fps": m["fps"], "pinned": int(m["pinned"] == "pinned"),
        "body": m["body"], "splitting": int(on),
        "substeps": m["substeps"] if on else "", "substeps_per_step": f"{int(m['substeps']) / int(m['steps']):.2f}" if on else "",
        "failed_at": "" if on else m["failed"], "highest_j": f"{high:.6g}", "start_j": f"{start:.6g}",
        "energy_ratio": f"{high / start:.6g}"})
if not rows:
    print("scripts/large_step_table.py: no case lines in the input", file=sys.stderr)
    sys.exit(3)
with open(sys.argv[1], "w", newline="") as out:
    w = csv.DictWriter(out, list(rows[0]), lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
