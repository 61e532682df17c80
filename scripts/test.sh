#!/usr/bin/env bash
# README command 2 (and CI's): install what is missing, build everything with warnings as errors,
# and run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
# For real, the packages of the failure once seen (JACK's development files, RtAudio, RtMidi and
# jackd2, which pull against each other), each removed (with what needs it) and installed again:
# the libraries vanish meanwhile, so only where asked — .ci/run asks on a CI machine it runs as
# root. Every listed package is checked by apt's simulation in the suite (install_deps_idempotent).
if [ "${HAMILTONE_CHECK_INSTALL_DEPS:-0}" = 1 ]; then
  ./scripts/check-install-deps.sh libjack-jackd2-dev librtaudio-dev librtmidi-dev jackd2 ||
    [ $? -eq 77 ]  # 77: not root, said why
fi
cmake -S . -B build/ci -G Ninja -DCMAKE_BUILD_TYPE=Release -DHAMILTONE_WERROR=ON >/dev/null
cmake --build build/ci

# The libFuzzer targets (tests/fuzz) need Clang and sanitizer flags, so they have a tree of their
# own; each fuzzes for HAMILTONE_FUZZ_SECONDS (30 s). Only their targets are built there. This runs
# before the main suite so that the suite's summary stays the last thing printed.
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DHAMILTONE_FUZZ=ON \
  -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=OFF -DHAMILTONE_BUILD_RENDER=OFF >/dev/null
cmake --build build/fuzz --target hamiltone_fuzzers
ctest --test-dir build/fuzz --output-on-failure

# The RealtimeSanitizer tests (tests/rtsan) need Clang 20 or later, Debian's clang-22; their tree,
# like the fuzzers', builds only their own targets (the engine compiled in with the player, or with
# the plugin and DPF's CLAP entry, or the player's MIDI input with RtMidi and libjack; without
# render/ and RtAudio). Any allocation, lock or syscall inside Player::render, the JACK MIDI
# input's process callback or the plugin's process call, or in the synthesizer's worker threads
# while they render keys, fails them.
CC=clang-22 CXX=clang++-22 cmake -S . -B build/rtsan -G Ninja -DHAMILTONE_RTSAN=ON \
  -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=OFF -DHAMILTONE_BUILD_RENDER=OFF >/dev/null
cmake --build build/rtsan --target hamiltone_rtsan_tests
ctest --test-dir build/rtsan --output-on-failure

ctest --test-dir build/ci --output-on-failure -j "$(nproc)"
