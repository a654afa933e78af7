#!/usr/bin/env bash
# Set up (if needed) and run the main job on the bundled sample (Spot, samples/spot.obj,
# shaded smooth):
# bake its AO map to out/spot_ao.png (16-bit) and out/spot_ao.exr (32-bit float), then
# render viewport AO (HAO) of Spot on a floor from a camera to out/spot_viewport_ao.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
mkdir -p out
.venv/bin/hao bake samples/spot.obj --size 1024 --directions 256 --out out/spot_ao.png
.venv/bin/hao bake samples/spot.obj --size 1024 --directions 256 --out out/spot_ao.exr
.venv/bin/python samples/make_scene.py out/spot_scene.blend
.venv/bin/hao render-ao out/spot_scene.blend --camera Camera --width 800 --height 600 \
    --max-distance 0.5 --out out/spot_viewport_ao.png
echo
echo "Sample outputs:"
for f in out/spot_ao.png out/spot_ao.exr out/spot_scene.blend out/spot_viewport_ao.png; do
  echo "  $(pwd)/$f"
done
