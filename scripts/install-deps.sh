#!/usr/bin/env bash
# Installs the Debian packages Hamiltone builds with — only those missing, so a second run is instant.
# Works as root, or through sudo otherwise; never prompts (CI has no terminal).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev       # engine: vectors and the scheme state
  libcli11-dev        # cli/, render/, sim/: hamiltone-render's and hamiltone-sim's command lines
  libtomlplusplus-dev # engine/presets: the TOML preset files
  libsndfile1-dev     # render/: hamiltone-render's WAV output
  # app/: hamiltone-play's audio output and MIDI input. They need a JACK development package,
  # "libjack-dev | libjack-jackd2-dev": named, or apt takes the first, jackd1's, which removes
  # jackd2 (below) — and the next run's jackd2 removes these two.
  libjack-jackd2-dev librtaudio-dev librtmidi-dev
  dpf-source          # plugin/: DPF (the DISTRHO Plugin Framework) and the CLAP headers
  libgtest-dev libgmock-dev  # tests/
  lv2-dev sordi       # tests/plugin: lv2_validate and the sord_validate it runs
  clang libclang-rt-14-dev   # tests/fuzz: libFuzzer targets for the MIDI reader and preset loader
  clang-22 libclang-rt-22-dev llvm-22  # tests/rtsan: RTSan test (bookworm-security; llvm-22 symbolises)
  libbenchmark-dev    # bench/
  jackd2              # tests/e2e: a JACK server (dummy driver) for hamiltone-play's test, and jack_rec
  jalv                # tests/e2e: an LV2 host on that server for the plugin's test
  python3-matplotlib python3-numpy  # scripts/validation.sh: the figures of docs/validation.md (Debian's, run by /usr/bin/python3)
)

# --list: the packages, one a line; --missing: those not installed, as dpkg's database in
# $INSTALL_DEPS_ADMINDIR (default /var/lib/dpkg) has them. Both for scripts/check-install-deps.sh.
if [ "${1:-}" = "--list" ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query --admindir="${INSTALL_DEPS_ADMINDIR:-/var/lib/dpkg}" -W -f='${Status}' "$p" \
    2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ "${1:-}" = "--missing" ]; then
  [ ${#missing[@]} -eq 0 ] || printf '%s\n' "${missing[@]}"
  exit 0
fi
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo -n)  # -n: fail rather than wait for a password nobody can type in CI
else
  echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
# env passes DEBIAN_FRONTEND through sudo, which resets the environment.
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
