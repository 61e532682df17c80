#!/usr/bin/env bash
# README command 1: install what is missing, build, and run the main job on bundled defaults —
# render the bundled demo (presets/demo.mid, written by scripts/make-demo-midi.py) on the
# grand-piano preset to demo.wav.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=OFF >/dev/null
cmake --build build/release

build/release/render/hamiltone-render --preset presets/grand-piano.toml \
    --midi presets/demo.mid -o demo.wav
