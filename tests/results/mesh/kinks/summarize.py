#!/usr/bin/env python3
"""One row per probe of the kink tool (tests/sim/kink_probe_tool_test.cpp): how far along the negative gradient phi
follows its slope, how much descent the line holds, the jump the bisection ended on and the discrete change there,
and (from the matching *-nonlinearity*.json) how strongly the rollout amplifies the control change and where it
first responds nonlinearly.

  python3 summarize.py OUT.csv LINE.json...   (each LINE.json's nonlinearity file: 'line-direct' -> 'nonlinearity')
"""
import csv, json, os, sys

DISCONTINUOUS = ["closest_point_jump", "pcg_iterations", "inside_outside_flip", "zone_cut_off", "substeps",
                 "self_contacts"]


def nonlinearity_file(line_file):
    base = os.path.basename(line_file).replace("-line-direct", "-nonlinearity")
    path = os.path.join(os.path.dirname(line_file), base)
    return path if "-nonlinearity" in base and os.path.exists(path) else None


def row(path):
    d = json.load(open(path))
    phi0, s0 = d["phi"], d["slope_at_start"]
    line = d["line"]
    half = next((r["t"] for r in line if r["slope"] > 0.5 * s0), None)
    turn = next((r["t"] for r in line if r["slope"] > 0), None)
    best = min(line, key=lambda r: r["phi"])
    first_up = next((r["t"] for r in line if r["phi"] > phi0), None)
    out = {
        "probe": os.path.basename(path),
        "solver": d["solver"],
        "phi": phi0,
        "slope_at_start": s0,
        "t_slope_halved": half,
        "t_slope_positive": turn,
        "t_phi_above_start": first_up,
        "descent_on_line": phi0 - best["phi"],
        "descent_at_t": best["t"],
        "discontinuous_changes_on_line": ";".join(
            sorted({k for r in line for k in r["changes_since_previous"] if k in DISCONTINUOUS})),
    }
    b = d.get("bisection")
    if b and b["steps"]:  # KF_KINK_BISECT=0 leaves the first departing interval unbisected: nothing to name
        kinds = [k for k in b["changes"] if k != "feature_change_continuous"]
        out.update({
            "bisected_to_width": b["to"] - b["from"],
            "bisected_at_t": b["from"],
            "bisected_phi_jump": b["phi_to"] - b["phi_from"],
            "bisected_change": ";".join(
                "%s(step %d, %s)" % (k, b["changes"][k]["first_step"], b["changes"][k]["example"]) for k in kinds)
            or "none (smooth to the resolution of t)",
            # the earliest step's kind: the cause; changes at later steps follow from it
            "bisected_kind": min(kinds, key=lambda k: b["changes"][k]["first_step"]) if kinds else "none",
        })
    nl = nonlinearity_file(path)
    if nl:
        n = json.load(open(nl))
        last = n["steps"][-1]
        out["amplification_m_per_unit_control"] = last["first_difference"] / n["T"]
        first = next((r for r in n["steps"] if r["ratio"] > 0.01), None)
        if first:
            out["first_nonlinear_step"] = first["step"]
            out["first_nonlinear_particle_zone"] = "%s (phi %.5f m, moved %.2e m)" % (
                first.get("zone_at_step_start"), first.get("phi", 0), first["particle_first"])
    return out


def main():
    rows = [row(p) for p in sys.argv[2:]]
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(sys.argv[1], "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("%.4g" % v if isinstance(v, float) else v) for k, v in r.items()})


main()
