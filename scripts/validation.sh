#!/usr/bin/env bash
# Regenerates the validation report: docs/validation.md and its figures docs/figures/*.png.
#   ./scripts/validation.sh [--quick] [--out DIR] [--build-dir DIR]
# --quick: shorter runs (about 2 minutes; exits non-zero if a basic check fails, e.g. the energy
#   drift of an energy-conserving scheme above 1e-10). --out DIR: write DIR/validation.md and
#   DIR/figures/ instead of docs/. --build-dir DIR: use that tree's hamiltone-sim and
#   hamiltone-render (and bench/hamiltone_bench_references, if built) as they are (no install, no
#   build); the ctest uses it. Without it the script installs what is missing and builds the
#   Release tree build/release, like scripts/demo.sh.
# Exit 77 (ctest's skip code) with --build-dir when Debian's python3-matplotlib is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

quick=()
out=docs
build_dir=
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=(--quick) ;;
    --out) out="${2:?--out needs a directory}"; shift ;;
    --build-dir) build_dir="${2:?--build-dir needs a directory}"; shift ;;
    *) echo "validation.sh: unknown argument '$1' (expected --quick, --out DIR, --build-dir DIR)" >&2
       exit 2 ;;
  esac
  shift
done

# Debian's interpreter, not a pyenv one that lacks matplotlib.
python=/usr/bin/python3
if [ -z "$build_dir" ]; then
  ./scripts/install-deps.sh
  # The benchmark program hamiltone_bench_references times BDZ Figs. 7 and 10.
  cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=ON >/dev/null
  cmake --build build/release --target hamiltone-sim hamiltone-render hamiltone_bench_references
  build_dir=build/release
elif ! "$python" -c 'import matplotlib, numpy' 2>/dev/null; then
  echo "validation.sh: $python has no matplotlib/numpy (scripts/install-deps.sh installs them); skipped"
  exit 77
fi

sim="$build_dir/render/hamiltone-sim"
render="$build_dir/render/hamiltone-render"
for b in "$sim" "$render"; do
  [ -x "$b" ] || { echo "validation.sh: $b is not built" >&2; exit 1; }
done

mkdir -p "$out/figures"
rm -f "$out"/figures/*.png
start=$SECONDS
status=0
"$python" docs/validation/report.py --sim "$sim" --render "$render" --out "$out" "${quick[@]}" ||
  status=$?

# Every figure the report links exists, and every figure written is linked.
for f in $(grep -o '](figures/[^)]*\.png)' "$out/validation.md" | sed 's/^](//; s/)$//'); do
  [ -s "$out/$f" ] || { echo "validation.sh: $out/validation.md links $f, which is missing" >&2; status=1; }
done
for f in "$out"/figures/*.png; do
  [ -e "$f" ] || continue
  grep -q "](figures/$(basename "$f"))" "$out/validation.md" ||
    { echo "validation.sh: $f is not linked from $out/validation.md" >&2; status=1; }
done
echo "validation.sh: $out/validation.md in $((SECONDS - start)) s (exit $status)"
exit $status
