#!/usr/bin/env python3
"""Runs `keyframe --threads 1 optimize SCENE --out RUN --quiet`, cut by SIGHUP at CUT CPU seconds (as the
reachable bench cuts), and appends a CSV row: scene, solver, evaluations, cpu_seconds, cut, miss_before,
miss_after (worst judged keyframe, tolerances), pass, exit code, status."""
import csv, json, os, signal, subprocess, sys, time
kf, scene, run, out_csv, label = sys.argv[1:6]
cut_s = float(sys.argv[6]) if len(sys.argv) > 6 else 120.0
load = open('/proc/loadavg').read().split()[0]
p = subprocess.Popen([kf, '--threads', '1', 'optimize', scene, '--out', run, '--quiet'],
                     stdout=subprocess.DEVNULL, stderr=open(run + '.stderr', 'w'))
tick = os.sysconf('SC_CLK_TCK'); cut = False; cpu = 0.0
def cpu_of(pid):
    f = open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()
    return (int(f[11]) + int(f[12])) / tick
while p.poll() is None:
    try: cpu = cpu_of(p.pid)
    except Exception: pass
    if cpu >= cut_s and not cut:
        p.send_signal(signal.SIGHUP); cut = True
    time.sleep(0.5)
rc = p.returncode
try:
    r = json.load(open(os.path.join(run, 'report.json')))
    ks = [k for k in r['keyframe_errors'] if k['judged']]
    w = max(ks, key=lambda k: k['miss_after'])
    row = [label, r['evaluations'], f'{cpu:.1f}', 'yes' if cut else 'no', f"{w['miss_before']:.3g}",
           f"{w['miss_after']:.3g}", 'yes' if (w['miss_after'] <= 1 and not cut) else 'no', rc, r['status'], load]
except Exception as e:
    row = [label, '', f'{cpu:.1f}', 'yes' if cut else 'no', '', '', 'no', rc, 'no report: %s' % e, load]
new = not os.path.exists(out_csv)
with open(out_csv, 'a', newline='') as f:
    w = csv.writer(f)
    if new: w.writerow(['run', 'evaluations', 'cpu_seconds', 'cut', 'miss_before', 'miss_after', 'pass', 'exit', 'status', 'load_1min'])
    w.writerow(row)
print(row)
