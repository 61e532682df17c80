#!/usr/bin/env bash
# Regenerates the validation report: docs/validation.md and its figures docs/figures/*.png.
#   ./scripts/validation.sh [--quick] [--out DIR] [--build-dir DIR]
# --quick: shorter runs (about 2 minutes; exits non-zero if a basic check fails, e.g. the energy
#   drift of an energy-conserving scheme above 1e-10). --out DIR: write DIR/validation.md and
#   DIR/figures/ instead of docs/. --build-dir DIR: use that tree's hamiltone-sim and
#   hamiltone-render (and bench/hamiltone_bench_references and bench/hamiltone_validate_grids, if
#   built) as they are (no install, no build); the ctest uses it. Without it the script installs
#   what is missing and builds the Release tree build/release, like scripts/demo.sh.
# Exit 77 (ctest's skip code) with --build-dir when Debian's python3-matplotlib is missing.
set -euo pipefail

usage() { echo "validation.sh: $1 (usage: validation.sh [--quick] [--out DIR] [--build-dir DIR])" >&2; exit 2; }
quick=()
out=
build_dir=
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=(--quick) ;;
    --out) [ -n "${2:-}" ] || usage "--out needs a directory"; out="$2"; shift ;;
    --build-dir) [ -n "${2:-}" ] || usage "--build-dir needs a directory"; build_dir="$2"; shift ;;
    *) usage "unknown argument '$1'" ;;
  esac
  shift
done
# Paths given on the command line are the caller's: make them absolute before moving to the root.
case "$out" in /* | "") ;; *) out="$PWD/$out" ;; esac
if [ -n "$build_dir" ]; then
  case "$build_dir" in /*) ;; *) build_dir="$PWD/$build_dir" ;; esac
  [ -d "$build_dir" ] || usage "--build-dir $build_dir: no such directory"
fi
cd "$(dirname "$0")/.."
out=${out:-docs}
mkdir -p "$out" 2>/dev/null && [ -w "$out" ] || usage "--out $out: cannot create or write to it"

# Debian's interpreter, not a pyenv one that lacks matplotlib.
python=/usr/bin/python3
if [ -z "$build_dir" ]; then
  ./scripts/install-deps.sh
  # The benchmark program hamiltone_bench_references times BDZ Figs. 7 and 10;
  # hamiltone_validate_grids renders and times the string's grid rules.
  cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DHAMILTONE_BUILD_TESTS=OFF -DHAMILTONE_BUILD_BENCH=ON >/dev/null
  cmake --build build/release --target hamiltone-sim hamiltone-render hamiltone_bench_references \
        hamiltone_validate_grids
  build_dir=build/release
elif ! "$python" -c 'import matplotlib, numpy' 2>/dev/null; then
  echo "validation.sh: $python has no matplotlib/numpy (scripts/install-deps.sh installs them); skipped"
  exit 77
fi

sim="$build_dir/sim/hamiltone-sim"
render="$build_dir/render/hamiltone-render"
# Optional: a tree built without the benchmarks lacks it, and its section says so.
grids="$build_dir/bench/hamiltone_validate_grids"
for b in "$sim" "$render"; do
  [ -x "$b" ] || { echo "validation.sh: $b is not built" >&2; exit 1; }
done

# The report is written to a fresh directory beside the old one and replaces it only when the run
# has finished, so an interrupted run leaves the previous report and its figures intact.
work=$(mktemp -d "$out/.validation-XXXXXX")
trap 'rm -rf "$work"' EXIT
start=$SECONDS
status=0
"$python" docs/validation/report.py --sim "$sim" --render "$render" --grids "$grids" \
  --out "$work" "${quick[@]}" ||
  status=$?
[ -f "$work/validation.md" ] || { echo "validation.sh: the report was not written" >&2; exit 1; }
mkdir -p "$out/figures"
rm -f "$out"/figures/*.png
mv "$work"/figures/*.png "$out/figures/" 2>/dev/null || true
mv "$work/validation.md" "$out/validation.md"

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
