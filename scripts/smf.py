"""Standard MIDI File bytes, for the scripts that write the project's MIDI files (the demo, the
dense performance and the fuzzer's seed corpus). Python 3 standard library only."""

import argparse
import pathlib
import struct

NOTE_OFF, NOTE_ON, CONTROLLER, PROGRAM = 0x80, 0x90, 0xB0, 0xC0  # channel message statuses
SUSTAIN = 64  # the sustain pedal's controller number


def variable_length(value):
    """A MIDI variable-length number: 7 bits a byte, the top bit set on all but the last."""
    out = [value & 0x7F]
    value >>= 7
    while value:
        out.append(0x80 | (value & 0x7F))
        value >>= 7
    return bytes(reversed(out))


def chunk(kind, data):
    """A chunk: its 4-byte type, its length (big-endian), its data."""
    return kind + struct.pack(">I", len(data)) + data


def meta(kind, data):
    """A meta event: 0xFF, its type, its length, its data."""
    return bytes([0xFF, kind]) + variable_length(len(data)) + data


def track_chunk(events):
    """An MTrk chunk from (tick, order, event bytes), sorted by tick then order. A channel
    message whose status repeats the previous one is written without it (running status); a
    meta event ends the run, as the SMF specification asks, so strict readers agree."""
    body = bytearray()
    now, running = 0, None
    for tick, _, event in sorted(events, key=lambda e: (e[0], e[1])):
        body += variable_length(tick - now)
        now = tick
        if event[0] == 0xFF:
            running = None
            body += event
        elif event[0] == running:
            body += event[1:]
        else:
            running = event[0]
            body += event
    return chunk(b"MTrk", bytes(body))


def write_file(doc, name, data):
    """The command line of a script that writes a bundled MIDI file: `doc` (its docstring) for
    --help, the path to write as the optional argument, presets/`name` by default. Writes `data`
    and returns the path."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    default = pathlib.Path(__file__).resolve().parent.parent / "presets" / name
    parser.add_argument("path", nargs="?", default=default, type=pathlib.Path,
                        help=f"the file to write (default: presets/{name} in the repository)")
    path = parser.parse_args().path
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path
