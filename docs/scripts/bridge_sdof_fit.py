#!/usr/bin/env python3
"""The per-register bridge of docs/instrument-data.md §6.6: the default soundboard's driving-point
impedance at three keys' bridge points (the modal sum of engine/instruments/soundboard.h over every
mode up to 12 kHz, the points of bridgeLine), its geometric mean in third-octave bands from 100 Hz
to 2 kHz, and the mass-spring-damper Z = R + i(wm - k/w) fitted to it by least squares on log|Z|,
with m set so that sqrt(k/m) = 2 pi 4 kHz. Plain Python, about 10 s.
Usage: python3 docs/scripts/bridge_sdof_fit.py"""
import cmath, math

LX, LY, H, RHO, D1, D2, D3, ETA = 1.9, 1.3, 9e-3, 664.2, 671.0, 10220.0, 90.5, 0.02  # §6.1-5.3
RHOH = RHO * H
MASS = RHOH * LX * LY / 4
BASS = ((0.82, 0.30), (0.74, 0.62))  # BridgeGeometry: A0 -> E2
TREBLE = ((0.66, 0.80), (0.14, 0.18))  # F2 -> C8


def omega(m, n):
    a, b = m / LX, n / LY
    return math.sqrt(math.pi**4 / RHOH * (D1 * a**4 + 2 * D3 * a * a * b * b + D2 * b**4))


MODES = [(m, n, omega(m, n)) for m in range(1, 200) for n in range(1, 200)
         if omega(m, n) <= 2 * math.pi * 12000]


def point(note):
    (a, b), t = (BASS, (note - 21) / 19) if note <= 40 else (TREBLE, (note - 41) / 67)
    return LX * (a[0] + t * (b[0] - a[0])), LY * (a[1] + t * (b[1] - a[1]))


def impedance(note, f):
    x, y = point(note)
    w = 2 * math.pi * f
    mobility = 0j
    for m, n, wm in MODES:
        phi = math.sin(m * math.pi * x / LX) * math.sin(n * math.pi * y / LY)
        mobility += phi * phi / (MASS * (wm * wm - w * w + 1j * ETA * wm * w))
    return 1 / (1j * w * mobility)


def band_mean(note, centre):  # geometric mean of |Z| over a third octave
    fs = [centre * 2 ** ((j - 10) / 60) for j in range(21)]
    return math.exp(sum(math.log(abs(impedance(note, f))) for f in fs) / len(fs))


def sdof(m, k, r, f):
    w = 2 * math.pi * f
    return abs(complex(r, w * m - k / w))


def nelder_mead(fun, x0, step=0.5, iterations=2000):
    n = len(x0)
    pts = [x0] + [[x0[j] + (step if j == i else 0) for j in range(n)] for i in range(n)]
    vals = [fun(p) for p in pts]
    for _ in range(iterations):
        order = sorted(range(n + 1), key=lambda i: vals[i])
        pts, vals = [pts[i] for i in order], [vals[i] for i in order]
        c = [sum(p[j] for p in pts[:-1]) / n for j in range(n)]
        r = [2 * c[j] - pts[-1][j] for j in range(n)]
        fr = fun(r)
        if fr < vals[0]:
            e = [3 * c[j] - 2 * pts[-1][j] for j in range(n)]
            fe = fun(e)
            pts[-1], vals[-1] = (e, fe) if fe < fr else (r, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = r, fr
        else:
            k = [(c[j] + pts[-1][j]) / 2 for j in range(n)]
            fk = fun(k)
            if fk < vals[-1]:
                pts[-1], vals[-1] = k, fk
            else:
                pts = [pts[0]] + [[(pts[0][j] + p[j]) / 2 for j in range(n)] for p in pts[1:]]
                vals = [vals[0]] + [fun(p) for p in pts[1:]]
    best = min(range(n + 1), key=lambda i: vals[i])
    return pts[best], vals[best]


W4 = (2 * math.pi * 4000) ** 2
CENTRES = [100 * 2 ** (i / 3) for i in range(14)]
print(f"{len(MODES)} modes up to 12 kHz")
print("| register (key) | mean |Z| | m (kg) | k (N/m) | R (kg/s) | SDOF |Z| 100/1000/2000 Hz | rms (dB) |")
for name, note in [("bass (A1)", 33), ("middle (C4)", 60), ("treble (C7)", 96)]:
    data = [(f, band_mean(note, f)) for f in CENTRES]

    def misfit(q):  # q = (log k, log R), m = k / W4
        k, r = math.exp(q[0]), math.exp(q[1])
        return sum((math.log(sdof(k / W4, k, r, f)) - math.log(z)) ** 2 for f, z in data)

    q, v = min((nelder_mead(misfit, [math.log(k0), math.log(500)]) for k0 in (1e5, 1e6, 1e7)),
               key=lambda t: t[1])
    k, r = math.exp(q[0]), math.exp(q[1])
    mean = math.exp(sum(math.log(z) for _, z in data) / len(data))
    rms_db = 20 * math.sqrt(v / len(data)) / math.log(10)
    at = " / ".join(f"{sdof(k / W4, k, r, f):.0f}" for f in (100, 1000, 2000))
    print(f"| {name} | {mean:.0f} | {k / W4:.3g} | {k:.3g} | {r:.0f} | {at} | {rms_db:.1f} |")
