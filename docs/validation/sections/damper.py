"""Key-off: the damper's felt against a uniform damper. Each partial's decay after the release,
measured on grand-piano-strings (the felt, damper.model = felt) and on the same preset with the
uniform damper, beside the published T60 after release of docs/instrument-data.md §3.2."""
import os
import tomllib

import matplotlib.pyplot as plt
import numpy as np

from common import code
from sections.body import render

TITLE = "Key-off: the damper's felt"
FIGURES = ["damper_partials"]

NOTES = {"A0": 21, "C3": 48, "C4": 60}
HELD, AFTER = 1.0, 1.5  # s held, s rendered after the release
WINDOW = 0.04  # s, Hann: the fundamental's leakage into its neighbours' bins under −60 dB
HOP = 0.01


def partials(x, rate, f0, count):
    """The first `count` partials' frequencies: the strongest bin within ±3 % of n·f0·(stretch)
    in the held sound (stiff strings are sharp), refined by parabolic interpolation."""
    seg = x[int(0.2 * rate):int(HELD * rate)]
    spec = np.abs(np.fft.rfft(seg * np.hanning(len(seg))))
    f = np.fft.rfftfreq(len(seg), 1 / rate)
    found, stretch = [], 1.0
    for n in range(1, count + 1):
        guess = n * f0 * stretch
        band = np.where(np.abs(f - guess) < 0.03 * guess)[0]
        i = band[np.argmax(spec[band])]
        a, b, c = np.log(spec[i - 1:i + 2] + 1e-30)
        hz = f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0])
        found.append(hz)
        stretch = hz / (n * f0)
    return found


def decay_t60(x, rate, hz):
    """T60 (s) of the partial at `hz` after the release: the least-squares slope of its level
    (Hann-windowed single DFT bin, 40 ms every 10 ms) from 0.03 s until it has fallen 30 dB."""
    x = x[int(HELD * rate):]
    n, hop = int(WINDOW * rate), int(HOP * rate)
    w = np.hanning(n) * np.exp(-2j * np.pi * hz * np.arange(n) / rate)
    db = np.array([20 * np.log10(abs(np.sum(x[i:i + n] * w)) + 1e-12)
                   for i in range(0, len(x) - n + 1, hop)])
    t = np.arange(len(db)) * HOP
    start = int(round(0.03 / HOP))
    below = np.nonzero(db[start:] < db[start] - 30.0)[0]
    stop = start + (below[0] if len(below) else len(db) - start)
    if stop - start < 4:
        return np.nan
    slope = -np.polyfit(t[start:stop], db[start:stop], 1)[0]
    return 60.0 / slope if slope > 0 else np.inf


def run(ctx):
    with open(os.path.join(ctx.source, "presets/grand-piano-strings.toml"), "rb") as f:
        anchors = {k["note"]: k for k in tomllib.load(f)["key"]}
    count = 8
    rows, t60 = [], {}
    for name, note in NOTES.items():
        f0 = 440.0 * 2 ** ((note - 69) / 12)
        notes = ["--notes", f"{name}:100:{HELD}", "--set", "string.unisons=1"]  # no unison beats
        felt, rate = render(ctx, f"damper_{name}_felt", "grand-piano-strings", notes, AFTER,
                            tail=AFTER)
        uniform, _ = render(ctx, f"damper_{name}_uniform", "grand-piano-strings", notes, AFTER,
                            ["--set", "damper.model=uniform"], tail=AFTER)
        hz = partials(felt, rate, f0, count)
        t60[name] = {model: [decay_t60(x, rate, h) for h in hz]
                     for model, x in (("felt", felt), ("uniform", uniform))}
        published = anchors[name]["loss"]["damper_t60_s"]
        for model in ("felt", "uniform"):
            cells = " | ".join(f"{v:.2f}" if np.isfinite(v) else "∞" for v in t60[name][model])
            rows.append(f"| {name} | {model} | {published:g} | {cells} |")
    fig, ax = plt.subplots(figsize=(7, 3.5))
    n = np.arange(1, count + 1)
    for name, style in zip(NOTES, ("o-", "s-", "^-")):
        ax.semilogy(n, t60[name]["felt"], style, label=f"{name}, felt")
        ax.semilogy(n, t60[name]["uniform"], style[0] + "--", alpha=0.4, label=f"{name}, uniform")
    ax.set_xlabel("partial")
    ax.set_ylabel("T60 after the release (s)")
    ax.legend(fontsize=7, ncol=2)

    c3 = t60["C3"]
    published = anchors["C3"]["loss"]["damper_t60_s"]
    spread = max(c3["felt"][1:5]) / min(c3["felt"][1:5])
    out = [
        "**Claim.** A damper is a felt pressed on the string over a few centimetres, not a loss "
        "spread along it: modelled as dashpots on the nodes under it (SavScheme::setPointDamper, "
        "centred and exactly dissipative), each partial gains the decay rate of its mode shape "
        "there, (D2) in engine/voices/string_voice.cpp — the fundamental the T60 after release of "
        "§3.2 (the only published damper figure), the others by their shape, and a partial with a "
        "node near the felt much less (the over-ring tuners hear). The uniform damper gives every "
        "partial the same added rate. Felt position and width are engineering choices "
        "(docs/instrument-data.md §3.5).",
        "",
        ctx.figure(fig, "damper_partials",
                   f"Each partial's T60 after the release ({HELD:g} s at velocity 100), from 0.03 s "
                   "over its first 30 dB: grand-piano-strings with one string per key."),
        "| note | damper | §3.2 T60 after release (s) | " +
        " | ".join(f"T60 p{i} (s)" for i in n) + " |",
        "|---|---|---|" + "---|" * count,
        *rows,
        "",
        ctx.check(abs(c3["felt"][0] - published) <= 0.25 * published,
                  "C3's fundamental under the felt decays within 25 % of §3.2's T60 after release"),
        ctx.check(spread > 1.5, "the felt damps C3's partials 2–5 unequally (by their shape)"),
        ctx.check(max(c3["uniform"][:5]) / min(c3["uniform"][:5]) < 1.5,
                  "the uniform damper damps C3's first five partials alike"),
        "",
        code(ctx.commands[-1]),
    ]
    return "\n".join(out)
