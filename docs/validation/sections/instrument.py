"""The synthesizer as heard: a grand-piano C3 at two velocities (brightness), its partials against
the stiff-string series (inharmonicity), a fortissimo note's pitch glide, and a gong's cascade of
energy to high frequencies. Notes rendered with hamiltone-render --notes; the pitch glide is also
checked against the Kirchhoff–Carrier tension-modulation estimate on single struck strings
(hamiltone-sim string --hammer-velocity)."""
import math
import os
import re
import tomllib

import matplotlib.pyplot as plt
import numpy as np

from common import code, fmt, peak, pitch_track, read_csv, read_wav, spectrum

TITLE = "The instrument: piano and gong"
FIGURES = ["instrument_piano_velocity", "instrument_piano_partials", "instrument_piano_glide",
           "instrument_gong"]

C3 = 440.0 * 2 ** ((48 - 69) / 12)  # equal-tempered C3, 130.81 Hz
PRESET = "presets/grand-piano.toml"


def render(ctx, name, notes, preset=None, tail=0.5):
    path = ctx.path(name + ".wav")
    args = [ctx.render]
    if preset:
        args += ["--preset", preset]
    args += ["--notes", notes, "--tail", tail, "--format", "pcm24", "--quiet", "-o", path]
    ctx.run(args)
    return read_wav(path)


def spectrogram(ax, x, rate, top, title):
    frame, hop = 2048, 256
    frames = np.array([x[i:i + frame] * np.hanning(frame)
                       for i in range(0, len(x) - frame, hop)])
    power = np.abs(np.fft.rfft(frames, axis=1)) ** 2
    db = 10 * np.log10(power / power.max() + 1e-12)
    f = np.fft.rfftfreq(frame, 1 / rate)
    t = (np.arange(len(frames)) * hop + frame / 2) / rate
    keep = f <= top
    mesh = ax.pcolormesh(t, f[keep] / 1e3, db[:, keep].T, vmin=-90, vmax=0, shading="auto",
                         cmap="magma")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("frequency (kHz)")
    ax.set_title(title)
    return mesh


def note_number(name):
    """MIDI number of a note name: C4 = 60, "A#1" = 34."""
    n = "C D EF G A B".index(name[0])
    rest = name[1:]
    if rest[:1] in ("#", "b"):
        n += 1 if rest[0] == "#" else -1
        rest = rest[1:]
    return 12 * (int(rest) + 1) + n


def preset_c3(ctx):
    """What the grand-piano preset sets for C3: its string (as hamiltone-sim string flags), the
    hammer's top speed, the unison anchor in force and the unison detune."""
    with open(os.path.join(ctx.source, PRESET), "rb") as f:
        preset = tomllib.load(f)
    keys = preset["key"]
    c3 = next(k for k in keys if k["note"] == "C3")
    anchor = [k for k in keys if "unisons" in k.get("string", {}) and note_number(k["note"]) <= 48][-1]
    s = c3["string"]
    area = math.pi * s["diameter_m"] ** 2 / 4
    physics = {"rho": s["linear_density_kg_m"] / area, "area": area, "length": s["length_m"],
               "young": preset["string"]["young_Pa"], "tension": s["tension_N"]}
    return (physics, preset["hammer"]["velocity_max_m_s"], anchor, s["detune_cents"],
            preset["scheme"])


def longitudinal_variant(ctx, lowest, oversampling):
    """The preset with grid_rule = "longitudinal" and the given oversampling, its keys cut to
    lowest … C4: the short treble strings are shorter than two longitudinal grid spacings at audio
    rates, and nothing of C3 comes from the keys dropped (its string, hammer, loss and detune are set
    at its own anchor, its unisons at `lowest`). Returns the file's path and the changed lines."""
    with open(os.path.join(ctx.source, PRESET)) as f:
        head, *keys = re.split(r"(?m)^(?=\[\[key\]\])", f.read())
    changes = {"lowest_note": f'"{lowest}"', "highest_note": '"C4"',
               "oversampling": str(oversampling), "grid_rule": '"longitudinal"'}
    for name, value in changes.items():
        head, n = re.subn(rf"(?m)^{name} = [^#\n]*?(\s*(#.*)?)$", rf"{name} = {value}\1", head)
        if n != 1:
            raise RuntimeError(f"{PRESET}: no single '{name} = ' line to change")
    kept = [k for k in keys
            if note_number(lowest) <= note_number(re.search(r'(?m)^note = "([^"]+)"', k).group(1))
            <= 60]
    path = ctx.path("grand-piano-longitudinal.toml")
    with open(path, "w") as f:
        f.write(head + "".join(kept))
    return path, ", ".join(f"`{k} = {v}`" for k, v in changes.items())


def note_glide(t, p):
    """Cents from the first frame (0–0.2 s) to the median over 1.5–2.0 s; and that late pitch."""
    late = float(np.median(p[(t > 1.5) & (t < 2.0)]))
    return 1200 * math.log2(p[0] / late), late


def strike(ctx, tag, physics, speed, grid, k, duration, start, grid_factor, scheme="sav-split"):
    """One lossless struck string (hamiltone-sim string, the C3 felt at 0.12 L): its probe u at
    0.31 L and snapshots every 1 ms. Returns the measurements of the frame [start, duration]."""
    every = max(1, round(2e-5 / k))  # the probe at about 50 kHz
    snaps = np.arange(0.0, duration - 0.5e-3, 1e-3)
    times = ",".join(f"{t:.3f}" for t in snaps)
    out, snap = ctx.path(f"strike_{tag}.csv"), ctx.path(f"strike_{tag}_snapshots.csv")
    args = [ctx.sim, "string", "--scheme", scheme, "--grid", grid, "--grid-factor",
            grid_factor, "--stiffness", "on", "--k", k, "--alpha", 0, "--hammer-velocity", speed,
            "--duration", duration, "--probe", 0.31, "--every", every,
            "--snapshots", times, "--snapshot-out", snap, "--out", out]
    for key, value in physics.items():
        args += ["--" + key, value]
    ctx.run(args)
    ctx.commands[-1] = ctx.commands[-1].replace(times, f'"$(seq -s, 0 0.001 {snaps[-1]:.3f})"')
    probe, comment = read_csv(out)
    shots, _ = read_csv(snap)
    m = int(comment["segments"])
    t_s = shots["t"].reshape(-1, m + 1)[:, 0]
    x, u, v = (shots[c].reshape(-1, m + 1) for c in ("x", "u", "v"))
    h = x[0, 1] - x[0, 0]
    zeta, eta = np.diff(u, axis=1) / h, np.diff(v, axis=1) / h
    integral = np.sum(zeta ** 2, axis=1) * h                      # ∫ (∂x u)² dx
    ea, t0 = physics["young"] * physics["area"], physics["tension"]
    stretch = np.sqrt((1 + eta) ** 2 + zeta ** 2)
    potential = 0.5 * h * (ea - t0) * np.sum((stretch - 1) ** 2, axis=1)   # V'(q) of (65)
    row = np.clip(np.searchsorted(probe["t"], t_s), 0, len(probe["t"]) - 1)
    aux = 0.5 * probe["psi"][row] ** 2                            # the scheme's ψ²/2 (sav)
    frame = (t_s >= start) & (t_s <= duration)
    # The fundamental of the probe over the frame (Hann, zero-padded ×32, parabolic peak).
    sel = probe["t"] >= start
    sig = probe["u"][sel] - probe["u"][sel].mean()
    dt = probe["t"][1] - probe["t"][0]
    size = 32 * len(sig)
    f_lin = math.sqrt(t0 / (physics["rho"] * physics["area"])) / (2 * physics["length"])
    pitch = peak(np.fft.rfftfreq(size, dt), np.abs(np.fft.rfft(sig * np.hanning(len(sig)), size)),
                 0.9 * f_lin, 1.6 * f_lin)[0]
    return {"speed": speed, "f": pitch, "integral": float(integral[frame].mean()),
            "peak": float(max(np.abs(u).max(), np.abs(probe["u"]).max())),
            "hammer_J": float(probe["energy"][0]), "segments": m,
            "aux_ratio": float(np.median(aux[frame] / potential[frame]))}


def kirchhoff_carrier(physics, integral):
    """Cents of the mean-tension shift √(1 + ΔT/T0), ΔT = (EA − T0)/(2L) ∫(∂x u)² dx."""
    ea, t0 = physics["young"] * physics["area"], physics["tension"]
    return 600 * math.log2(1 + (ea - t0) / (2 * physics["length"]) * integral / t0)


def sweep(ctx, physics, speeds, grid, k, duration, start, grid_factor, scheme="sav-split"):
    """The struck string at each speed, and at 0.05 m/s as the decayed (linear) reference: the
    measured shift from the reference, against the Kirchhoff–Carrier estimate."""
    ref = strike(ctx, f"{scheme}_{grid}_ref", physics, 0.05, grid, k, duration, start,
                 grid_factor, scheme)
    rows = []
    for v in speeds:
        r = strike(ctx, f"{scheme}_{grid}_{v:g}", physics, v, grid, k, duration, start,
                   grid_factor, scheme)
        r["measured"] = 1200 * math.log2(r["f"] / ref["f"])
        r["estimate"] = (kirchhoff_carrier(physics, r["integral"])
                         - kirchhoff_carrier(physics, ref["integral"]))
        r["ratio"] = r["measured"] / r["estimate"]
        rows.append(r)
    return rows


def glide(ctx, f0, notes, rate):
    """The pitch glide: the rendered fortissimo note (shipped preset, and the same preset on the
    longitudinal grid), then single struck strings against the Kirchhoff–Carrier estimate."""
    out = []
    physics, vmax, anchor, detune, scheme = preset_c3(ctx)
    unisons = anchor["string"]["unisons"]
    # Rendered notes: the preset as shipped at velocities 127 and 30, and its longitudinal variant.
    loud, _ = render(ctx, "c3_v127", "C3:127:3.0")
    variant, changed = longitudinal_variant(ctx, anchor["note"], 2)
    fixed, _ = render(ctx, "c3_v127_longitudinal", "C3:127:3.0", preset=variant)
    commands = [ctx.commands[-2], ctx.commands[-1]]
    band = (0.8 * f0, 1.2 * f0)
    tracks = {"shipped, velocity 127": pitch_track(loud, rate, *band, stop=2.0),
              # Its key is released at 2 s: the last frame ends there.
              "shipped, velocity 30": pitch_track(notes[30][0], rate, *band, stop=1.81),
              "longitudinal grid, velocity 127": pitch_track(fixed, rate, *band, stop=2.0)}
    glides = {name: note_glide(t, p) for name, (t, p) in tracks.items()}
    t_fixed, p_fixed = tracks["longitudinal grid, velocity 127"]
    late_fixed = glides["longitudinal grid, velocity 127"][1]
    below = np.nonzero(1200 * np.log2(p_fixed / late_fixed) < 1.0)[0]
    settles = (f"under 1 cent from t ≈ {t_fixed[below[0]]:.2f} s on" if len(below) else
               "above 1 cent throughout")

    # Single struck strings (the preset's C3 string and the C3 felt), lossless, against amplitude.
    if ctx.quick:
        speeds, duration, start = [vmax / math.sqrt(unisons), vmax, 20.0], 0.13, 0.03
    else:
        speeds, duration, start = [2.0, vmax / math.sqrt(unisons), vmax, 12.0, 20.0, 40.0], 0.3, 0.05
    k_paper = 1e-6
    k_audio = 1.0 / (rate * scheme["oversampling"])
    long_rows = sweep(ctx, physics, speeds, "longitudinal", k_paper, duration, start, 1.05)
    first_long = ctx.commands[-len(speeds)]
    trans_rows = sweep(ctx, physics, speeds, "transverse", k_audio, duration, start,
                       scheme["grid_factor"])
    first_trans = ctx.commands[-len(speeds)]
    sweep_commands = [first_long, first_trans]
    # Störmer–Verlet, which has no auxiliary variable, on the longitudinal grid at the top speed.
    sv = sweep(ctx, physics, [vmax], "longitudinal", k_paper, duration, start, 1.05, "sv")[0]
    sweep_commands.append(ctx.commands[-1])

    ea, t0, length = physics["young"] * physics["area"], physics["tension"], physics["length"]
    lv_ = next(r for r in long_rows if r["speed"] == vmax)
    c_long = math.sqrt(physics["young"] / physics["rho"])
    c_trans = math.sqrt(t0 / (physics["rho"] * physics["area"]))

    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 3.9))
    for name, (t, p) in tracks.items():
        a.plot(t, 1200 * np.log2(p / glides[name][1]), label=name)
    a.set_xlabel("t (s), centre of a 0.2 s frame")
    a.set_ylabel("fundamental (cents re its pitch at 1.5–2 s)")
    a.set_title(f"rendered C3 (grand-piano preset, {unisons} unison strings)")
    a.legend()
    for rows, grid, colour, mark in ((long_rows, f"longitudinal grid, k = {k_paper:g} s", "C0", "o"),
                                     (trans_rows, f"transverse grid, k = 1/{1 / k_audio:.0f} s "
                                      "(the preset's)", "C3", "s")):
        v = np.array([r["speed"] for r in rows])
        est = np.array([r["estimate"] for r in rows])
        b.fill_between(v, est, 1.5 * est, color=colour, alpha=0.15)
        b.plot(v, est, "-", color=colour, lw=0.8, alpha=0.6)
        b.plot(v, [r["measured"] for r in rows], mark, color=colour, label=grid + ": measured")
    b.plot([], [], "-", color="0.5", lw=6, alpha=0.3, label="Kirchhoff–Carrier, 1× to 1.5×")
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xticks(speeds, [f"{v:.3g}" for v in speeds])
    b.minorticks_off()
    b.set_xlabel("hammer speed (m/s), one C3 string, full C3 hammer")
    b.set_ylabel("pitch shift from the linear string (cents)")
    b.set_title(f"struck string, frame {start:g}–{duration:g} s, lossless")
    b.legend(loc="upper left")
    fig.tight_layout()

    out.append("**Claim.** Tension modulation raises the pitch of a loud note at the attack; it "
               "glides down as the amplitude decays (soft notes barely glide).\n")
    out.append(
        "**Expected size (Kirchhoff–Carrier).** A transverse displacement u(x, t) stretches the "
        "string. With both ends fixed and the longitudinal wave much faster than the transverse "
        f"one (√(E/ρ) = {c_long:.0f} m/s against √(T0/ρA) = {c_trans:.0f} m/s for the preset's "
        "C3), the longitudinal motion follows quasi-statically and spreads the stretch evenly, so "
        "the tension rises everywhere by ΔT = (EA − T0)/(2L) ∫₀ᴸ (∂x u)² dx (EA − T0 is the "
        "stiffness of the geometrically exact string (65) beyond its pre-tension; the textbook "
        f"EA differs by {100 * t0 / ea:.1f} %). The transverse wave speed goes as √T, so over a "
        "frame short against the decay the fundamental is raised by the factor √(1 + ⟨ΔT⟩/T0) ≈ "
        "1 + ⟨ΔT⟩/(2T0), ⟨·⟩ the mean over the frame. Assumed: small slopes, ΔT ≪ T0, the "
        "quasi-static stretch, and that the fundamental feels only the mean tension. That last "
        "holds for the share of ∫(∂x u)² carried by the other modes, not for the fundamental's own: "
        "a string in its first mode alone is a Duffing oscillator whose harmonic balance gives 3/2 "
        "of the mean-tension shift. A struck string lies in between, so the measured shift should "
        "be 1 to 1.5 times the estimate. Since ⟨∫(∂x u)²⟩ ≈ 2⟨potential⟩/T0 ≈ E_s/T0 for a "
        "string of energy E_s, the shift is about EA·E_s/(4 L T0²) = "
        f"{fmt(1200 / math.log(2) * ea / (4 * length * t0 ** 2) * 1e-3)} cents per mJ: it grows "
        "with the strike's energy, i.e. about as the square of the hammer speed. (E_s is below the "
        "hammer's energy, as the hammer rebounds: at "
        f"{vmax:g} m/s below, T0⟨∫(∂x u)²⟩ is {100 * t0 * lv_['integral'] / lv_['hammer_J']:.0f} % "
        "of it.)\n")
    out.append(ctx.figure(
        fig, FIGURES[2],
        "Left: fundamental of the rendered C3 over time (0.2 s Hann frames every 25 ms, "
        "zero-padded ×16, parabolic peak), each relative to its own pitch at 1.5–2 s; the preset "
        "as shipped at velocities 127 and 30, and the same preset on the longitudinal grid. "
        "Right: pitch shift of one lossless struck C3 string against hammer speed (markers, from "
        "the probe at 0.31 L against the same string struck at 0.05 m/s), with the "
        "Kirchhoff–Carrier estimate from each run's own mean ∫(∂x u)² dx (line: 1×, band up to "
        "1.5×)."))

    g127, g30 = glides["shipped, velocity 127"][0], glides["shipped, velocity 30"][0]
    gfix = glides["longitudinal grid, velocity 127"][0]
    out.append(
        "**Measured, rendered notes.** Glide from the first frame (0–0.2 s) to the median over "
        f"1.5–2.0 s: the preset as shipped, velocity 127 ({vmax:g} m/s hammer): {g127:+.3f} "
        f"cents; velocity 30: {g30:+.3f} cents. The same preset with {changed} (its keys cut to "
        f"{anchor['note']}–C4, see `longitudinal_variant` in the section's code): velocity 127: "
        f"{gfix:+.2f} cents, {settles}.\n")
    out.append(code("\n".join(commands + [ctx.commands[0]])))

    def aux(x):
        return f"{x:.4f}" if x > 0.01 else f"{x:.1e}"

    def table(rows):
        lines = ["| hammer speed (m/s) | hammer energy (mJ) | peak \\|u\\| (mm) | "
                 "⟨∫(∂x u)² dx⟩ (m) | measured (cents) | Kirchhoff–Carrier (cents) | "
                 "measured / estimate | ψ²/2 ÷ V′(q) |",
                 "|---|---|---|---|---|---|---|---|"]
        for r in rows:
            lines.append(f"| {r['speed']:.3g} | {1e3 * r['hammer_J']:.3g} | {1e3 * r['peak']:.3g} "
                         f"| {r['integral']:.3g} | {r['measured']:+.4g} | {r['estimate']:+.4g} | "
                         f"{r['ratio']:.3g} | {aux(r['aux_ratio'])} |")
        return "\n".join(lines) + "\n"

    lv = next(r for r in long_rows if r["speed"] == vmax)
    tv = next(r for r in trans_rows if r["speed"] == vmax)
    ratios = [r["ratio"] for r in long_rows]
    grows = all(b_["measured"] > a_["measured"] for a_, b_ in zip(long_rows, long_rows[1:]))
    ok = grows and all(0.9 <= q <= 1.65 for q in ratios)
    unison = next(r for r in long_rows if r["speed"] == vmax / math.sqrt(unisons))
    trans_ratios = [r["ratio"] for r in trans_rows]
    out.append(
        "**Measured, one struck string against amplitude.** `hamiltone-sim string` with the "
        f"preset's C3 string (L = {length:g} m, A = {physics['area']:.3e} m², ρ = "
        f"{physics['rho']:.0f} kg/m³, E = {physics['young']:.3g} Pa, T0 = {t0:g} N, bending "
        "stiffness on), struck at 0.12 L by the full C3 felt, lossless, so the shift from the "
        "same string struck at 0.05 m/s is what the note glides by once its amplitude has "
        f"decayed. Fundamental over {start:g}–{duration:g} s; ⟨∫(∂x u)²⟩ over the snapshots in "
        "that frame; peak |u| the largest over the string in the 1 ms snapshots and the probe. "
        f"On the paper's longitudinal grid ({long_rows[0]['segments']} segments, k = "
        f"{k_paper:g} s)"
        + (f" (`--quick`: {len(speeds)} speeds and {duration:g} s runs; the full report has six "
           "speeds from 2 to 40 m/s and 0.3 s)" if ctx.quick else "") + ":\n")
    out.append(table(long_rows))
    out.append(ctx.check(ok, "on the longitudinal grid the shift grows with the hammer speed and "
                             "is 0.9 to 1.65 times the Kirchhoff–Carrier estimate at every speed "
                             f"(measured {min(ratios):.2f} to {max(ratios):.2f})"))
    same = abs(sv["measured"] - lv["measured"]) < 0.01 * abs(sv["measured"])
    out.append(" " + ctx.check(same, f"Störmer–Verlet (no auxiliary variable) on the same grid at "
                                     f"{vmax:g} m/s shifts the pitch by the same amount within 1 % "
                                     f"({sv['measured']:.4g} cents against the split scheme's "
                                     f"{lv['measured']:.4g})"))
    out.append(f"\nOn the transverse grid (the preset's rule before the two grids of the next "
               f"section) at {rate:.0f} Hz × {scheme['oversampling']} "
               f"({trans_rows[0]['segments']} segments, k = 1/{1 / k_audio:.0f} s), same strikes:\n")
    out.append(table(trans_rows))
    out.append(
        f"\nAt {vmax:g} m/s both grids give the string the same motion (peak |u| "
        f"{1e3 * lv['peak']:.2g} mm and {1e3 * tv['peak']:.2g} mm, ⟨∫(∂x u)²⟩ {lv['integral']:.3g} "
        f"and {tv['integral']:.3g} m), and Kirchhoff–Carrier expects {lv['estimate']:.3g} cents; "
        f"the longitudinal grid shifts the pitch by {lv['measured']:.3g} cents, the transverse "
        f"grid by {tv['measured']:.2g}. "
        + (f"**On the transverse grid the shift is at most {100 * max(trans_ratios):.1g} % of "
           "the estimate at every speed: the tension modulation is all but gone, an artefact of "
           "that grid rule, not physics.** "
           if max(trans_ratios) < 0.5 else
           "The transverse grid follows the estimate too. ")
        + "Why: on that grid h is below √(E/ρ)k, so the longitudinal wave, which lives only in "
        "the split potential V′ of (65), is far from resolved; the scheme stays stable and "
        "conserves its energy, but its auxiliary ψ²/2 (the potential it actually feels) parts "
        "from V′(q) computed from the snapshots: the last column, the median ratio over the "
        "frame, is ≈ 1 on the longitudinal grid and tiny on the transverse grid, so the "
        "stretching force ψ·∇V′/√(2V′) is scaled down by the same factor. "
        "(`docs/string-grids.md` measured this grid's waveform error over a strike's first "
        "20 ms, a few per cent, and took the pitch to be unaffected since every voice is tuned on "
        "its own grid; that holds for the small-amplitude pitch, not for its rise with "
        "amplitude.)\n")
    out.append(
        f"**What a listener hears.** The preset gives each of its {unisons} unison strings a "
        f"hammer of 1/{unisons} the mass, so at velocity 127 each string receives the energy of "
        f"a full hammer at {vmax:g}/√{unisons} = {vmax / math.sqrt(unisons):.2f} m/s, for which "
        f"the single string above shifts by {unison['measured']:.2g} cents "
        f"(Kirchhoff–Carrier {unison['estimate']:.2g}). On the longitudinal grid the rendered "
        f"fortissimo starts {gfix:.2g} cents sharp (the first frame is centred at 0.1 s, after "
        "some decay) and is " + settles + ": a slight sharpness of the attack, of the "
        f"order of the preset's own unison detune at C3 ({detune:g} cents between the outermost "
        f"strings), not a swoop. The preset as shipped glides by {g127:+.3f} cents at velocity "
        "127 — "
        + ("nothing a listener could hear, and about "
           f"{abs(gfix / g127):.0f} times less than the same preset on the longitudinal grid. "
           "The shipped fortissimo has no pitch glide because of its scheme setting (grid_rule "
           f"= \"transverse\"), not because the physics is weak at {vmax:g} m/s."
           if abs(g127) < 0.1 * abs(gfix) else
           "comparable to the longitudinal grid's: the preset plays on the two grids, which "
           "resolve the longitudinal wave at 48 kHz (next section).")
        + " (No measured piano pitch glides are in the shared data, so none is quoted here.)\n")
    out.append(code("\n".join(sweep_commands)))
    out.append("The other runs of the sweep differ only in `--hammer-velocity` (0.05 for the "
               "reference, then " + ", ".join(f"{v:.3g}" for v in speeds) + ").\n")
    return out


def run(ctx):
    out = []
    # Brightness against velocity.
    notes = {v: render(ctx, f"c3_v{v}", f"C3:{v}:2.0") for v in (30, 120)}
    commands = ctx.commands[-2:]
    rate = notes[30][1]
    centroid, high = {}, {}
    for v, (x, r) in notes.items():
        f, m = spectrum(x, r, 0.0, 0.5)
        p = m ** 2
        centroid[v] = float(np.sum(f * m) / np.sum(m))  # magnitude-weighted
        high[v] = float(10 * np.log10(np.sum(p[f > 10.5 * C3]) / np.sum(p)))
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6), sharey=True)
    for ax, v in zip(axes, (30, 120)):
        mesh = spectrogram(ax, notes[v][0], rate, 5000, f"grand-piano C3, velocity {v}")
    fig.colorbar(mesh, ax=axes, label="dB (each plot's own maximum)")
    out.append("**Claim.** A harder strike is brighter: the felt hammer's stiffening law puts "
               "more energy into high partials at high velocity.\n")
    out.append(ctx.figure(fig, FIGURES[0], "Spectrograms of a C3 on `grand-piano` at velocities "
                                           "30 and 120 (2048-sample Hann frames)."))
    brighter = high[120] > high[30] + 1.0
    out.append("**Measured** (first 0.5 s): spectral centroid (magnitude-weighted) "
               + ", ".join(f"velocity {v}: {centroid[v]:.0f} Hz" for v in (30, 120))
               + "; energy above the 10th partial relative to the total "
               + ", ".join(f"velocity {v}: {high[v]:.1f} dB" for v in (30, 120)) + ". "
               + (f"Brighter when harder ({high[120] - high[30]:+.1f} dB above the 10th partial"
                  + (", centroid up too" if centroid[120] > centroid[30] else
                     "; the centroid, dominated by the low partials, does not rise")
                  + "), as expected.\n" if brighter else
                  "**Not brighter when harder: the hammer model does not give the expected "
                  "timbre change.**\n"))
    out.append(code("\n".join(commands)))

    # Inharmonicity: partials of the velocity-30 note against n f0 sqrt(1 + B n²).
    x, r = notes[30]
    f, m = spectrum(x, r, 0.05, 1.5, pad=8)
    found, f0, b = [], C3, 0.0
    for n in range(1, 31):
        guess = n * f0 * math.sqrt(1 + b * n * n)
        if guess > 0.45 * r:
            break
        fn, level = peak(f, m, guess - 0.3 * f0, guess + 0.3 * f0)
        if level < 1e-4 * m.max():   # below -80 dB: no partial there
            continue
        found.append((n, fn))
        if len(found) >= 3:  # refit: (f_n / n)² = f0² + f0² B n²
            ns, fs = np.array(found, dtype=float).T
            slope, icept = np.polyfit(ns ** 2, (fs / ns) ** 2, 1)
            f0, b = math.sqrt(icept), slope / icept
    ns, fs = np.array(found, dtype=float).T
    model = ns * f0 * np.sqrt(1 + b * ns ** 2)
    cents = 1200 * np.log2(fs / model)
    fig, (a, c) = plt.subplots(1, 2, figsize=(11, 3.6))
    a.plot(ns, fs / (ns * f0), "o", ms=4, label="measured f_n / (n f₀)")
    nn = np.linspace(1, ns.max(), 200)
    a.plot(nn, np.sqrt(1 + b * nn ** 2), "k-", lw=1, label=f"√(1 + B n²), B = {b:.2e}")
    a.axhline(1.0, color="0.5", ls=":", lw=1, label="harmonic")
    a.set_xlabel("partial number n")
    a.set_ylabel("f_n / (n f₀)")
    a.legend()
    c.plot(ns, cents, "o-", ms=4)
    c.set_xlabel("partial number n")
    c.set_ylabel("measured − fitted (cents)")
    c.set_title("residual of the fit")
    fig.tight_layout()
    out.append("**Claim.** A stiff string's partials follow f_n = n f₀ √(1 + B n²) (the "
               "preset's strings have bending stiffness).\n")
    out.append(ctx.figure(fig, FIGURES[1], "Partials of the velocity-30 C3 (0.05–1.55 s, "
                                           "parabolic peak interpolation) against the fitted "
                                           "inharmonic series."))
    out.append(f"**Measured.** {len(found)} partials (n = 1 … {int(ns.max())}); least-squares fit "
               f"f₀ = {f0:.2f} Hz ({1200 * math.log2(f0 / C3):+.1f} cents from equal-tempered "
               f"C3), B = {b:.2e}; largest residual {np.max(np.abs(cents)):.1f} cents. "
               + ("The series fits (inharmonic, B > 0).\n" if b > 0 and np.max(np.abs(cents)) < 10
                  else "**The inharmonic series does not fit these partials well.**\n"))

    # Pitch glide: the rendered notes, and tension modulation against amplitude.
    out += glide(ctx, f0, notes, rate)

    # The gong: the energy cascade to high frequencies.
    gong_preset = ctx.source + "/presets/gong.toml"
    x, r = render(ctx, "gong", "C2:120:3.0", preset=gong_preset, tail=1.0)
    cut = 2000.0
    spans = [(0.0, 0.05), (0.3, 0.5), (1.0, 1.5), (2.5, 3.0)]
    frac = {}
    for a0, a1 in spans:
        f, m = spectrum(x, r, a0, a1 - a0, pad=1)
        p = m ** 2
        frac[a0, a1] = float(np.sum(p[f > cut]) / np.sum(p))
    fig, ax = plt.subplots(figsize=(9, 3.8))
    mesh = spectrogram(ax, x, r, 12000, "gong (presets/gong.toml), C2, velocity 120")
    fig.colorbar(mesh, ax=ax, label="dB re maximum")
    fig.tight_layout()
    out.append("**Claim.** A gong struck hard cascades energy from its low modes to high "
               "frequencies over the first fraction of a second (von Kármán coupling), the "
               "'shimmer' that builds after the strike.\n")
    out.append(ctx.figure(fig, FIGURES[3], "Spectrogram of a gong strike."))
    values = [frac[s] for s in spans]
    rises = max(values[1:]) > values[0]
    out.append(f"**Measured.** Fraction of the energy above {cut:.0f} Hz: "
               + ", ".join(f"{a0:g}–{a1:g} s: {100 * frac[a0, a1]:.2f} %" for a0, a1 in spans)
               + ". "
               + ("It rises after the strike: energy moves up in frequency, as claimed.\n"
                  if rises else
                  "**It does not rise after the strike: no cascade to high frequencies is "
                  "measured.**\n"))
    out.append(code(ctx.commands[-1]))
    return "\n".join(out)
