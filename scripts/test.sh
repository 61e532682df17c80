#!/usr/bin/env bash
# README command 2 (and CI's): install what is missing, build everything with warnings as errors,
# and run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake -S . -B build/ci -G Ninja -DCMAKE_BUILD_TYPE=Release -DHAMILTONE_WERROR=ON >/dev/null
cmake --build build/ci
ctest --test-dir build/ci --output-on-failure -j "$(nproc)"
