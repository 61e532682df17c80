#!/usr/bin/env python3
"""The string's grid rules on keys and velocities the validation report does not measure
(docs/string-grids.md, "Keys the report does not measure"): reads the output directory of
bench/hamiltone_validate_grids and prints, per key and velocity, the two grids' glide and
between-partials level against the converged string's, measured as the report measures them
(docs/validation/sections/string_grids.py).
Usage: /usr/bin/python3 docs/scripts/string_grids_held_out.py DIR"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "validation"))
sys.path.insert(0, os.path.join(HERE, "..", "validation", "sections"))
import string_grids as grids  # noqa: E402


def main(out):
    partials = {}
    for r in grids.read_rows(os.path.join(out, "partials.csv")):
        partials.setdefault((int(r["midi"]), r["config"], r["kind"]), []).append(float(r["hz"]))
    runs = {}
    for r in grids.read_rows(os.path.join(out, "runs.csv")):
        midi, config = int(r["midi"]), r["config"]
        x = np.fromfile(os.path.join(out, r["file"]), dtype="<f4").astype(float)
        linear = np.array(partials[midi, config, "transverse"])
        r.update(grids.analyse(x, float(r["f0_hz"]), linear,
                               partials[midi, config, "longitudinal"][0], midi))
        r["linear"] = linear
        runs[midi, int(r["velocity"]), config] = r
    print("| key | vel. | u/v segments (2G) | L's oversampling | glide 2G | glide L (cents) | 2G ÷ L "
          "| between 2G | between L (dB) | 2G − L (dB) | outside both bands (dB) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for (midi, velocity, config), g in sorted(runs.items()):
        if config != "two-grid":
            continue
        ref = runs[midi, velocity, "longitudinal"]
        ratio = g["glide"] / ref["glide"]
        held = abs(ref["glide"]) > grids.GLIDE_FLOOR
        both = grids.common_bands_diff(g, ref, g["linear"], ref["linear"])
        print(f"| {g['note']} | {velocity} | {g['segments']}/{g['longitudinal_segments']} "
              f"| ×{ref['oversampling']} | {g['glide']:+.2f} | {ref['glide']:+.2f} "
              f"| {ratio:.2f}{'' if held else ' (not held)'} | {g['phantom']:.1f} "
              f"| {ref['phantom']:.1f} | {g['phantom'] - ref['phantom']:+.1f} | {both:+.1f} |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.splitlines()[-1])
    main(sys.argv[1])
