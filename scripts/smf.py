"""Standard MIDI File bytes, for the scripts that write the project's MIDI files (the demo and the
fuzzer's seed corpus). Python 3 standard library only."""

import struct


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
