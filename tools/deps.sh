#!/bin/sh
# Installs the Debian packages the toolkit needs, when they are missing.
# Prints one line when everything is there already.
set -eu

PACKAGES="
  make g++ gcc pkg-config
  libeigen3-dev libopenmesh-dev libdraco-dev
  libosmesa6-dev libglfw3-dev libgl-dev libpng-dev zlib1g-dev
  xvfb
  libgtest-dev
  gcc-arm-linux-gnueabi libc6-dev-armel-cross qemu-user
  clang libclang-rt-14-dev
  chromium
"
# Node.js for the export tests (tools/deps-npm.sh): Debian's nodejs and npm,
# unless a node and npm are installed already (e.g. from another source,
# whose packages Debian's npm would conflict with).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  PACKAGES="$PACKAGES nodejs npm"
fi

missing=""
for p in $PACKAGES; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  case "$status" in
    "install ok installed") ;;
    *) missing="$missing $p" ;;
  esac
done

npm_deps="$(dirname "$0")/deps-npm.sh"
if [ -z "$missing" ]; then
  echo "deps: all packages present"
  exec sh "$npm_deps"
fi

echo "deps: installing$missing"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1; then
  SUDO="sudo"
else
  echo "deps: need root (or sudo) to install:$missing" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
echo "deps: done"
exec sh "$npm_deps"
