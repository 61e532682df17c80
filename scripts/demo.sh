#!/usr/bin/env bash
# README command 1: install what is missing, build, and run the main job on bundled defaults —
# the Fermi–Pasta–Ulam test of BDZ §4.1 with each scheme, printing its energy drift.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=OFF >/dev/null
cmake --build build/release

mkdir -p out
for scheme in sv sav sav-split marazzato; do
  build/release/render/hamiltone-sim fpu --scheme "$scheme" --alpha 100 --k 1e-3 --duration 1 \
      --out "out/fpu-$scheme.csv"
done
