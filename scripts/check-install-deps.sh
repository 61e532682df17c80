#!/usr/bin/env bash
# Checks that scripts/install-deps.sh is idempotent from any partial install: for each package it
# lists (or each one named on the command line), remove that package — and what depends on it —
# then run the install, and require every listed package to be installed afterwards. (A
# machine missing only librtaudio-dev once got jackd1's libjack-dev, which removed jackd2; the
# next run put jackd2 back and removed librtaudio-dev.)
#
#   check-install-deps.sh [--simulate] [PACKAGE ...]
#
# --simulate changes nothing: apt works on a copy of dpkg's status with the removal applied
# (apt-get -s -o Dir::State::status=…), the install is apt's simulated transaction, and the check
# is on its result. Needs apt's package lists; fast (about a second a package); any user. Without
# it the packages are really removed and reinstalled: root only, minutes, and it takes the
# libraries away from anything building meanwhile — for a disposable CI machine (.ci/run runs it
# there when HAMILTONE_CHECK_INSTALL_DEPS=1). Exit 0 all held, 1 one did not (named), 2 bad use,
# 77 cannot run here (no root, or no apt lists).
set -euo pipefail
cd "$(dirname "$0")/.."

simulate=0
if [ "${1:-}" = "--simulate" ]; then
  simulate=1
  shift
fi
mapfile -t listed < <(./scripts/install-deps.sh --list)
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=("${listed[@]}")

if [ $simulate -eq 0 ] && [ "$(id -u)" -ne 0 ]; then
  echo "check-install-deps: removing packages needs root (or use --simulate)" >&2
  exit 77
fi
if [ $simulate -eq 1 ] && ! ls /var/lib/apt/lists/*_Packages* >/dev/null 2>&1; then
  echo "check-install-deps: no apt package lists (run apt-get update)" >&2
  exit 77
fi

# The packages apt's output for a transaction marks with `verb` ("Inst" or "Remv"), without arch.
marked() { awk -v verb="$1" '$1 == verb { sub(/:.*/, "", $2); print $2 }'; }

# `1` and every installed package that depends on it, directly or through others (as one of
# alternatives too): what a machine that never had it lacks. (apt-get remove would instead swap
# in an alternative — jackd1's libjack-dev for libjack-jackd2-dev — which is another state.)
closure() {
  apt-cache rdepends --installed --recurse --no-suggests --no-recommends --no-enhances \
    --no-breaks --no-conflicts --no-replaces "$1" |
    awk '/^[^ ]/ && $0 != "Reverse Depends:" { sub(/:.*/, ""); print }' | sort -u
}

failed=0
for target in "${targets[@]}"; do
  if [ $simulate -eq 1 ]; then
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    mkdir -p "$work/updates"
    removed=$(closure "$target")
    # dpkg's status without the removed packages' stanzas: the machine after the removal.
    awk -v gone="$(tr '\n' ' ' <<<"$removed")" '
      BEGIN { RS = ""; ORS = "\n\n"; n = split(gone, g, " "); for (i = 1; i <= n; i++) out[g[i]] = 1 }
      { split($0, lines, "\n"); sub(/^Package: /, "", lines[1]); if (!(lines[1] in out)) print }
    ' /var/lib/dpkg/status >"$work/status"
    mapfile -t missing < <(INSTALL_DEPS_ADMINDIR="$work" ./scripts/install-deps.sh --missing)
    # What install-deps.sh would run, simulated on that machine.
    transaction=$(apt-get -s -o Dir::State::status="$work/status" install -y \
      --no-install-recommends "${missing[@]}" 2>&1) || {
      echo "check-install-deps: without $target, apt refuses the install: $transaction" >&2
      failed=1
      continue
    }
    installed=$(printf '%s\n' "$transaction" | marked Inst)
    dropped=$(printf '%s\n' "$transaction" | marked Remv)
    absent=()
    for p in "${listed[@]}"; do
      if printf '%s\n' "$dropped" | grep -qx -- "$p"; then
        absent+=("$p")
      elif ! printf '%s\n' "$installed" | grep -qx -- "$p" &&
        ! dpkg-query --admindir="$work" -W -f='${Status}' "$p" 2>/dev/null |
        grep -q 'install ok installed'; then
        absent+=("$p")
      fi
    done
    rm -rf "$work"
    trap - EXIT
  else
    # dpkg, not apt: exactly these go, nothing is installed in their place.
    mapfile -t removed < <(closure "$target")
    dpkg --remove "${removed[@]}" >/dev/null
    ./scripts/install-deps.sh
    absent=()
    for p in "${listed[@]}"; do
      dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' ||
        absent+=("$p")
    done
  fi
  if [ ${#absent[@]} -gt 0 ]; then
    echo "check-install-deps: after removing $target and running install-deps.sh, not installed:" \
      "${absent[*]}" >&2
    failed=1
  else
    echo "check-install-deps: without $target: every listed package installed again"
  fi
done
exit $failed
