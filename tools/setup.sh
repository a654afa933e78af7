#!/usr/bin/env bash
# Set up a fresh Debian/Ubuntu machine: OpenGL over EGL (Mesa llvmpipe works without a GPU),
# the X11 client libraries the bpy wheel links against, and a virtual environment with the
# pinned requirements of one Blender release (requirements/bpy-<version>.txt).
#
#   bash tools/setup.sh                  # default release, in .venv
#   HAO_BPY=4.2.23 bash tools/setup.sh   # that release, in .venv-4.2.23
#
# Safe to re-run: it reuses what is already there, and rebuilds an environment whose Python
# or requirements changed. Prints the environment's folder on its last line.
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/bpy_releases.sh

# nodejs: the tests compile the Flamenco job type (JavaScript) under node.
APT_PACKAGES="libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 libx11-6 libxi6 libxxf86vm1 libxfixes3 \
libxrender1 libxkbcommon0 libsm6 libice6 libxext6 nodejs"
missing=""
for p in $APT_PACKAGES; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
fi

release="${HAO_BPY:-$HAO_DEFAULT_BPY}"
req="$(requirements_for "$release")"
venv="$(venv_for "$release")"
pyver="$(python_version_for "$release")"
py="$(find_python "$pyver")"

if [ -x "$venv/bin/python" ] && ! "$venv/bin/python" -c "import sys; sys.exit(sys.version[:len('$pyver')+1] != '$pyver.')"; then
  rm -rf "$venv"  # made with another Python: pinned wheels would not match
fi
if [ ! -x "$venv/bin/python" ]; then
  "$py" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import bpy, xatlas, pytest, matplotlib" >/dev/null 2>&1 \
   || ! cmp -s "$req" "$venv/.requirements.installed"; then
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$req"
  cp "$req" "$venv/.requirements.installed"
fi
echo "$venv"
