"""The piano's body: unison strings on the bridge decaying in two stages (Weinreich), a single
string's bridge loss against the single-string T60 it was set from (docs/instrument-data.md §3.2)
and against Weinreich's measured string (§3.6), the sustain pedal's sympathetic ring through
the soundboard, absent from the dry piano, the strings' longitudinal force on the tilted bridge
(§3.7), and the pedal's effect on a held note's decay by register (§3.8).
Rendered with hamiltone-render (--notes, and a small MIDI file for the pedal)."""
import os
import struct
import tomllib

import matplotlib.pyplot as plt
import numpy as np

from common import code, peak, read_wav, spectrum

TITLE = "The body: bridge, two-stage decay and sympathetic resonance"
FIGURES = ["body_two_stage_decay", "body_weinreich_string", "body_sympathetic_spectrum"]

C4 = 440.0 * 2 ** ((60 - 69) / 12)
# docs/instrument-data.md §3.6: Weinreich's string at 311 Hz (D#4), the others wedged, its sound
# pressure level's prompt sound.
WEINREICH_PROMPT = 8.0  # dB/s, "about"


def render(ctx, name, preset, source, seconds, extra=(), tail=None):
    """The left channel and the rate; `tail` s after the last event (default: none after --notes,
    `seconds` after a MIDI file)."""
    path = ctx.path(name + ".wav")
    if tail is None:
        tail = 0 if source[0] == "--notes" else seconds
    args = [ctx.render, "--preset", ctx.source + "/presets/" + preset + ".toml", *source,
            "--tail", tail, *extra, "--format", "pcm24",
            "--quiet", "-o", path]
    ctx.run(args)
    x, rate = read_wav(path)
    return (x[:, 0] if x.ndim == 2 else x), rate


def levels(x, rate, hz, window=0.1):
    """The partial at `hz` in dB, one value per `window` seconds (a single DFT bin)."""
    n = int(window * rate)
    phase = np.exp(-2j * np.pi * hz * np.arange(n) / rate)
    return np.array([20 * np.log10(2 * abs(np.sum(x[i:i + n] * phase)) / n + 1e-12)
                     for i in range(0, len(x) - n + 1, n)])


def total_levels(x, rate, window=0.1):
    """The whole output's level in dB, one value per `window` seconds (a sound pressure level)."""
    n = int(window * rate)
    return np.array([10 * np.log10(np.mean(x[i:i + n] ** 2) + 1e-24)
                     for i in range(0, len(x) - n + 1, n)])


def slope(db, t0, t1, smooth=0, window=0.1):
    """dB/s lost from t0 to t1: the least-squares slope of the levels, each window's power first
    averaged over ±smooth/2 s (the unisons beat in the aftersound)."""
    power = 10 ** (db / 10)
    half = int(round(smooth / window / 2))
    idx = np.arange(int(round(t0 / window)), int(round(t1 / window)) + 1)
    y = [10 * np.log10(np.mean(power[max(0, i - half):i + half + 1])) for i in idx]
    return -np.polyfit(idx * window, y, 1)[0]


def midi_file(path, pedal, seconds, note=60, velocity=100):
    """Format 0, 480 ticks a beat at 120 bpm (1 ms a tick ≈ 1.04): the pedal down at 0 (or not),
    `note` (C4) struck at 10 ms and held to `seconds`, the pedal never lifted."""
    ticks = lambda s: int(round(s * 960))
    def var(n):
        out = [n & 0x7F]
        while n > 0x7F:
            n >>= 7
            out.insert(0, (n & 0x7F) | 0x80)
        return bytes(out)
    events = b""
    if pedal:
        events += var(0) + bytes([0xB0, 64, 127])
    events += var(ticks(0.01)) + bytes([0x90, note, velocity])
    events += var(ticks(seconds) - ticks(0.01)) + bytes([0x80, note, 0])
    events += var(0) + b"\xff\x2f\x00"
    with open(path, "wb") as f:
        f.write(b"MThd" + struct.pack(">IHHH", 6, 0, 1, 480))
        f.write(b"MTrk" + struct.pack(">I", len(events)) + events)


def run(ctx):
    seconds = 7.0  # the pedal's comparison
    held = 15.0  # the aftersound: C4's outer strings beat every 4 s, with the middle one every 8 s
    fit_end = 6.5  # one string and the rigid ends: fitted before they fall silent (−100 dBFS)
    with open(os.path.join(ctx.source, "presets/grand-piano-strings.toml"), "rb") as f:
        t60 = next(k for k in tomllib.load(f)["key"] if k["note"] == "C4")["loss"]["t60_low_s"]
    published = 60.0 / t60  # dB/s of one string, the STK column of data §3.2
    with open(os.path.join(ctx.source, "presets/grand-piano.toml"), "rb") as f:
        own_t60 = next(k for k in tomllib.load(f)["key"] if k["note"] == "C4")["loss"]["t60_low_s"]
    own = 60.0 / own_t60  # dB/s: the string's own loss (data §2.1), no bridge

    notes = ["--notes", f"C4:100:{held}"]
    body, rate = render(ctx, "body_c4", "grand-piano", notes, held)
    one, _ = render(ctx, "body_c4_one", "grand-piano", notes, held,
                    ["--set", "string.unisons=1"])
    dry, _ = render(ctx, "body_c4_dry", "grand-piano-strings", notes, held)
    db = {name: levels(x, rate, C4) for name, x in
          (("three strings on the bridge (grand-piano)", body),
           ("one string on the bridge", one),
           ("three strings, rigid ends (grand-piano-strings)", dry))}
    three, single, rigid = db.values()
    end = held - 0.5
    prompt, after = slope(three, 0.1, 0.9), slope(three, 2.5, end, smooth=1.0)
    alone = slope(single, 0.5, fit_end)
    rigid_rate = slope(rigid, 0.5, fit_end, smooth=1.0)

    fig, ax = plt.subplots(figsize=(7, 3.5))
    for name, d in db.items():
        ax.plot(np.arange(len(d)) * 0.1, d - d[:3].max(), label=name)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("C4's fundamental (dB)")
    ax.set_ylim(-90, 5)
    ax.legend(fontsize=8)
    out = [
        "**Claim.** A key's unison strings on a common resistive bridge decay in two stages: while "
        "they move in phase they drain n times faster than one string alone (the prompt sound), "
        "then what the detune and the hammer's unequal shares put out of phase barely moves the "
        "bridge and decays far more slowly (the aftersound) [Weinreich 1977]. The bridge's "
        "resistance is set per key so that one string alone decays in the single-string T60 of "
        "docs/instrument-data.md §3.2; the string's own loss is RT-425's string-only law (§2.1).",
        "",
        ctx.figure(fig, "body_two_stage_decay",
                   "C4 at velocity 100, held: its fundamental's level in 100 ms windows."),
        "| C4's fundamental | decay (dB/s) |",
        "|---|---|",
        f"| one string alone, on the bridge, 0.5–{fit_end:g} s | {alone:.1f} |",
        f"| published single-string decay (§3.2, STK: T60 = {t60:g} s) | {published:.1f} |",
        f"| three strings on the bridge: prompt, 0.1–0.9 s | {prompt:.1f} |",
        f"| three strings on the bridge: aftersound, 2.5–{end:g} s (1 s power means) | {after:.1f} |",
        f"| the string's own loss at 0 Hz, no bridge (§2.1: T60 = {own_t60:g} s): a floor | "
        f"{own:.1f} |",
        f"| three strings on rigid ends (grand-piano-strings), 0.5–{fit_end:g} s | {rigid_rate:.1f} |",
        "",
        ctx.check(abs(alone - published) <= 0.2 * published,
                  "one string on the bridge decays within 20 % of the published single-string rate"),
        ctx.check(prompt > 2 * alone and after < 0.5 * alone,
                  "prompt sound over twice, aftersound under half the single string's rate"),
        ctx.check(after >= 0.75 * own,
                  "the aftersound at least 75 % of the string's own loss, its floor (25 % for the "
                  "beats)"),
        "",
        code(ctx.commands[-3]),
        "",
    ]

    # Weinreich's string (data §3.6): 311 Hz, one string free, its sound pressure level falling
    # about 8 dB/s in the prompt sound. Here one D#4 string on its bridge, the whole output.
    long = 6.0
    tone, rate = render(ctx, "body_ds4_one", "grand-piano", ["--notes", f"D#4:80:{long}"], long,
                        ["--set", "string.unisons=1"])
    level = total_levels(tone, rate)
    top = int(np.argmax(level[:10]))
    t0 = top * 0.1
    tone_prompt = slope(level, t0 + 0.1, t0 + 2.0)
    fig, ax = plt.subplots(figsize=(7, 3.0))
    t = np.arange(len(level)) * 0.1
    ax.plot(t, level - level[top], label="one D#4 string on its bridge, velocity 80")
    ax.plot([t0, long], [0, -WEINREICH_PROMPT * (long - t0)], "k--",
            label="Weinreich's string: about 8 dB/s")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("level (dB)")
    ax.set_ylim(-60, 5)
    ax.legend(fontsize=8)
    out += [
        "**Claim.** One string on its bridge falls as the one measured in Weinreich's lecture "
        "(docs/instrument-data.md §3.6: 311 Hz, the other strings wedged, sound pressure level): "
        "about 8 dB/s in its prompt sound.",
        "",
        ctx.figure(fig, "body_weinreich_string",
                   f"One D#4 string held {long:g} s at velocity 80: the output's level in 100 ms "
                   "windows."),
        f"**Measured.** {tone_prompt:.1f} dB/s over the 2 s after the peak, against about "
        f"{WEINREICH_PROMPT:g}. One string of one piano at an unknown dynamic, read from a "
        "lecture's text: the check allows ±25 %. His string's aftersound (under a quarter of the "
        "prompt's rate) is its motion passed to the horizontal plane, which the bridge barely "
        "drains; each string here moves in one plane, so it has none: it decays at one rate.",
        ctx.check(0.75 * WEINREICH_PROMPT <= tone_prompt <= 1.25 * WEINREICH_PROMPT,
                  "one string's prompt sound within 25 % of Weinreich's 8 dB/s"),
        "",
        code(ctx.commands[-1]),
        "",
    ]

    takes = {}
    for pedal in (False, True):
        midi = ctx.path(f"body_pedal_{int(pedal)}.mid")
        midi_file(midi, pedal, seconds)
        for preset in ("grand-piano", "grand-piano-strings"):
            takes[(preset, pedal)], _ = render(ctx, f"body_{preset}_{int(pedal)}", preset,
                                               ["--midi", midi], 0.0)
    start, stop = int(0.5 * rate), int((seconds - 0.2) * rate)
    def power_db(x):
        return 10 * np.log10(np.mean(x[start:stop] ** 2) + 1e-30)
    pedal_up = takes[("grand-piano", False)]
    ring = takes[("grand-piano", True)] - pedal_up
    dry_diff = np.max(np.abs(takes[("grand-piano-strings", True)] -
                             takes[("grand-piano-strings", False)]))
    change = power_db(ring) - power_db(pedal_up)

    seg = slice(start, stop)
    w = np.hanning(stop - start)
    f = np.fft.rfftfreq(stop - start, 1 / rate)
    spec = lambda x: 20 * np.log10(np.abs(np.fft.rfft(x[seg] * w)) / np.sum(w) * 2 + 1e-12)
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(f, spec(pedal_up), lw=0.7, label="C4 held, pedal up")
    ax.plot(f, spec(takes[("grand-piano", True)]), lw=0.7, label="C4 held, pedal down")
    ax.plot(f, spec(ring), lw=0.7, label="the difference: the sympathetic ring")
    ax.set_xlim(50, 2000)
    ax.set_ylim(-140, -20)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("level (dBFS)")
    ax.legend(fontsize=8)
    strongest = f[np.argmax(np.where(f > 50, spec(ring), -np.inf))]
    out += [
        "**Claim.** With the sustain pedal down every key's strings ring in sympathy through the "
        "soundboard (engine/instruments/piano_body.h); on the dry piano the pedal changes nothing "
        "while the struck key is held (its damper is off either way).",
        "",
        ctx.figure(fig, "body_sympathetic_spectrum",
                   f"C4 held, 0.5–{seconds - 0.2:g} s: spectra with the pedal up and down."),
        f"**Measured.** Pedal down against pedal up, C4 held: the difference, the ring, has "
        f"{change:+.1f} dB the power of the held note, strongest at {strongest:.0f} Hz (C4's "
        "fundamental, where the lifted C3, C2 … strings' partials meet it); on "
        f"grand-piano-strings the largest sample difference is {dry_diff:g}. No published level "
        "of the ring was found to compare with, so it is not calibrated, and it is likely too "
        "strong: this modal board is a plain rectangle without the bridge's own mass and "
        "stiffness, and each key's unisons ring as one.",
        ctx.check(dry_diff == 0.0, "the dry piano is unchanged by the pedal"),
        ctx.check(change > -40.0, "the pedal's sympathetic ring is there on grand-piano"),
        "",
        code(ctx.commands[-2]),
    ]
    out += longitudinal_force(ctx)
    out += pedal_by_register(ctx)
    return "\n".join(out)


def band_db(x, rate, lo, hi):
    """Power in [lo, hi) Hz of the whole take (common.spectrum, not padded), dB."""
    f, mag = spectrum(x, rate, 0.0, len(x) / rate + 1.0, pad=1)  # the slice stops at the end
    return 10 * np.log10(np.sum(mag[(f >= lo) & (f < hi)] ** 2) + 1e-30)


def longitudinal_force(ctx):
    """The strings' tension change on the tilted bridge: what it adds to the sound, by band."""
    bands = [(20, 200), (200, 1000), (1000, 5000)]
    rows, growth = [], None
    for note in ("A0", "C2", "C4"):
        takes = {}
        for angle in (0, 1, 10) if note == "A0" else (0, 1):
            takes[angle], rate = render(ctx, f"body_angle_{note}_{angle}", "grand-piano",
                                        ["--notes", f"{note}:127:2"], 2.0,
                                        extra=["--set", f"bridge.angle_deg={angle}"])
        diff = takes[1] - takes[0]
        whole = band_db(diff, rate, 0, rate / 2) - band_db(takes[0], rate, 0, rate / 2)
        cells = [band_db(diff, rate, lo, hi) - band_db(takes[0], rate, lo, hi) for lo, hi in bands]
        rows.append(f"| {note} | {whole:.0f} | " + " | ".join(f"{c:.0f}" for c in cells) + " |")
        if 10 in takes:
            growth = (band_db(takes[10] - takes[0], rate, 0, rate / 2) -
                      band_db(diff, rate, 0, rate / 2))
    expected = 20 * np.log10(np.sin(np.radians(10)) / np.sin(np.radians(1)))
    return [
        "",
        "### The longitudinal end force",
        "",
        "**Claim.** The strings meet the bridge 1° off the board's plane (docs/instrument-data.md "
        "§3.7), so their tension change pushes it by sin 1° of it (engine/instruments/bridge.h): "
        "the longitudinal end force reaches the board, linearly in sin α. Its pulse reaches the "
        "bridge at the longitudinal speed, ahead of the transverse wave, and it grows as the "
        "square of the transverse amplitude (tests/instruments/bridge_test.cpp measures both).",
        "",
        "**Measured.** Velocity 127, 2 s, grand-piano with `bridge.angle_deg` 1 against 0: the "
        "difference's power over the note's, dB, in all and by band.",
        "",
        "| note | all | 20–200 Hz | 200–1000 Hz | 1–5 kHz |",
        "|---|---|---|---|---|",
        *rows,
        "",
        f"At A0, 10° against 1° raises the difference by {growth:.1f} dB (sin 10°/sin 1°: "
        f"{expected:.1f} dB). The drive adds little at 1°: sin 1° passes 1.7 % of the tension "
        "change to the bridge. The level is not calibrated: no published measurement of the "
        "longitudinal share of a bridge's force was found, and the bridge's rocking, which may pass "
        "more of it, is not modelled.",
        ctx.check(abs(growth - expected) <= 1.0, "the drive is linear in sin α"),
        ctx.check(all(-80 < float(r.split("|")[2]) < -10 for r in rows),
                  "at 1° the longitudinal force adds to the sound (above −80 dB) without "
                  "dominating it (below −10 dB)"),
        "",
        code(ctx.commands[-1]),
        *longitudinal_decay(ctx),
    ]


def longitudinal_decay(ctx):
    """A fortissimo A0's longitudinal modes at the board under the pedal, against their loss law."""
    with open(ctx.source + "/presets/grand-piano.toml", "rb") as f:
        loss = tomllib.load(f)["loss"]
    high = 2 * np.pi * loss["t60_high_Hz"]
    sigma0 = 6.908 / loss["longitudinal_t60_low_s"]
    eta = (6.908 / loss["longitudinal_t60_high_s"] - sigma0) / high ** 2  # σ = σ0 + η ω²
    midi = ctx.path("body_longitudinal_A0.mid")
    midi_file(midi, True, 1.0, note=21, velocity=127)
    none = ["--set", "loss.longitudinal_t60_low_s=inf", "--set", "loss.longitudinal_t60_high_s=inf"]
    rows, rates, laws, levels = [], {}, {}, {}
    for name, extra in (("law", []), ("none", none)):
        x, rate = render(ctx, f"body_longitudinal_{name}", "grand-piano", ["--midi", midi], 10.0,
                         extra=extra, tail=10.0)
        window = lambda t: x[int(t * rate):int((t + 2) * rate)] * np.hanning(int(2 * rate))
        def magnitude(t, hz):
            n = np.arange(int(2 * rate))
            return abs(np.sum(window(t) * np.exp(-2j * np.pi * hz * n / rate)))
        for m in (1, 2):
            grid = np.linspace(465.5 * m - 3, 465.5 * m + 3, 121)
            hz = grid[np.argmax([magnitude(4.0, f) for f in grid])]
            rates[(name, m)] = 20 * np.log10(magnitude(4.0, hz) / magnitude(8.0, hz)) / 4.0
            if name == "law":
                laws[m] = 20 / np.log(10) * (sigma0 + eta * (2 * np.pi * hz) ** 2)
                levels[m] = 20 * np.log10(magnitude(4.0, hz))
                rows.append(f"| {m} | {hz:.1f} | {rates[(name, m)]:.2f} | {laws[m]:.2f} |")
    for m in (1, 2):
        rows[m - 1] += f" {rates[('none', m)]:.2f} |"
    return [
        "",
        "### The longitudinal modes' own loss",
        "",
        "**Claim.** The longitudinal wave decays by its own law, RT-425's σ_v = R_v + η_v ω² "
        "(docs/instrument-data.md §3.1; `loss.longitudinal_t60_low_s` "
        f"{loss['longitudinal_t60_low_s']:g} s and `_high_s` {loss['longitudinal_t60_high_s']:g} s "
        f"at {loss['t60_high_Hz']:g} Hz on grand-piano), so a fortissimo bass note's longitudinal "
        "tone dies away at the board even while the pedal holds its damper off. Shared with the "
        "transverse law by wavenumber (the paper's (49)) it barely decays: on A0, where R_u = 0, it "
        "held at −64 dBFS for as long as the pedal.",
        "",
        "**Measured.** A0 at velocity 127 with the pedal down, released at 1 s: each longitudinal "
        "mode's magnitude in the output (left and right averaged, a 2 s Hann window at its peak "
        "within ±3 Hz of m × 465.5 Hz) at 4–6 s and 8–10 s, as dB/s; beside the law, the same "
        "preset with both times set to inf (no loss of the longitudinal wave's own). Earlier "
        "windows read slower (3.9 dB/s for the first mode from 2–4 s to 6–8 s): the transverse "
        "partials, still ringing under the pedal, keep forcing the tension at that frequency.",
        "",
        "| mode | Hz | dB/s | law, dB/s | without, dB/s |",
        "|---|---|---|---|---|",
        *rows,
        "",
        f"The second mode ({levels[2] - levels[1]:+.0f} dB against the first at 4 s) shares its "
        "window with A0's dense transverse partials (27.5 Hz apart): the check is on the first.",
        ctx.check(abs(rates[("law", 1)] - laws[1]) <= 0.15 * laws[1],
                  "A0's first longitudinal mode decays within 15 % of its law"),
        ctx.check(rates[("none", 1)] < 1.0,
                  "without the longitudinal law it decays under 1 dB/s"),
        "",
        code(ctx.commands[-2]),
    ]


def outer(ratio):
    """The bass's and the treble's decay against Lehtonen et al.'s "not observed", in words."""
    words = []
    for name, where in (("C2", "bass"), ("C6", "treble")):
        r = ratio[name]
        verdict = ("unchanged within 10 %, as they found" if abs(r - 1) <= 0.1 else
                   "longer, where they saw no effect" if r < 1 else "shorter")
        words.append(f"the {where}'s (ratio {r:.2f}) {verdict}")
    return "; ".join(words)


def pedal_by_register(ctx):
    """A held note's first partials, pedal up and down: their decay rates by register, beside
    Lehtonen et al. (2007), who found the pedal lengthens the middle register's decay, not the
    bass's or the treble's. Reported, not checked."""
    seconds, fit, smooth = 9.0, (1.0, 8.0), 1.0
    notes = [("C2", 36), ("C4", 60), ("C6", 84)]
    rows, ratio = [], {}
    for name, note in notes:
        f0 = 440.0 * 2 ** ((note - 69) / 12)
        rates = {}
        for pedal in (False, True):
            midi = ctx.path(f"body_register_{name}_{int(pedal)}.mid")
            midi_file(midi, pedal, seconds, note)
            x, rate = render(ctx, f"body_register_{name}_{int(pedal)}", "grand-piano",
                             ["--midi", midi], 0.0)
            freqs, mag = spectrum(x, rate, 0.5, seconds - 1.0)
            rates[pedal] = []
            for n in (1, 2, 3):
                hz, _ = peak(freqs, mag, 0.97 * n * f0, 1.03 * n * f0 * (1 + 1e-3 * n * n))
                rates[pedal].append(slope(levels(x, rate, hz), *fit, smooth=smooth) + 0.0)
        up, down = np.mean(rates[False]), np.mean(rates[True])
        ratio[name] = down / up
        rows.append(f"| {name} | " + " | ".join(f"{a:.1f} / {b:.1f}" for a, b in
                                                zip(rates[False], rates[True])) +
                    f" | {down / up:.2f} |")
    middle = ratio["C4"]
    return [
        "",
        "### The pedal and the decay, by register",
        "",
        "**Published.** Lehtonen, Penttinen, Rauhala & Välimäki (J. Acoust. Soc. Am. 122, 1787 "
        "(2007), abstract) found that the sustain pedal lengthens the decay of the partials of "
        "tones in the middle of the keyboard, and not of bass or treble tones. Here the held "
        "strings drive the body one way (they do not feel the board), so what the pedal can "
        "change is the sound beside them: the lifted strings ring in sympathy and the board "
        "radiates them. The board's modes stop at 1 kHz (body.max_mode_Hz), under C6's "
        "fundamental, so the treble cannot change by construction.",
        "",
        f"**Measured.** A note held {seconds:g} s at velocity 100 on grand-piano, pedal up / down: "
        f"the decay of its first three partials (dB/s, the slope of 100 ms levels over "
        f"{fit[0]:g}–{fit[1]:g} s, each window's power averaged over {smooth:g} s: the unisons "
        "and the lifted strings beat), and the mean rate's ratio down over up (< 1: the pedal "
        "lengthens the decay).",
        "",
        "| note | partial 1 | partial 2 | partial 3 | down / up |",
        "|---|---|---|---|---|",
        *rows,
        "",
        f"The middle register's decay (ratio {middle:.2f}) is " +
        ("longer with the pedal, as Lehtonen et al. found" if middle < 0.8 else
         "not longer with the pedal, unlike Lehtonen et al.'s piano") + "; " + outer(ratio) +
        ". Reported, not checked: the engine's held strings never feel the lifted ones, so the "
        "pedal cannot slow the held note's own decay, only add the sympathetic ring beside it, "
        "which beats with the partials it shares. An earlier measure of this, single partials "
        "over 1–4 s without the power means, read 0.57 at C4: the beats, not the pedal.",
        "",
        code(ctx.commands[-3]),
    ]
