#!/usr/bin/env bash
# The dense pedalled performance (presets/dense-pedalled.mid, 41 s, up to 30 keys sounding) on the
# grand piano through hamiltone-render at 64 voices: the real-time factor of each run and their
# median (the machine may be shared: single runs are noisy), and the keys stolen.
#
#   bench/dense-performance.sh [BUILD_DIR (build/release)] [RUNS (3)]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}
runs=${2:-3}
out=$(mktemp --suffix=.wav)
trap 'rm -f "$out"' EXIT

factors=()
for ((run = 1; run <= runs; ++run)); do
  summary=$("$build/render/hamiltone-render" --midi presets/dense-pedalled.mid --voices 64 \
    -o "$out" 2>&1 >/dev/null)
  echo "$summary"
  factors+=("$(sed -n 's/.*real-time factor \([0-9.]*\).*/\1/p' <<<"$summary")")
done
median=$(printf '%s\n' "${factors[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p")
echo "dense-pedalled.mid at 64 voices: real-time factor $median (the median of $runs)"
