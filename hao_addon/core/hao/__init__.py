# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport Hybrid Ambient Occlusion's math: settings, the scene's region of interest, the
voxel grid and CPU voxelizations, the ray pattern and voxel-march mirror, the bilateral
reference, camera matrices."""
