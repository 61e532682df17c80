"""Dynamics: each key's peak level across MIDI velocity against the velocity law of
docs/instrument-data.md §5 (a tone's peak ∝ the hammer's speed, Palmer & Brown 1991), the levels
of the registers at one velocity, and a fortissimo pedalled passage against the master's ceiling.
Runs docs/scripts/dynamics.py (which renders with hamiltone-render) and reports its table."""
import re
import sys

from common import code

TITLE = "Dynamics: loudness across velocity and register, and the master's headroom"
FIGURES = []

KEYS = "A0,C1,C2,C3,C4,C5,C6,C7,C8"
TOLERANCE = 3.0  # dB, of each relative level against the law (docs/instrument-data.md §5.4)
EVEN = 1.0       # dB, of the velocity-100 peaks about their mean (the per-register gains)
HEADROOM = 1.0   # dB under the 0.98 ceiling, wanted of the fortissimo passage


def run(ctx):
    script = ctx.source + "/docs/scripts/dynamics.py"
    args = [sys.executable, script, "--render", ctx.render, "--preset", "grand-piano",
            "--tolerance", TOLERANCE, "--headroom", HEADROOM]
    if ctx.quick:
        args += ["--keys", "C4", "--velocities", "64,100,127"]
    else:
        args += ["--keys", KEYS, "--velocities", "20,64,100,127", "--passage"]
    text, seconds = ctx.run(args, allow_fail=True)
    rows = re.findall(r"^\| (\S+) \| (\d+) \| (\S+) \| (\S+) \| (\S+) \| (\S+) \| (\S+?)( LIMITED)? \|$",
                      text, re.M)
    table = [l for l in text.splitlines() if l.startswith("|")]
    worst = max(rows, key=lambda r: abs(float(r[6])))
    forte = [float(r[2]) for r in rows if r[1] == "100"]
    spread = max(forte) - min(forte) if forte else float("nan")
    limited = [r for r in rows if r[7]]
    out = [
        "**Claim.** Each key's peak level at velocity v, relative to the same key at 127, follows "
        "20·log10(s(v)/s(127)) for the preset's hammer-speed law s (docs/instrument-data.md §5.2–5.3: "
        "peak ∝ hammer speed, [PB91]; s = 0.5 + 5.5·(v/127)² m/s, a square law reaching [RR98]'s "
        f"6 m/s) within ±{TOLERANCE:g} dB across the keyboard; at velocity 100 the registers peak "
        f"within ±{EVEN:g} dB of each other (the per-register pickup gains of §5.4, an engineering "
        "choice); no single note makes the master's limiter act.",
        "",
        next(l for l in text.splitlines() if l.startswith("hammer speed")) + ".",
        "",
        *table,
        "",
        f"**Measured.** Largest deviation from the law: {float(worst[6]):+.1f} dB ({worst[0]}, "
        f"velocity {worst[1]}); velocity-100 peaks from {min(forte):.1f} to {max(forte):.1f} dBFS "
        f"(spread {spread:.1f} dB); limiter acted on {len(limited)} of {len(rows)} notes.",
        ctx.check(abs(float(worst[6])) <= TOLERANCE and not limited,
                  f"every relative level within ±{TOLERANCE:g} dB and no limiting"),
        ctx.check(spread <= 2 * EVEN, f"velocity-100 peaks within ±{EVEN:g} dB"),
        "",
        code(ctx.commands[-1]),
    ]
    if not ctx.quick:
        passage = next((l for l in text.splitlines() if l.startswith("presets/dense-pedalled")), "")
        room = re.search(r"headroom to the ceiling: (-?[0-9.]+|-inf) dB", text)
        headroom = float(room.group(1)) if room else float("-inf")
        out += [
            "",
            "**Claim.** The fortissimo pedalled passage — presets/dense-pedalled.mid with every "
            "note-on velocity scaled so its loudest note is 127 — stays at least "
            f"{HEADROOM:g} dB under the master's 0.98 ceiling, and the limiter does not act "
            "(the preset's gain_dB is set for it).",
            "",
            f"**Measured.** {passage}; headroom {headroom:.1f} dB.",
            ctx.check(headroom >= HEADROOM and "did not act" in passage,
                      f"the passage at least {HEADROOM:g} dB under the ceiling, limiter idle"),
        ]
    out += [
        "",
        "The limiter itself (engine/synth/master_bus.h, `PeakLimiter`) is tested on its own in "
        "tests/synth/master_bus_test.cpp — bit-transparent below the ceiling, a +12 dB step held "
        "at the ceiling with no overshoot, the hold and the release time constant measured to the "
        "frame, never above the ceiling on noise, deterministic — and allocates nothing "
        "(`NoAllocation.MasterBusLimiting`).",
    ]
    return "\n".join(out)
