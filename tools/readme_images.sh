#!/usr/bin/env bash
# The README's pictures of the bake outputs, made with the command line on the bundled sample
# (Spot, samples/spot.obj, its own UVs, shaded smooth: 's 1'):
#   docs/images/spot_ao.png            AO, 256^2, 256 directions
#   docs/images/spot_bent_normals.png  bent normals of the same bake, tangent space, OpenGL
#   docs/images/spot_viewport_ao.png   viewport AO (HAO) of the sample scene, render-ao
# and (tools/readme_pictures.py) the colour-attribute and UDIM pictures.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p docs/images
.venv/bin/python -m hao_addon bake samples/spot.obj --size 256 --directions 256 --margin 4 \
    --out docs/images/spot_ao.png --bent-normal-out docs/images/spot_bent_normals.png
# The viewport picture: HAO of Spot on a floor from the sample scene's camera (tools/sample.sh).
.venv/bin/python samples/make_scene.py out/spot_scene.blend
.venv/bin/python -m hao_addon render-ao out/spot_scene.blend --camera Camera --width 640 --height 480 \
    --max-distance 0.5 --out docs/images/spot_viewport_ao.png
# Then the pictures made in Python, and both above set on a mid-grey background.
.venv/bin/python tools/readme_pictures.py
