#!/usr/bin/env bash
# Set up (if needed) and run the whole test suite headless, once per Blender release:
# by default the oldest and the newest supported ones (what CI runs); HAO_BPY=4.5.15 (or any
# release with a requirements/bpy-<version>.txt) runs just that one. Extra arguments go to pytest.
set -uo pipefail
cd "$(dirname "$0")/.."
source tools/bpy_releases.sh

status=0
for release in ${HAO_BPY:-$HAO_CI_BPY}; do
  venv="$(HAO_BPY="$release" bash tools/setup.sh | tail -n 1)" || exit 2
  echo "== Blender $release ($("$venv/bin/python" -c 'import sys; print("Python", sys.version.split()[0])'))"
  "$venv/bin/python" -m pytest -q -p no:cacheprovider tests "$@" || status=1
done
exit $status
