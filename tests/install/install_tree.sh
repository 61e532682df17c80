#!/usr/bin/env bash
# cmake --install of a build tree into a fresh prefix, as a user installs: the programs in bin/,
# the presets in share/hamiltone/presets/, the documents in share/doc/hamiltone/ and the plugins
# under lib/lv2, lib/clap and lib/vst3; then the installed programs print their version, render
# with their default preset found from the prefix alone (no XDG directory has one, the working
# directory is elsewhere, the source tree is not looked at), and hold no path of the source or
# build tree.
#
#   install_tree.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1")
source=$(realpath "$2")
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
prefix="$root/usr"
cmake --install "$build" --prefix "$prefix" >/dev/null

failed=0
fail() {
  echo "install_tree: $*" >&2
  failed=1
}

programs=(hamiltone-render hamiltone-sim hamiltone-play)
expected=(share/hamiltone/presets/grand-piano.toml share/hamiltone/presets/demo.mid
          share/doc/hamiltone/README.md share/doc/hamiltone/LICENSE
          share/doc/hamiltone/instrument-data.md)
for p in "${programs[@]}"; do expected+=("bin/$p"); done
if [ -e "$build/plugin" ]; then
  expected+=(lib/lv2/hamiltone.lv2/manifest.ttl lib/lv2/hamiltone.lv2/hamiltone_dsp.ttl
             lib/lv2/hamiltone.lv2/hamiltone_dsp.so lib/clap/hamiltone.clap
             "lib/vst3/hamiltone.vst3/Contents/$(uname -m)-linux/hamiltone.so")
fi
for f in "${expected[@]}"; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
for f in "$source"/presets/*; do
  [ -e "$prefix/share/hamiltone/presets/$(basename "$f")" ] ||
    fail "preset not installed: $(basename "$f")"
done

for p in "${programs[@]}"; do
  out=$("$prefix/bin/$p" --version) || fail "$p --version failed"
  [[ "$out" == "$p "* ]] || fail "$p --version printed: $out"
done
# Nothing of the build machine's trees in a program or a plugin: not the source, not the build.
while IFS= read -r -d '' binary; do
  if grep -q -a -F -e "$source" -e "$build" "$binary"; then
    fail "${binary#"$prefix"/} holds a path of the source or build tree:" \
      "$(grep -a -o -F -e "$source" -e "$build" "$binary" | head -1)"
  fi
done < <(find "$prefix/bin" "$prefix/lib" -type f \( -perm -u+x -o -name '*.so' -o -name '*.clap' \) -print0 2>/dev/null)

# The default preset (grand-piano) found in the prefix's share/, with the user's and the system's
# data directories empty and the working directory outside both trees.
mkdir -p "$root/home" "$root/work"
if ! (cd "$root/work" && env -i PATH=/usr/bin:/bin HOME="$root/home" XDG_DATA_DIRS=/nonexistent \
  "$prefix/bin/hamiltone-render" --notes "A4:100:0.2" --tail 0 --quiet -o take.flac); then
  fail "the installed hamiltone-render did not render with its default preset"
fi
[ -s "$root/work/take.flac" ] || fail "no take.flac"
exit $failed
