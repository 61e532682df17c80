#!/usr/bin/env python3
"""The string's grid-rule trade-off (docs/string-grids.md): a C3 string struck by the felt hammer,
u(L/2) over 20 ms on each grid rule and oversampling against a 128x longitudinal-grid reference.
Usage: python3 docs/scripts/string_grid_tradeoff.py [path/to/hamiltone-sim]  (run in a scratch dir)"""
import sys
import subprocess, math, csv, time
SIM = sys.argv[1] if len(sys.argv) > 1 else "build/release/sim/hamiltone-sim"
L, c_L = 1.259, math.sqrt(2.02e11/7850)
def segs_long(k): return int(L / (c_L*k))
def run(tag, k, segments, every, v, dur=0.02):
    out = f"{tag}.csv"
    t0 = time.time()
    subprocess.run([SIM, "string", "--k", repr(k), "--segments", str(segments), "--alpha", "0", "--hammer-velocity", str(v),
                    "--stiffness", "on", "--duration", str(dur), "--every", str(every), "--probe", "0.5", "--out", out], check=True, capture_output=True)
    el = time.time() - t0
    rows = [r for r in csv.reader(open(out)) if r and not r[0].startswith('#') and r[0] != 't']
    return [float(r[1]) for r in rows], el
fs = 48000
for v in (1.0, 4.0):
    refR = 128
    refSeg = segs_long(1/(fs*refR)); refSeg -= refSeg % 2
    ref, el = run("ref", 1/(fs*refR), refSeg, refR, v)
    print(f"v0 = {v} m/s; reference: longitudinal grid, {refR}x, {refSeg} segments ({el:.1f} s)")
    for rule, R in [("transverse",1),("transverse",2),("transverse",4),("transverse",8),("longitudinal",4),("longitudinal",8),("longitudinal",16),("longitudinal",32)]:
        k = 1/(fs*R)
        if rule == "longitudinal": M = segs_long(k)
        else:
            M = None  # the CLI's stiff-string rule decides; its count is read back below
        args_M = M - (M % 2) if M else None  # even, so a grid point sits at L/2
        if args_M is None:
            out = subprocess.run([SIM, "string", "--k", repr(k), "--grid", "transverse", "--alpha", "0", "--hammer-velocity", str(v), "--stiffness", "on", "--duration", "1e-3", "--out", "probe.csv"], check=True, capture_output=True)
            first = open("probe.csv").readline(); args_M = int(first.split("segments=")[1].split()[0]); args_M -= args_M % 2
        x, el = run(f"{rule}{R}", k, args_M, R, v)
        n = min(len(x), len(ref))
        err = math.sqrt(sum((x[i]-ref[i])**2 for i in range(n)) / sum(ref[i]**2 for i in range(n)))
        print(f"  {rule:12s} {R:3d}x  {args_M:4d} segments  rel. L2 error of u(L/2), 20 ms: {err:.2e}")
