#!/usr/bin/env bash
# Set up a fresh Debian/Ubuntu machine: OpenGL over EGL (Mesa llvmpipe works without a GPU),
# the X11 client libraries the bpy wheel links against, and .venv with pinned requirements.
# Safe to re-run: it reuses what is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES="libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 libx11-6 libxi6 libxxf86vm1 libxfixes3 \
libxrender1 libxkbcommon0 libsm6 libice6 libxext6"
missing=""
for p in $APT_PACKAGES; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
fi

PY="${PYTHON:-python3.11}"
command -v "$PY" >/dev/null 2>&1 || PY=python3
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
if ! .venv/bin/python -c "import bpy, xatlas, pytest, matplotlib" >/dev/null 2>&1 \
   || ! cmp -s requirements.txt .venv/.requirements.installed; then
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -r requirements.txt
  cp requirements.txt .venv/.requirements.installed
fi
