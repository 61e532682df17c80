#!/usr/bin/env bash
# lv2_validate (Debian's lv2-dev, with sordi's sord_validate) on every turtle file of the LV2
# bundle given: the plugin's description against the LV2 specifications. Exit 77 (skipped) when the
# tool is missing — except in CI (CI=true), where scripts/install-deps.sh must have installed it.
set -euo pipefail
bundle="$1"
if ! command -v lv2_validate >/dev/null || ! command -v sord_validate >/dev/null; then
  echo "lv2_validate or sord_validate is missing (Debian's lv2-dev and sordi)" >&2
  [ "${CI:-}" = true ] && exit 1
  exit 77
fi
shopt -s nullglob
files=("$bundle"/*.ttl)
[ ${#files[@]} -ge 2 ] || { echo "no turtle in $bundle" >&2; exit 1; }
lv2_validate "${files[@]}"
