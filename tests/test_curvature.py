# SPDX-License-Identifier: GPL-3.0-or-later
"""Curvature and cavity maps (core/bake/curvature.py), two rows of core/bake/map_kinds.py,
against analytic shapes: a sphere's mean curvature is 1/R, a plane's 0, a groove's cavity is
darker than its rim; and baked through the command line as any other map."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.core import scenes
from hao_addon.core.bake.curvature import (CAVITY_RANGE, CURVATURE_RANGE, cavity_map, curvature_map,
                                           texel_curvature, vertex_mean_curvature)
from hao_addon.core.geometry import TriangleSoup, bounding_sphere


def groove(cells: int = 64, depth: float = 0.2, width: float = 0.4) -> TriangleSoup:
    """A square z = -depth exp(-(x / width)^2) over [-1, 1]^2, UVs (x, y) / 2 + 1/2: a groove
    along y (concave at x = 0) between two convex shoulders (near |x| = width, where the
    profile bends back: z'' < 0)."""
    t = np.linspace(-1.0, 1.0, cells + 1)
    x, y = np.meshgrid(t, t, indexing="ij")
    z = -depth * np.exp(-(x / width) ** 2)
    p = np.stack([x, y, z], axis=-1)
    quads = [(p[i, j], p[i + 1, j], p[i + 1, j + 1], p[i, j + 1]) for i in range(cells) for j in range(cells)]
    tris = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
    return TriangleSoup(tris, tris[..., :2] / 2.0 + 0.5, name="groove")


@pytest.mark.parametrize("radius", [0.5, 2.0])
def test_a_spheres_mean_curvature_is_one_over_its_radius(radius):
    """Every vertex of a 64 x 32 UV sphere but the pole fans' nearest rings reads 1/R within
    1 % (the median within 0.3 %), whatever R: the cotangent Laplacian's -(L x . n) / 2."""
    h = vertex_mean_curvature(scenes.uv_sphere(radius, (0.3, -0.2, 1.0), 64, 32).positions)
    assert abs(np.median(h) * radius - 1.0) < 0.003
    assert np.mean(np.abs(h * radius - 1.0) < 0.01) > 0.9


def test_a_plane_has_no_curvature_and_its_maps_are_flat():
    plane = scenes.grid_plane(2.0, 8, z=0.5)
    assert np.abs(vertex_mean_curvature(plane.positions)).max() < 1e-9
    k, covered = texel_curvature(plane, 32)
    assert covered.mean() > 0.9 and np.abs(k[covered]).max() < 1e-9
    np.testing.assert_allclose(curvature_map(plane, 32, 2)[covered], 0.5, atol=1e-6)
    np.testing.assert_allclose(cavity_map(plane, 32, 2)[covered], 1.0, atol=1e-6)


def test_a_sphere_fills_its_bounds_so_its_texels_read_one():
    """k = H r: a sphere's texels read 1 (its radius is its bounding radius), and the maps encode
    it as 0.5 + 0.5 / CURVATURE_RANGE and as 1 in the cavity map (convex)."""
    sphere = scenes.uv_sphere(3.0, (0.0, 0.0, 0.0), 64, 32)
    k, covered = texel_curvature(sphere, 64)
    assert abs(np.median(k[covered]) - 1.0) < 0.005
    middle = covered.copy()
    middle[:16], middle[-16:] = False, False  # away from the poles' fans
    np.testing.assert_allclose(curvature_map(sphere, 64, 2)[middle], 0.5 + 0.5 / CURVATURE_RANGE, atol=2e-3)
    assert (cavity_map(sphere, 64, 2)[covered] == 1.0).all()


def test_a_grooves_cavity_is_darker_than_its_rim():
    """Across the groove: the bottom is concave (curvature below 0.5, cavity below 1) and the
    shoulders convex (curvature above 0.5, cavity 1); the bottom reads its analytic
    k = -r z''(0) / 2 within 5 % (r the bounding radius; small slopes there)."""
    soup, size = groove(), 64
    k, covered = texel_curvature(soup, size)
    row = size // 2  # texel rows run along v = y: a row is a cross-section of the groove
    bottom, rim = size // 2, int((0.4 / 2.0 + 0.5) * size)  # the columns at x = +1/64 and x = the width
    radius = float(bounding_sphere(soup.positions.reshape(-1, 3))[1])
    expected = -radius * 0.5 * (2.0 * 0.2 / 0.4 ** 2)  # z''(0) = 2 depth / width^2
    assert covered[row, bottom] and abs(k[row, bottom] / expected - 1.0) < 0.05, (k[row, bottom], expected)
    cavity, curvature = cavity_map(soup, size, 2), curvature_map(soup, size, 2)
    assert cavity[row, bottom] < cavity[row, rim] == 1.0
    assert curvature[row, bottom] < 0.5 < curvature[row, rim]
    assert cavity[row, bottom] == pytest.approx(max(0.0, 1.0 + k[row, bottom] / CAVITY_RANGE), abs=1e-6)


def test_curvature_and_cavity_bake_as_maps_on_the_command_line(tmp_path):
    """--maps curvature,cavity writes both beside --out, as their own options would; Spot's
    ears are convex and the creases at its legs concave, so its curvature map spans 0.5."""
    from bake_helpers import load_image_rgba
    from test_cli_runs import SPOT, run

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    done = run(["bake", SPOT, "--size", "64", "--directions", "8", "--quiet", "--out", tmp_path / "ao.png",
                "--maps", "curvature,cavity"], tmp)
    assert done.returncode == 0, done.stderr
    curvature = load_image_rgba(tmp_path / "ao_curvature.png")[..., 0]
    cavity = load_image_rgba(tmp_path / "ao_cavity.png")[..., 0]
    assert curvature.min() < 0.45 and curvature.max() > 0.55
    assert cavity.min() < 0.9 and cavity.max() == 1.0
