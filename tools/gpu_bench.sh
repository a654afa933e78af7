#!/usr/bin/env bash
# The benchmarks on a machine with an NVIDIA GPU, headless over EGL: the bake's time against
# error (bench/bake_bench.py, HAO beside Cycles' CPU bake, flat rows) and the viewport's frame
# time at 1080p (bench/hao_bench.py's frame part), and the ray cast's list forms (textures
# against Blender 5.3's storage buffers, bench/list_forms_bench.py), their JSON and plots into one folder.
#
#     bash tools/gpu_bench.sh [OUT]        # OUT: bench/results/gpu (default)
#
# It sets the project up as CI does (tools/setup.sh: .venv with the pinned bpy wheel), then
# checks that Blender's GPU context is the NVIDIA device and not Mesa's llvmpipe, and stops if
# it is not (the numbers would be the CPU's). What the numbers show: the same passes on a GPU
# through the same `gpu` module. What they do not: ray tracing hardware (none is used; an
# H100/H200 has no RT cores), and a data-centre GPU's rasterization is weak beside a desktop
# card's, so depth-map-bound bakes understate what a workstation GPU does.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-bench/results/gpu}"
mkdir -p "$out"
if command -v nvidia-smi >/dev/null; then
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
else
  echo "gpu_bench: no nvidia-smi on this machine" >&2
fi
venv="$(bash tools/setup.sh | tail -n 1)"
python="$venv/bin/python"
"$python" - <<'PY' | tee -a "$out/gpu.txt"
import sys
sys.path.insert(0, ".")
import bpy, gpu
from hao_addon.gpu.context import ensure_gpu_context
ensure_gpu_context()
renderer = gpu.platform.renderer_get()
print("renderer:", renderer, "| vendor:", gpu.platform.vendor_get(), "| backend:", gpu.platform.backend_type_get())
if "llvmpipe" in renderer.lower() or "lavapipe" in renderer.lower():
    sys.exit("gpu_bench: Blender's GPU context is Mesa's software rasterizer, not a GPU")
PY
"$python" bench/bake_bench.py --parts flat --meshes rocker-arm,bunny --out "$out"
"$python" bench/hao_bench.py --parts frame --resolution 1920x1080 --out "$out"
"$python" bench/list_forms_bench.py --out "$out"  # list textures against 5.3's storage buffers
echo "gpu_bench: wrote $out/bake_bench.json, $out/hao_bench.json and $out/list_forms_bench.json"
