#!/bin/sh
# Installs the npm packages of tools/npm/package.json (for the glTF export
# tests: the Khronos validator, three.js, a headless Chromium driver) into
# build/node/node_modules when they are missing or the list changed. Called
# by tools/deps.sh. Versions are pinned in package.json; no lock file is kept.
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
dir="$top/build/node"
want="$top/tools/npm/package.json"
# The stamp is written last, so an interrupted install is redone.
if [ -d "$dir/node_modules" ] && cmp -s "$want" "$dir/installed.json"; then
  echo "deps: npm packages present"
  exit 0
fi
if ! command -v npm >/dev/null 2>&1; then
  echo "deps: npm is missing (tools/deps.sh installs the Debian package npm)" >&2
  exit 1
fi
echo "deps: installing npm packages into build/node"
rm -rf "$dir"
mkdir -p "$dir"
cp "$want" "$dir/package.json"
if ! (cd "$dir" && npm install --no-audit --no-fund --no-package-lock --loglevel=error >/dev/null); then
  rm -rf "$dir"
  echo "deps: npm install failed (no network?): the export tests need these packages" >&2
  exit 1
fi
cp "$want" "$dir/installed.json"
echo "deps: npm packages done"
