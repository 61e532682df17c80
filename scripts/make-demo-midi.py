#!/usr/bin/env python3
"""Writes the bundled demo MIDI file (default presets/demo.mid): about 18.6 s of solo piano.

A Standard MIDI File, format 1, 480 ticks a quarter note:
  track 0  the tempo track: 112 bpm, slowing to 84 bpm for the last two bars;
  track 1  the piano (channel 1): eight bars of I-vi-IV-V-I-IV-V7-I in C, a bass note and a
           three-note chord in each bar, and a melody above them in the middle register
           (MIDI 64-79), rising from about velocity 40 to 120 and falling back to about 30; the
           sustain pedal (CC64) is pressed after each chord and released before the next.
Most notes end with a note-on of velocity 0 and the bass notes with a note-off, and consecutive
channel messages share a status byte (running status), so the file exercises what real files do.
Every note is within MIDI 36-96. Python 3 standard library only.
"""

import struct

from smf import (CONTROLLER, NOTE_OFF, NOTE_ON, PROGRAM, SUSTAIN, chunk, meta, track_chunk,
                 write_file)

DIVISION = 480  # ticks per quarter note
BAR = 4 * DIVISION
LEGATO = 0.95  # a note sounds for this fraction of its written length
CHANNEL = 0

# (bass, chord) for each bar.
HARMONY = [
    (36, (52, 55, 60)),  # C
    (45, (52, 57, 60)),  # Am
    (41, (53, 57, 60)),  # F
    (43, (50, 55, 59)),  # G
    (36, (52, 55, 60)),  # C
    (41, (53, 57, 60)),  # F
    (43, (53, 55, 59)),  # G7
    (36, (48, 52, 55)),  # C
]
# The melody, bar by bar: (start beat in the bar, length in beats, MIDI note).
MELODY = [
    [(0, 1, 64), (1, 1, 67), (2, 2, 72)],
    [(0, 0.5, 72), (0.5, 0.5, 71), (1, 1, 69), (2, 2, 64)],
    [(0, 1, 65), (1, 1, 69), (2, 1, 72), (3, 1, 77)],
    [(0, 0.5, 76), (0.5, 0.5, 74), (1, 1, 74), (2, 2, 71)],
    [(0, 1, 72), (1, 1, 76), (2, 2, 79)],
    [(0, 0.5, 77), (0.5, 0.5, 76), (1, 1, 74), (2, 2, 72)],
    [(0, 1, 71), (1, 1, 74), (2, 1, 77), (3, 1, 74)],
    [(0, 4, 72)],
]
SLOW_BAR = 6  # the bar (from 0) where the tempo falls
TEMPI = [(0, 60_000_000 // 112), (SLOW_BAR * BAR, 60_000_000 // 84)]  # (tick, µs a quarter)


def dynamics(beat):
    """The melody's velocity at a beat: 40 rising to 120 at beat 18 (bar 5), then down to 30."""
    if beat <= 18:
        return round(40 + (120 - 40) * beat / 18)
    return round(120 - (120 - 30) * (beat - 18) / 14)


def tempo_track(end):
    events = [(0, 0, meta(0x03, b"Hamiltone demo")),
              (0, 1, meta(0x58, bytes([4, 2, 24, 8])))]  # 4/4
    events += [(tick, 2, meta(0x51, micros.to_bytes(3, "big"))) for tick, micros in TEMPI]
    events.append((end, 9, meta(0x2F, b"")))
    return track_chunk(events)


def piano_track(end):
    # Order at equal ticks: releases, then the pedal, then new notes.
    events = [(0, 0, meta(0x03, b"Piano")), (0, 1, bytes([PROGRAM | CHANNEL, 0]))]

    def note(start, length, key, velocity, note_off=False):
        assert 36 <= key <= 96 and 1 <= velocity <= 127
        stop = start + round(length * LEGATO)
        events.append((start, 4, bytes([NOTE_ON | CHANNEL, key, velocity])))
        release = [NOTE_OFF | CHANNEL, key, 64] if note_off else [NOTE_ON | CHANNEL, key, 0]
        events.append((stop, 2, bytes(release)))

    for bar, ((bass, chord), melody) in enumerate(zip(HARMONY, MELODY)):
        start = bar * BAR
        level = dynamics(4 * bar)
        note(start, BAR, bass, max(30, round(0.8 * level)), note_off=True)
        for beat in (0, 2):
            for key in chord:
                note(start + beat * DIVISION, 2 * DIVISION, key, max(30, round(0.6 * level)))
        for beat, length, key in melody:
            note(start + round(beat * DIVISION), length * DIVISION, key, dynamics(4 * bar + beat))
        events.append((start + 40, 3, bytes([CONTROLLER | CHANNEL, SUSTAIN, 127])))
        events.append((start + BAR - 10, 3, bytes([CONTROLLER | CHANNEL, SUSTAIN, 0])))
    events.append((end, 9, meta(0x2F, b"")))
    return track_chunk(events)


def demo():
    end = len(HARMONY) * BAR
    header = chunk(b"MThd", struct.pack(">HHH", 1, 2, DIVISION))
    return header + tempo_track(end) + piano_track(end)


def main():
    write_file(__doc__, "demo.mid", demo())


if __name__ == "__main__":
    main()
