#!/usr/bin/env python3
"""Writes the seed corpus of the MIDI file fuzzer (tests/fuzz/corpus/midi/): small files, valid
and not, that between them reach every branch of engine/midi/midi_file.cpp, so that libFuzzer
starts from the grammar instead of discovering "MThd" and "MTrk" byte by byte.

Usage: tests/fuzz/make-midi-corpus.py [directory]. Python 3 standard library only.
"""

import pathlib
import struct
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
from smf import chunk, variable_length  # noqa: E402


def header(fmt, tracks, division):
    return chunk(b"MThd", struct.pack(">HHH", fmt, tracks, division))


def track(*events):
    """An MTrk chunk of (delta, event bytes) pairs, written as given."""
    return chunk(b"MTrk", b"".join(variable_length(d) + e for d, e in events))


END = (0, b"\xff\x2f\x00")


def tempo(micros):
    return b"\xff\x51\x03" + micros.to_bytes(3, "big")


def seeds():
    notes = track((0, tempo(500000)), (0, b"\x90\x3c\x64"), (0, b"\x40\x50"),  # running status
                  (480, b"\x3c\x00"), (0, b"\x80\x40\x40"), (0, b"\xb0\x40\x7f"),
                  (0, b"\xc0\x05"), (0, b"\x06"), (0, b"\xe0\x00\x40"), (0, b"\xa0\x3c\x10"),
                  (0, b"\xd0\x20"), END)
    valid = {
        "format0.mid": header(0, 1, 480) + notes,
        "format1-tempo-map.mid": header(1, 3, 96)
        + track((0, tempo(600000)), (192, tempo(250000)), END)
        + track((0, b"\x90\x30\x50"), (96, b"\x30\x00"), (96, b"\x34\x60"), END)
        + track((96, b"\x91\x43\x70"), (0, tempo(400000)), (96, b"\x81\x43\x00"), (96, END[1])),
        "meta-sysex-running-status.mid": header(0, 1, 480)
        + track((0, b"\x90\x3c\x64"), (10, b"\xff\x01\x02hi"), (0, b"\x3e\x64"),
                (0, b"\xf0\x05\x7e\x7f\x09\x01\xf7"), (10, b"\x3c\x00"),
                (0, b"\xf7\x04\xff\x2f\x00\xf8"), (0, b"\x3e\x00"), END),
        "smpte-29.97.mid": header(0, 1, 0xE350) + notes,
        "smpte-25.mid": header(0, 1, 0xE728) + notes,
        "unknown-chunks.mid": chunk(b"MThd", struct.pack(">HHHH", 1, 2, 480, 0xABCD))
        + chunk(b"XFIH", b"MTrk\x00\x00") + notes + chunk(b"\x00\x01\x02\x03", b"")
        + track((0, b"\x90\x3c\x64"), (960, b"\x3c\x00"))  # no End of Track
        + b"trailing",
        "after-end-of-track.mid": header(0, 1, 480) + track(END, (0, b"\xf8\xf1\xff")),
    }
    invalid = {
        "bad-missing-mthd.mid": b"RIFF\x00\x00\x00\x06\x00\x00\x00\x01\x00\x60",
        "bad-short-header.mid": chunk(b"MThd", b"\x00\x00\x00\x01") + track(END),
        "bad-chunk-past-end.mid": (header(0, 1, 480) + notes)[:-5],
        "bad-track-count.mid": header(1, 0xFFFF, 480) + track(END),
        "bad-format-2.mid": header(2, 1, 480) + track(END),
        "bad-division-0.mid": header(0, 1, 0) + track(END),
        "bad-smpte-rate.mid": header(0, 1, 0x9C28) + track(END),
        "bad-long-number.mid": header(0, 1, 480)
        + chunk(b"MTrk", b"\x81\x80\x80\x80\x00\x90\x3c\x64"),
        "bad-no-running-status.mid": header(0, 1, 480)
        + track((0, b"\xff\x01\x00"), (0, b"\x3c\x64"), END),
        "bad-data-byte.mid": header(0, 1, 480) + track((0, b"\x90\x3c\x80"), END),
        "bad-system-common.mid": header(0, 1, 480) + track((0, b"\x90\x3c\x64"), (0, b"\xf2\x00"), END),
        "bad-tempo-length.mid": header(0, 1, 480) + track((0, b"\xff\x51\x02\x07\xa1"), END),
        "bad-sysex-past-end.mid": header(0, 1, 480) + chunk(b"MTrk", b"\x00\xf0\x10\x01"),
    }
    return {**valid, **invalid}


def main():
    here = pathlib.Path(__file__).resolve().parent
    directory = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else here / "corpus" / "midi"
    directory.mkdir(parents=True, exist_ok=True)
    for name, data in seeds().items():
        (directory / name).write_bytes(data)


if __name__ == "__main__":
    main()
