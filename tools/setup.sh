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

# The Khronos glTF Validator (npm's gltf-validator: one JavaScript file, no dependencies),
# fetched by its pinned checksum; the tests validate every .glb the bake exports with it
# (tools/gltf_validate.cjs).
GLTF_VALIDATOR_URL="https://registry.npmjs.org/gltf-validator/-/gltf-validator-2.0.0-dev.3.10.tgz"
GLTF_VALIDATOR_SHA1="9b09225db864fe3f0a584259f65d087e2213a93a"
if [ ! -f .tools/gltf-validator/package/index.js ]; then
  "$py" - "$GLTF_VALIDATOR_URL" "$GLTF_VALIDATOR_SHA1" <<'PY'
import hashlib, io, sys, tarfile, urllib.request
data = urllib.request.urlopen(sys.argv[1], timeout=120).read()
if hashlib.sha1(data).hexdigest() != sys.argv[2]:
    sys.exit("gltf-validator: checksum mismatch")
archive = tarfile.open(fileobj=io.BytesIO(data))
archive.extractall(".tools/gltf-validator", **({"filter": "data"} if hasattr(tarfile, "data_filter") else {}))
PY
fi

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
# The repository on the environment's path (as an editable install would put it) and a `hao`
# command in it: `.venv/bin/hao bake ...` is `python -m hao_addon bake ...` from any folder.
site="$("$venv/bin/python" -c "import sysconfig; print(sysconfig.get_path('purelib'))")"
echo "$(pwd)" > "$site/hao_for_blender.pth"
printf '#!%s\n# hao for Blender: the command line (python -m hao_addon), made by tools/setup.sh\nimport runpy\nrunpy.run_module("hao_addon", run_name="__main__", alter_sys=True)\n' \
  "$(pwd)/$venv/bin/python" > "$venv/bin/hao"
chmod +x "$venv/bin/hao"
echo "$venv"
