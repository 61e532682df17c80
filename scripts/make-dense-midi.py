#!/usr/bin/env python3
"""Writes the bundled dense performance (default presets/dense-pedalled.mid): about 41 s of
pedalled piano across the keyboard (MIDI 27-99), for the voice-stealing test and the polyphony
benchmark — arpeggiated chords in the manner of a Romantic etude, under a melody.

A Standard MIDI File, format 1, 480 ticks a quarter note:
  track 0  the tempo track: 96 bpm, slowing to 88 and then 76 bpm for the last two bars;
  track 1  the piano (channel 1): sixteen bars in E-flat major, a harmony a bar (bars 5-6, 9-10
           and the climax 13-14 hold one for two); in each bar a bass octave from MIDI 27-36, an
           arpeggio of the harmony over four octaves from the octave above the bass (an octave
           higher in a harmony's second bar), half the bar rising, half falling back through
           the tones it skipped, in sixteenths (sextuplets in bars 11-14), two soft chords
           under the melody, and the melody (MIDI 70-92, doubled an octave down in bars 12-15),
           from about velocity 50 up to 115 at bar 13 and down to 45. The sustain pedal (CC64)
           is pressed just after each change of harmony and lifted just before the next, as a
           pianist pedals legato, so every key of a harmony rings until it changes.
Over 400 notes start in the first 40 s, and with the pedal over 20 keys are held at once (down
or sustained): it checks both, and prints them. Deterministic; Python 3 standard library only.
"""

import struct

from smf import (CONTROLLER, NOTE_OFF, NOTE_ON, PROGRAM, SUSTAIN, chunk, meta, track_chunk,
                 write_file)

DIVISION = 480  # ticks per quarter note
BAR = 4 * DIVISION
LEGATO = 0.95  # a note sounds for this fraction of its written length
CHANNEL = 0
PEDAL_DOWN_AFTER, PEDAL_UP_BEFORE = 30, 15  # ticks after a change of harmony, before the next

EB, C, AB, BB, G, F = 3, 0, 8, 10, 7, 5  # pitch classes
# Each harmony: (bars it lasts, bass note, its pitch classes, the arpeggio's notes a beat).
HARMONY = [
    (1, 27, (EB, G, BB), 4),  # E♭
    (1, 36, (C, EB, G), 4),  # Cm
    (1, 32, (AB, C, EB), 4),  # A♭
    (1, 34, (BB, 2, F, AB), 4),  # B♭7
    (2, 31, (EB, G, BB), 4),  # E♭/G
    (1, 29, (F, AB, C, EB), 4),  # Fm7
    (1, 34, (BB, 2, F, AB), 4),  # B♭7
    (2, 32, (AB, C, EB, G), 4),  # A♭maj7
    (1, 34, (EB, G, BB), 6),  # E♭/B♭
    (1, 34, (BB, 2, F, AB), 6),  # B♭7
    (2, 32, (AB, C, EB, BB), 6),  # A♭add9, the climax
    (1, 34, (BB, 2, F, AB), 4),  # B♭7
    (1, 27, (EB, G, BB), 4),  # E♭
]
# The melody, bar by bar: (start beat in the bar, length in beats, MIDI note).
MELODY = [
    [(0, 1.5, 79), (1.5, 0.5, 77), (2, 1, 75), (3, 1, 82)],
    [(0, 2, 84), (2, 1, 82), (3, 1, 79)],
    [(0, 1.5, 80), (1.5, 0.5, 79), (2, 1, 77), (3, 1, 75)],
    [(0, 2, 77), (2, 1, 74), (3, 1, 70)],
    [(0, 1, 75), (1, 1, 79), (2, 1.5, 82), (3.5, 0.5, 84)],
    [(0, 2, 87), (2, 1, 82), (3, 1, 79)],
    [(0, 1.5, 84), (1.5, 0.5, 82), (2, 1, 80), (3, 1, 77)],
    [(0, 2, 82), (2, 1, 80), (3, 1, 74)],
    [(0, 1, 75), (1, 1, 79), (2, 2, 84)],
    [(0, 1.5, 87), (1.5, 0.5, 84), (2, 1, 79), (3, 1, 80)],
    [(0, 2, 82), (2, 1, 79), (3, 1, 75)],
    [(0, 1, 77), (1, 1, 80), (2, 1, 86), (3, 1, 89)],
    [(0, 2, 92), (2, 1, 91), (3, 1, 87)],
    [(0, 1.5, 84), (1.5, 0.5, 87), (2, 1, 89), (3, 1, 87)],
    [(0, 2, 86), (2, 1, 84), (3, 1, 82)],
    [(0, 4, 87)],
]
DOUBLED = range(11, 15)  # bars (from 0) whose melody is doubled an octave down
TEMPI = [(0, 96), (14 * BAR, 88), (15 * BAR, 76)]  # (tick, bpm)


def dynamics(bar):
    """The level of a bar: 50 rising to 115 at bar 12 (from 0), the climax, then down to 45."""
    if bar <= 12:
        return round(50 + (115 - 50) * bar / 12)
    return round(115 - (115 - 45) * (bar - 12) / 3)


def chord_tones(classes, low, high):
    return [k for k in range(low, high + 1) if k % 12 in classes]


def spread(tones, steps):
    """An arpeggio of `steps` notes over `tones` (ascending, at least steps / 2 of them): half
    rising from the lowest to the highest, half falling back between them, each half through
    tones spread evenly, so the fall strikes many the rise skipped."""
    half = steps // 2

    def even(keys, count):
        return [keys[round(i * (len(keys) - 1) / (count - 1))] for i in range(count)]

    return even(tones, half) + even(tones[-2:0:-1], steps - half)


def seconds_at(tick):
    """The time of a tick under TEMPI."""
    t, last_tick, bpm = 0.0, 0, TEMPI[0][1]
    for at, next_bpm in TEMPI[1:]:
        if at >= tick:
            break
        t += (at - last_tick) / DIVISION * 60 / bpm
        last_tick, bpm = at, next_bpm
    return t + (tick - last_tick) / DIVISION * 60 / bpm


def performance():
    """The notes as (start, stop, key, velocity) and the pedal as (down tick, up tick)."""
    notes, pedal = [], []
    bar = 0
    for bars, bass, classes, per_beat in HARMONY:
        start = bar * BAR
        length = bars * BAR
        pedal.append((start + PEDAL_DOWN_AFTER, start + length - PEDAL_UP_BEFORE))
        for b in range(bars):
            at = start + b * BAR
            level = dynamics(bar + b)
            if b == 0:
                for key in (bass, bass + 12):
                    notes.append((at, start + length, key, round(0.8 * level)))
            # Four octaves of the harmony from the octave above the bass (an octave higher in a
            # second bar of it): half the bar rising over them, half falling back through the
            # tones it skipped, as the hand does in a wide arpeggio.
            steps = 4 * per_beat
            tones = chord_tones(classes, bass + 12 * (b + 1), min(bass + 12 * (b + 1) + 48, 100))
            path = spread(tones, steps)
            tick = BAR // steps
            for i, key in enumerate(path):
                shape = 1.0 + 0.15 * min(i, steps - i) / (steps // 2)
                notes.append((at + i * tick, at + (i + 1) * tick, key, round(0.5 * level * shape)))
            for beat, beats, key in MELODY[bar + b]:
                on = at + round(beat * DIVISION)
                off = on + round(beats * DIVISION)
                notes.append((on, off, key, level))
                if bar + b in DOUBLED:
                    notes.append((on, off, key - 12, round(0.85 * level)))
            for beat in (0, 2):
                top = min(k for t, _, k in MELODY[bar + b] if t <= beat + 1) - 3
                for key in chord_tones(classes, 55, top)[-3:]:
                    on = at + beat * DIVISION
                    notes.append((on, on + 2 * DIVISION, key, round(0.45 * level)))
        bar += bars
    return legato(notes), pedal


def legato(notes):
    """Each note shortened to LEGATO of its length, and a key struck again before it was let go
    let go just before: a file never strikes a key that is down (a reader could not tell which
    note-off ends which note). Of two notes of a key at one tick, the louder stays."""
    by_key = {}
    for start, stop, key, velocity in sorted(notes, key=lambda n: (n[2], n[0], -n[3])):
        assert 21 <= key <= 108 and 1 <= velocity <= 127, (key, velocity)
        stop = start + max(1, round((stop - start) * LEGATO))
        same = by_key.setdefault(key, [])
        if same and same[-1][0] == start:
            continue
        if same and same[-1][1] > start:
            same[-1] = (same[-1][0], start, key, same[-1][3])
        same.append((start, stop, key, velocity))
    return sorted(n for same in by_key.values() for n in same)


def most_held(notes, pedal):
    """The most keys held at once, down or kept by the pedal, over the performance."""
    events = [(on, 1, ("on", k)) for on, _, k, _ in notes]
    events += [(off, 0, ("off", k)) for _, off, k, _ in notes]
    events += [(down, 0, ("down", None)) for down, _ in pedal]
    events += [(up, 0, ("up", None)) for _, up in pedal]
    down, sustained, pressed, most = set(), set(), False, 0
    for _, _, (kind, key) in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == "on":
            down.add(key)
            sustained.discard(key)
        elif kind == "off":
            down.discard(key)
            if pressed:
                sustained.add(key)
        else:
            pressed = kind == "down"
            if not pressed:
                sustained.clear()
        most = max(most, len(down | sustained))
    return most


def tempo_track(end):
    events = [(0, 0, meta(0x03, b"Hamiltone dense pedalled performance")),
              (0, 1, meta(0x58, bytes([4, 2, 24, 8])))]  # 4/4
    events += [(tick, 2, meta(0x51, (60_000_000 // bpm).to_bytes(3, "big")))
               for tick, bpm in TEMPI]
    events.append((end, 9, meta(0x2F, b"")))
    return track_chunk(events)


def piano_track(notes, pedal, end):
    # Order at equal ticks: releases, then the pedal, then new notes.
    events = [(0, 0, meta(0x03, b"Piano")), (0, 1, bytes([PROGRAM | CHANNEL, 0]))]
    for start, stop, key, velocity in notes:
        events.append((start, 4, bytes([NOTE_ON | CHANNEL, key, velocity])))
        events.append((stop, 2, bytes([NOTE_OFF | CHANNEL, key, 64])))
    for down, up in pedal:
        events.append((down, 3, bytes([CONTROLLER | CHANNEL, SUSTAIN, 127])))
        events.append((up, 3, bytes([CONTROLLER | CHANNEL, SUSTAIN, 0])))
    events.append((end, 9, meta(0x2F, b"")))
    return track_chunk(events)


def main():
    notes, pedal = performance()
    end = sum(h[0] for h in HARMONY) * BAR
    early = sum(1 for n in notes if seconds_at(n[0]) < 40.0)
    held = most_held(notes, pedal)
    assert early >= 400 and held >= 20, (early, held)
    header = chunk(b"MThd", struct.pack(">HHH", 1, 2, DIVISION))
    path = write_file(__doc__, "dense-pedalled.mid",
                      header + tempo_track(end) + piano_track(notes, pedal, end))
    print(f"{path}: {len(notes)} notes ({early} in the first 40 s) over {seconds_at(end):.1f} s, "
          f"at most {held} keys held at once")


if __name__ == "__main__":
    main()
