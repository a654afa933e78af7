#!/usr/bin/env bash
# Set up (if needed) and run the main job on the bundled sample: bake the AO map of Spot
# (samples/spot.obj) to out/spot_ao.png (16-bit) and out/spot_ao.exr (32-bit float).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
mkdir -p out
.venv/bin/python -m hao_addon bake samples/spot.obj --size 1024 --directions 256 --out out/spot_ao.png
.venv/bin/python -m hao_addon bake samples/spot.obj --size 1024 --directions 256 --out out/spot_ao.exr
