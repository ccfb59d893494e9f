#!/usr/bin/env python3
"""The frames around where a drape goes into the body: per frame, the deepest particle's signed distance to the
body (as drape_penetration.py measures it) and its velocity along the body's outward normal; the particle that
is deepest one frame later, where it is now and the body contact's stiffness in a step's matrix at its depth
(character.body: thickness, stiffness, the cloth's contact_ramp; src/sim/cloth/contact_profile.h); and the whole
sheet's mean velocity and median and largest particle speed (from trajectory.bin).

  python3 tests/results/shots/drape_kick.py KEYFRAME OUT.csv FIRST:LAST LABEL=RUN_DIR...

Each RUN_DIR is a `keyframe optimize` or `keyframe simulate` run of a character scene; frames FIRST..LAST are
exported (--format obj)."""
import json, math, os, struct, subprocess, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drape_penetration import dot, read_obj, signed_distances  # noqa: E402


def trajectory(path):
    """Per frame, the positions and velocities (flat lists of 3p floats) of trajectory.bin."""
    data = open(path, "rb").read()
    p, frames = struct.unpack_from("<II", data, 8)
    at, x, v = 24, [], []
    for _ in range(frames):
        x.append(struct.unpack_from(f"<{3 * p}d", data, at)); at += 24 * p
        v.append(struct.unpack_from(f"<{3 * p}d", data, at)); at += 24 * p
    return p, x, v


def stiffness(delta, k, ramp):
    """g'(delta) of the contact profile: 0 outside, k t^2 (3 - 2t) within the ramp, k beyond."""
    if delta <= 0: return 0.0
    if delta >= ramp: return k
    t = delta / ramp
    return k * t * t * (3 - 2 * t)


def main():
    keyframe, out, span, runs = sys.argv[1], sys.argv[2], sys.argv[3], [a.split("=", 1) for a in sys.argv[4:]]
    first, last = (int(a) for a in span.split(":"))
    rows = []
    for label, run in runs:
        subprocess.run([keyframe, "export", run, "--format", "obj", "--frames", f"{first}:{last + 1}"], check=True,
                       capture_output=True)
        scene = json.load(open(os.path.join(run, "scene.json")))
        body = scene.get("character", {}).get("body", {})
        thickness, k = body.get("thickness", 0.012), body.get("stiffness", 2000.0)
        ramp = scene["cloth"].get("contact_ramp", 0.5) * thickness
        p, xs, vs = trajectory(os.path.join(run, "trajectory.bin"))
        sds = {}
        for frame in range(first, last + 1):
            v_obj, groups = read_obj(os.path.join(run, "export", f"frame_{frame:04d}.obj"))
            sds[frame] = signed_distances([xs[frame][3 * i:3 * i + 3] for i in range(p)], v_obj, groups["body"])
        for frame in range(first, last + 1):
            sd = sds[frame]
            d, i = min((d, i) for i, (d, _) in enumerate(sd) if d is not None)
            nxt = {}
            if frame < last:
                _, j = min((e, j) for j, (e, _) in enumerate(sds[frame + 1]) if e is not None)
                dj = sd[j][0]
                nxt = {"next_deepest": j, "its_distance_m": "" if dj is None else round(dj, 5),
                       "its_contact_stiffness_N_m": "" if dj is None else round(stiffness(thickness - dj, k, ramp), 1)}
            vel = vs[frame][3 * i:3 * i + 3]
            mean = [sum(vs[frame][3 * j + c] for j in range(p)) / p for c in range(3)]
            speeds = sorted(math.sqrt(dot(vs[frame][3 * j:3 * j + 3], vs[frame][3 * j:3 * j + 3])) for j in range(p))
            rows.append({"run": label, "frame": frame, "particle": i, "min_signed_distance_m": round(d, 5),
                         "normal_velocity_m_s": round(dot(vel, sd[i][1]), 4),
                         "inside": sum(1 for e, _ in sd if e is not None and e < 0),
                         "mean_vx": round(mean[0], 4), "mean_vy": round(mean[1], 4), "mean_vz": round(mean[2], 4),
                         "median_speed_m_s": round(speeds[p // 2], 4), "max_speed_m_s": round(speeds[-1], 4),
                         "next_deepest": "", "its_distance_m": "", "its_contact_stiffness_N_m": "", **nxt})
    fields = list(rows[0].keys())
    with open(out, "w") as f:
        f.write(",".join(fields) + "\n")
        for r in rows:
            f.write(",".join(str(r[k]) for k in fields) + "\n")


if __name__ == "__main__":
    main()
