# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake settings shared by the operator, the CLI and the tests (plain data, validated).

Each field is the one definition of its setting (default, range, unit, description): the
Blender properties, the command-line options and the README table are made from it.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..kernels import FALLOFF_CHOICES
from ..setting_spec import Choice, setting, validate

MAX_DIRECTIONS = 65536
MAX_MAP_SIZE = 16384

WEIGHTING_CHOICES = (
    Choice("cosine", "Cosine", "Lambertian ambient occlusion (what Cycles bakes)"),
    Choice("uniform", "Uniform", "fraction of the open hemisphere"),
)
NORMALS_CHOICES = (
    Choice("mesh", "Mesh Shading", "the mesh's own shading as Blender evaluates it: smooth faces interpolated, "
                                   "sharp edges and custom normals kept (what Cycles bakes)"),
    Choice("face", "Face", "flat: every texel uses its triangle's normal"),
)
METHOD_CHOICES = (
    Choice("auto", "Auto", "the gather for unlimited distance, Selected to Active and bent normals (fastest at "
                           "equal error in the benchmark), otherwise the scatter with a max distance"),
    Choice("scatter", "Histogram Scatter", "McGraw & Sowers: texel-area average; supports max distance and falloff"),
    Choice("gather", "Shadow-Map Gather", "shadow maps sampled at texel centres (the paper's baseline); with a "
                                          "max distance, per-pixel depth lists"),
    Choice("reference", "Reference (CPU)", "the same estimator ray traced on the CPU: slow (minutes), "
                                           "for checking a GPU bake"),
)
METHODS = tuple(c.value for c in METHOD_CHOICES)
TERMINATOR_CHOICES = (
    Choice("object", "Object's", "each object's own Shadow Terminator Geometry Offset (Object Properties > "
                                 "Shading, Cycles), as Cycles' bake does; Terminator Offset where the input has "
                                 "none (OBJ, glTF)"),
    Choice("setting", "Terminator Offset", "the Terminator Offset setting for every object"),
)
ALPHA_CHOICES = (
    Choice("blend", "Blend", "an occluder stops light as much as its material's alpha (a 50 % leaf card half)"),
    Choice("clip", "Clip", "an occluder stops light where its alpha reaches Alpha Clip, elsewhere none (cut-outs)"),
    Choice("off", "Off", "every occluder is opaque, whatever its material"),
)
TARGET_CHOICES = (
    Choice("image", "Image Textures", "an AO map in the UV layout"),
    Choice("color-attribute", "Color Attribute", "AO per vertex (or face corner) into the mesh's colour attribute "
                                                 "hao_ao, as Cycles' Color Attributes target bakes it; no UVs needed"),
)
COLOR_DOMAIN_CHOICES = (
    Choice("point", "Vertex", "one value per vertex: the mean of its face corners (Cycles' point domain)"),
    Choice("corner", "Face Corner", "one value per face corner, shaded with that corner's normal"),
)
QUALITY_CHOICES = (
    Choice("fixed", "Fixed Directions", "exactly Directions (to Max Error instead when that is above 0)"),
    Choice("draft", "Draft", "to an estimated p99 error of 0.01: a look at the result"),
    Choice("8-bit", "8-Bit Exact", "to half an 8-bit step (p99 0.00196): no 8-bit value wrong by more than rounding"),
    Choice("16-bit", "16-Bit", "to an eighth of an 8-bit step (p99 0.00049), for 16-bit and float maps"),
    Choice("custom", "Custom", "to Max Error"),
)
# The p99 error each Quality bakes to (0: none, Directions decide).
QUALITY_ERRORS = {"fixed": 0.0, "draft": 0.01, "8-bit": 0.5 / 255.0, "16-bit": 0.125 / 255.0, "custom": None}
# The presets' own caps on directions, in place of Directions (which caps Custom and Max
# Error): enough to reach their targets on every mesh of bench/ (bench/error_bench.py: 8-bit
# took up to 12k directions at 1024^2 and the 16-bit target's p99 falls about as D^-0.6).
QUALITY_CAPS = {"draft": 16384, "8-bit": 65536, "16-bit": 65536}
SAMPLES_PER_TEXEL_CHOICES = (
    Choice(1, "Off", "one sample at each texel centre"),
    Choice(4, "4 Samples", "a 2 x 2 grid of points in each texel, averaged"),
    Choice(9, "9 Samples", "a 3 x 3 grid of points in each texel, averaged"),
    Choice(16, "16 Samples", "a 4 x 4 grid of points in each texel, averaged"),
)
TEXEL_SETS_CHOICES = (
    Choice(1, "One", "every texel the same directions: each direction's shadow edge lies in the same place "
                     "for all, and the error takes the shapes of those shadows"),
    Choice(4, "2 x 2", "neighbouring texels take turns with four direction sets: fine grain instead of shadow "
                       "shapes; four light views per direction, each at twice the pixel side"),
)


@dataclass(frozen=True)
class BakeSettings:
    """What a bake computes (see each field's description)."""

    size: int = setting(
        1024, label="Size", noun="map size", minimum=16, maximum=MAX_MAP_SIZE, soft_max=8192, unit="texels",
        subtype='PIXEL', description="width and height of the AO map (also limited by the GPU's texture size)")
    directions: int = setting(
        256, label="Directions", minimum=1, maximum=MAX_DIRECTIONS, soft_max=4096,
        description="light directions (with Quality 'custom' or a Max Error: at most this many; the Draft, 8-Bit "
                    "and 16-Bit presets have their own caps); noise falls about as directions^-0.75, time grows "
                    "linearly")
    quality: str = setting(
        "fixed", label="Quality", choices=QUALITY_CHOICES,
        description="bake a fixed number of directions, or add them in rounds until the bake's own estimate of "
                    "its p99 error (99 % of texels within it) reaches a target")
    max_error: float = setting(
        0.0, label="Max Error", minimum=0.0, maximum=0.5, soft_max=0.05,
        description="the p99 error to bake to, with Quality 'custom' or 'fixed' (0 = none: exactly Directions); "
                    "a bake that reaches Directions first stops there and says so")
    max_distance: float = setting(
        0.0, label="Max Distance", minimum=0.0, soft_max=100.0, unit="scene units",
        subtype='DISTANCE', description="occluders farther than this do not darken; 0 = unlimited")
    falloff: str = setting(
        "none", label="Falloff", choices=FALLOFF_CHOICES,
        description="how occlusion fades with distance (only with a max distance)")
    weighting: str = setting(
        "cosine", label="Weighting", choices=WEIGHTING_CHOICES, description="how directions over the hemisphere count")
    normals: str = setting(
        "mesh", label="Normals", choices=NORMALS_CHOICES,
        description="which normal the hemisphere is about; visibility is always tested from the true surface")
    spread_angle: float = setting(
        90.0, label="Spread Angle", minimum=0.0, above_minimum=True, maximum=90.0, unit="degrees",
        description="the cone about the normal that counts: directions farther from the normal weigh nothing "
                    "(90 = the whole hemisphere; smaller gives a tighter, contact-like AO)")
    min_distance: float = setting(
        0.0, label="Min Distance", minimum=0.0, soft_max=1.0, unit="scene units", subtype='DISTANCE',
        description="occluders nearer than this along a ray are ignored (the ray goes on past them); 0 = none")
    ignore_back_faces: bool = setting(
        False, label="Ignore Back Faces", description="faces seen from behind do not occlude (open or single-sided meshes)")
    margin: int = setting(
        16, label="Margin", minimum=0, maximum=1024, unit="texels", subtype='PIXEL',
        description="texels grown past every UV island, so filtering never reads the background")
    samples_per_texel: int = setting(
        1, label="Anti-Aliasing", noun="samples per texel", choices=SAMPLES_PER_TEXEL_CHOICES,
        description="stratified points per texel, averaged, for silhouettes, thin features and UV edges "
                    "(the scatter, which averages each texel's area already, takes that many times more "
                    "light-view pixels per texel)")
    texel_sets: int = setting(
        1, label="Texel Sets", noun="direction sets", choices=TEXEL_SETS_CHOICES,
        description="direction sets that neighbouring texels take turns with (the gather and the reference; "
                    "the scatter and colour attributes bake one)")
    cage_extrusion: float = setting(
        0.0, label="Cage Extrusion", minimum=0.0, soft_max=1.0, unit="scene units", subtype='DISTANCE',
        description="Selected to Active: how far each ray starts outside the low-poly, along its normals "
                    "(Cycles' Extrusion)")
    max_ray_distance: float = setting(
        0.0, label="Max Ray Distance", minimum=0.0, soft_max=1.0, unit="scene units", subtype='DISTANCE',
        description="Selected to Active: a high-poly surface farther than this from the ray start is not found; "
                    "0 = no limit")
    terminator: str = setting(
        "object", label="Terminator", noun="terminator offset source", choices=TERMINATOR_CHOICES,
        description="where the terminator offset of a Blender object comes from")
    terminator_offset: float = setting(
        0.1, label="Terminator Offset", minimum=0.0, maximum=1.0,
        description="Cycles' Shadow Terminator Geometry Offset (its default 0.1): rays that graze a smooth-shaded "
                    "facet start from the smooth surface its normals describe, so the triangles do not show as "
                    "dark bands; 0 = off. Used for OBJ and glTF input and with Terminator 'setting'; "
                    "the scatter ignores it")
    bent_normals: bool = setting(
        False, label="Bent Normals", cli=None, cli_via="--bent-normal-out FILE",
        description="also bake the bent normal: each texel's cosine-weighted mean unoccluded direction, from "
                    "the same directions as the AO (gather and reference; the scatter cannot)")
    alpha: str = setting(
        "blend", label="Alpha", noun="alpha mode", choices=ALPHA_CHOICES,
        description="how an occluder's material alpha (the Principled BSDF's Alpha: a value, or an Image Texture's "
                    "alpha on the mesh's UVs) lets light through")
    alpha_clip: float = setting(
        0.5, label="Alpha Clip", minimum=0.0, maximum=1.0,
        description="Alpha 'clip': an occluder's surface stops light where its alpha is at least this")
    thickness: bool = setting(
        False, label="Thickness", cli=None, cli_via="--thickness-out FILE",
        description="also bake thickness (Substance's): the occlusion of the inverted hemisphere, seen from inside "
                    "the surface, by the mesh itself within Thickness Distance; 1 where a wall is that near in every "
                    "direction (thin), 0 where none is (images of the mesh's own surface)")
    thickness_distance: float = setting(
        0.0, label="Thickness Distance", minimum=0.0, soft_max=10.0, unit="scene units", subtype='DISTANCE',
        description="how far inside the surface a wall counts for thickness; 0 = the mesh's bounding-sphere radius")
    target: str = setting(
        "image", label="Target", noun="bake target", choices=TARGET_CHOICES,
        description="where the AO goes; a colour attribute samples every vertex with light views as fine as a "
                    "Size map's")
    color_domain: str = setting(
        "point", label="Domain", noun="colour-attribute domain", choices=COLOR_DOMAIN_CHOICES,
        description="Color Attribute target: per vertex or per face corner")
    method: str = setting("auto", label="Method", choices=METHOD_CHOICES, description="GPU bake algorithm")
    view_samples: float = setting(
        2.0, label="View Samples", minimum=0.25, maximum=64.0, soft_max=8.0,
        description="light-view pixels per texel (with Texel Sets 2 x 2, the gather's per 2 x 2 texels): "
                    "more is smoother and slower")
    seed: int = setting(0, label="Seed", minimum=0, maximum=2**31 - 1, description="rotation of the direction set")

    def validated(self) -> "BakeSettings":
        """Return self, or raise SettingError / BakeInputError with a message a user can act on."""
        validate(self)
        return self

    @property
    def error_target(self) -> float:
        """The p99 error this bake adds directions until (0: exactly Directions)."""
        preset = QUALITY_ERRORS[self.quality]
        return self.max_error if preset is None or (preset == 0.0 and self.max_error > 0.0) else preset

    @property
    def direction_cap(self) -> int:
        """The most directions a bake to an error may use: a preset's own cap (QUALITY_CAPS),
        else Directions."""
        return QUALITY_CAPS.get(self.quality, self.directions)

    @property
    def spread_cos(self) -> float:
        """cos(Spread Angle): the weight's cut-off (0 for the whole hemisphere)."""
        return 0.0 if self.spread_angle >= 90.0 else math.cos(math.radians(self.spread_angle))

    @property
    def sample_count(self) -> int:
        """Samples per texel (1, 4, 9 or 16)."""
        return self.samples_per_texel

    def cache_key(self) -> tuple:
        return tuple(sorted(asdict(self).items()))
