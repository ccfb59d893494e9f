#!/usr/bin/env python3
"""Prints columns of a CSV as the README's markdown table.

Usage: scripts/csv_table.py FILE 'COLUMN|HEADER|FORMAT' ...
  FORMAT is printf-style (%.3f, %.2g, %d) or s for the text as it is; COLUMN may be a/b for a ratio."""
import csv, sys

if len(sys.argv) < 3:
    raise SystemExit(__doc__)
rows = list(csv.DictReader(open(sys.argv[1])))
specs = [s.split("|") for s in sys.argv[2:]]
for s in specs:
    if len(s) != 3:
        raise SystemExit(f"csv_table.py: expected COLUMN|HEADER|FORMAT, got {'|'.join(s)!r}")


def cell(row, column, fmt):
    if "/" in column:
        a, b = column.split("/")
        value = float(row[a]) / float(row[b])
    elif fmt == "s":
        return row[column]
    else:
        value = float(row[column]) if row[column] != "" else None
    if value is None:
        return "–"
    return fmt % (int(round(value)) if fmt.endswith("d") else value)


print("| " + " | ".join(h for _, h, _ in specs) + " |")
print("|" + "---|" * len(specs))
for r in rows:
    print("| " + " | ".join(cell(r, c, f) for c, _, f in specs) + " |")
