#!/usr/bin/env bash
# Set up (if needed) and run the whole test suite headless, once per Blender release:
# by default the oldest and the newest supported ones (what CI runs); HAO_BPY=4.5.15 (or any
# release with a requirements/bpy-<version>.txt) runs just that one. Extra arguments go to pytest.
# Several releases run side by side (most of a test's time is one core's, so two suites on two
# cores take about as long as one); each one's output is printed whole when it ends, and
# Ctrl-C stops them all.
set -uo pipefail
cd "$(dirname "$0")/.."
source tools/bpy_releases.sh

releases=(${HAO_BPY:-$HAO_CI_BPY})
venvs=()
for release in "${releases[@]}"; do  # set-ups one at a time: they share apt and pip caches
  venvs+=("$(HAO_BPY="$release" bash tools/setup.sh | tail -n 1)") || exit 2
done

logs="$(mktemp -d)"
pids=()
trap 'trap - INT TERM; rm -rf "$logs"; kill 0; exit 130' INT TERM  # the whole process group: every suite at once
for i in "${!releases[@]}"; do
  venv="${venvs[$i]}"
  (
    echo "== Blender ${releases[$i]} ($("$venv/bin/python" -c 'import sys; print("Python", sys.version.split()[0])'))"
    "$venv/bin/python" -m pytest -q -p no:cacheprovider tests "$@"
  ) > "$logs/$i" 2>&1 &
  pids+=($!)
done

status=0
for i in "${!releases[@]}"; do
  wait "${pids[$i]}" || status=1
  cat "$logs/$i"
done
rm -rf "$logs"
exit $status
