#!/usr/bin/env bash
# The README's pictures of the bake outputs, made with the command line on the bundled sample
# (Spot, samples/spot.obj, its own UVs; shaded flat: the OBJ has no 's' groups):
#   docs/images/spot_ao.png            AO, 256^2, 256 directions
#   docs/images/spot_bent_normals.png  bent normals of the same bake, tangent space, OpenGL
# and (tools/readme_pictures.py) the colour-attribute and UDIM pictures.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p docs/images
.venv/bin/python -m hao_addon bake samples/spot.obj --size 256 --directions 256 --margin 4 \
    --out docs/images/spot_ao.png --bent-normal-out docs/images/spot_bent_normals.png
.venv/bin/python tools/readme_pictures.py
