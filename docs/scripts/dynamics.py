#!/usr/bin/env python3
"""Dynamics of a piano preset (docs/validation.md, "Dynamics"; docs/instrument-data.md, "Dynamics:
loudness across velocity and register"): single notes across the keyboard at several MIDI
velocities, and a fortissimo pedalled passage against the master's ceiling.

For each key and velocity it renders the note alone (1 s held, 1 s of tail) with hamiltone-render
and reports its peak level (dBFS, the larger of the two channels) and the RMS of its first 0.5 s
(dBFS), then each level relative to the same key at velocity 127 beside the target of
docs/instrument-data.md: 20·log10(s(v)/s(127)), s(v) the preset's hammer speed at velocity v —
a tone's peak amplitude is proportional to the hammer's speed (Palmer & Brown 1991) — and the
deviation. With --passage it renders presets/dense-pedalled.mid with its velocities scaled so that
its loudest note is 127 (a fortissimo version of it) and reports the peak before the limiter, the
headroom to the 0.98 ceiling and whether the limiter acted (hamiltone-render's own summary line).

Usage (from the repository root; the preset by name or file, so the same run measures a later
version of the instrument, e.g. one with a soundboard):
  python3 docs/scripts/dynamics.py [--render build/dev/render/hamiltone-render]
      [--preset grand-piano] [--keys A0,C2,C4,C6,C8] [--velocities 20,64,100,127]
      [--set hammer.velocity_curve=2 ...] [--passage] [--tolerance 3]
Exit status 1 when a relative level misses its target by more than --tolerance dB, or the
passage's headroom is under --headroom dB (default 1). Python 3 standard library only.
"""

import argparse
import array
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read_float_wav(path):
    """The interleaved float32 samples of a WAV file hamiltone-render wrote with --format float32."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise ValueError(path + ": not a WAV file")
    at, channels, samples = 12, 2, None
    while at + 8 <= len(data):
        tag, size = data[at:at + 4], struct.unpack("<I", data[at + 4:at + 8])[0]
        body = data[at + 8:at + 8 + size]
        if tag == b"fmt ":
            channels = struct.unpack("<H", body[2:4])[0]
        elif tag == b"data":
            samples = array.array("f")
            samples.frombytes(body[: len(body) // 4 * 4])
        at += 8 + size + (size & 1)
    if samples is None:
        raise ValueError(path + ": no data chunk")
    return channels, samples


def db(x):
    return 20.0 * math.log10(x) if x > 0.0 else -math.inf


def preset_file(name):
    """A preset file, or a name looked for in the repository's presets/ (else left to the renderer)."""
    if os.path.exists(name):
        return name
    bundled = os.path.join(ROOT, "presets", name if name.endswith(".toml") else name + ".toml")
    return bundled if os.path.exists(bundled) else name


def render(args, out, extra):
    command = [args.render, "--preset", preset_file(args.preset), "-o", out, "--format", "float32"] + extra
    for s in args.set:
        command += ["--set", s]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("hamiltone-render failed: " + " ".join(command) + "\n" + done.stderr)
    limiter = [l for l in done.stderr.splitlines() if "limiter" in l]
    return limiter[-1].split(": ", 1)[1] if limiter else ""


def note_levels(args, key, velocity, scratch, rate):
    out = os.path.join(scratch, f"{key}-{velocity}.wav")
    limiter = render(args, out, ["--notes", f"{key}:{velocity}:1.0", "--tail", "1.0"])
    channels, x = read_float_wav(out)
    peak = max(abs(v) for v in x)
    head = x[: int(0.5 * rate) * channels]
    rms = math.sqrt(sum(v * v for v in head) / len(head))
    return db(peak), db(rms), "did not act" not in limiter


def hammer_speed(args, velocity):
    """The preset's velocity law, with --set overrides: min + (max − min)·(v/127)^curve."""
    law = {"velocity_min_m_s": 0.5, "velocity_max_m_s": 6.0, "velocity_curve": 1.0}
    preset = preset_file(args.preset)
    section = None
    for line in open(preset, encoding="utf-8"):
        line = line.split("#", 1)[0].strip()
        if line.startswith("["):
            section = line.strip("[]")
            continue
        m = re.match(r"(\w+)\s*=\s*([-0-9.eE+]+)$", line)
        if m and section == "hammer" and m.group(1) in law:
            law[m.group(1)] = float(m.group(2))
    for s in args.set:
        name, value = s.split("=", 1)
        if name.startswith("hammer.") and name[7:] in law:
            law[name[7:]] = float(value)
    lo, hi, curve = law["velocity_min_m_s"], law["velocity_max_m_s"], law["velocity_curve"]
    return lo + (hi - lo) * (velocity / 127.0) ** curve


def variable_length(data, i):
    """A MIDI variable-length quantity at data[i]: (its value, the index after it)."""
    n = 0
    while data[i] & 0x80:
        n = (n << 7) | (data[i] & 0x7F)
        i += 1
    return (n << 7) | data[i], i + 1


def fortissimo_midi(source, target, loudest=127):
    """A copy of a Standard MIDI File with every note-on velocity scaled so the loudest is `loudest`."""
    data = bytearray(open(source, "rb").read())
    ons = []  # (offset of the velocity byte, velocity)
    at = 14
    while at < len(data):
        size = struct.unpack(">I", data[at + 4:at + 8])[0]
        end, i, status = at + 8 + size, at + 8, 0
        while i < end:
            _, i = variable_length(data, i)  # the delta time
            if data[i] & 0x80:
                status = data[i]
                i += 1
            kind = status & 0xF0
            if status in (0xFF, 0xF0, 0xF7):  # meta (a type byte first) or system exclusive
                n, i = variable_length(data, i + (status == 0xFF))
                i += n
            elif kind in (0xC0, 0xD0):
                i += 1
            else:
                if kind == 0x90 and data[i + 1] > 0:
                    ons.append((i + 1, data[i + 1]))
                i += 2
        at = end
    top = max(v for _, v in ons)
    for offset, v in ons:
        data[offset] = max(1, min(127, round(v * loudest / top)))
    open(target, "wb").write(data)
    return top, len(ons)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--render", default=os.path.join(ROOT, "build/dev/render/hamiltone-render"))
    parser.add_argument("--preset", default="grand-piano")
    parser.add_argument("--keys", default="A0,C2,C4,C6,C8")
    parser.add_argument("--velocities", default="20,64,100,127")
    parser.add_argument("--set", action="append", default=[], help="a preset override, repeatable")
    parser.add_argument("--tolerance", type=float, default=3.0)
    parser.add_argument("--passage", action="store_true")
    parser.add_argument("--headroom", type=float, default=1.0)
    args = parser.parse_args()
    keys = args.keys.split(",")
    velocities = [int(v) for v in args.velocities.split(",")]
    if 127 not in velocities:
        velocities.append(127)
    rate = 48000
    failed = False
    with tempfile.TemporaryDirectory() as scratch:
        print(f"preset {args.preset} {' '.join('--set ' + s for s in args.set)}".rstrip())
        speeds = ", ".join(f"{v}: {hammer_speed(args, v):.2f}" for v in velocities)
        print(f"hammer speed (m/s) at velocity {speeds}\n")
        print("| key | velocity | peak dBFS | RMS 0.5 s dBFS | peak rel. 127 | target | deviation |")
        print("|---|---|---|---|---|---|---|")
        for key in keys:
            levels = {v: note_levels(args, key, v, scratch, rate) for v in velocities}
            top = levels[127][0]
            for v in velocities:
                peak, rms, limited = levels[v]
                target = db(hammer_speed(args, v) / hammer_speed(args, 127))
                miss = (peak - top) - target
                failed |= abs(miss) > args.tolerance or limited
                print(f"| {key} | {v} | {peak:.1f} | {rms:.1f} | {peak - top:+.1f} | {target:+.1f} "
                      f"| {miss:+.1f}{' LIMITED' if limited else ''} |")
        if args.passage:
            source = os.path.join(ROOT, "presets", "dense-pedalled.mid")
            midi = os.path.join(scratch, "ff.mid")
            top, notes = fortissimo_midi(source, midi)
            line = render(args, os.path.join(scratch, "ff.wav"), ["--midi", midi, "--tail", "3"])
            print(f"\npresets/dense-pedalled.mid, {notes} notes scaled by 127/{top} (its loudest, "
                  f"{top}, to 127): {line}")
            m = re.search(r"peak ([-+]?[0-9.]+) dBFS before the limiter|peak before it ([-+]?[0-9.]+)",
                          line)
            peak = float(m.group(1) or m.group(2)) if m else math.inf
            headroom = 20.0 * math.log10(0.98) - peak
            print(f"headroom to the ceiling: {headroom:.1f} dB (wanted >= {args.headroom} dB)")
            failed |= headroom < args.headroom
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
