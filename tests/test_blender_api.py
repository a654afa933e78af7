# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's Python API follows Blender's (issue 41 item 1): every enum identifier is
UPPER_CASE, as in all of bpy ('SELECTED', 'TANGENT', 'OPENGL'), and what scripts, presets
and farm submitters wrote against earlier releases keeps working: the core's lower-case
words of the previous release, and the UPPER_CASE identifiers of the ones before it."""
from __future__ import annotations

import re

import bpy
import numpy as np
import pytest

from conftest import select_only, soup_to_object
from hao_addon.core import scenes

GROUPS = ("hao_bake", "hao_view")


def enum_properties(group) -> list:
    return [p for p in group.bl_rna.properties if p.type == 'ENUM']


@pytest.mark.parametrize("name", GROUPS)
def test_every_enum_identifier_is_upper_case(scene, name):
    group = getattr(scene, name)
    enums = enum_properties(group)
    assert len(enums) >= (12 if name == "hao_bake" else 4)
    for prop in enums:
        for item in prop.enum_items:
            assert re.fullmatch(r"[A-Z0-9_]+", item.identifier), (prop.identifier, item.identifier)
        assert re.fullmatch(r"[A-Z0-9_]+", getattr(group, prop.identifier)), prop.identifier  # the default too


def test_the_identifiers_map_to_the_core_words_and_back(scene):
    """Each identifier is read back as the core's word (what the CLI takes and reports)."""
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.setting_spec import specs
    group = scene.hao_bake
    for field, spec in specs(BakeSettings):
        if not (spec.ui and spec.choices):
            continue
        for choice in spec.choices:
            setattr(group, field.name, choice.identifier)
            assert getattr(group.to_settings(), field.name) == choice.value


# A script written against the previous release (lower-case identifiers: the core's words),
# and what one written before it set (UPPER_CASE, Blender's convention).
PREVIOUS_RELEASE = dict(occluders='visible', target='image', method='gather', quality='fixed', weighting='cosine',
                        normals='mesh', terminator='setting', alpha='blend', bent_space='tangent',
                        bent_convention='opengl', png_bits='16', falloff='none')
EARLIER_RELEASE = dict(occluders='VISIBLE', uv_mode='AUTO', bent_space='TANGENT', bent_convention='OPENGL')


@pytest.mark.parametrize("release", [PREVIOUS_RELEASE, EARLIER_RELEASE], ids=["previous", "earlier"])
def test_a_script_written_against_an_earlier_release_still_bakes(scene, tmp_path, release):
    floor = soup_to_object(scenes.grid_plane(4.0, 4, name="floor"), "floor")
    ball = soup_to_object(scenes.uv_sphere(0.6, (0.0, 0.0, 0.6), 16, 8, name="ball"), "ball")
    select_only(floor)  # the ball occludes only as a visible mesh
    settings = scene.hao_bake
    for name, value in release.items():
        setattr(settings, name, value)
    settings.size, settings.directions, settings.margin = 32, 16, 2
    settings.filepath = str(tmp_path / "{object}.png")
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert settings.occluders == 'VISIBLE' and settings.to_options().occluders == "visible"
    image = bpy.data.images["floor_AO"]
    pixels = np.array(image.pixels[:]).reshape(32, 32, 4)[..., 0]
    assert pixels.min() < 0.6  # the ball's contact shadow: it occluded
    assert (tmp_path / "floor.png").is_file()
    del ball


def test_the_viewport_takes_its_earlier_identifiers(scene):
    view = scene.hao_view
    view.method = 'near+far'
    assert view.method == 'NEAR_FAR' and view.to_settings().method == "near+far"
    view.march = 'hierarchical'
    assert view.march == 'HIERARCHICAL'
    with pytest.raises(TypeError, match="not found"):
        view.march = 'sideways'  # an unknown word is still refused, by Blender's own message


def test_the_panel_and_the_command_line_share_the_occluders_default(scene):
    """Issue 41 item 3: every visible mesh occludes by default, as in Cycles' bake, whether the
    bake starts from the panel or from the command line (one definition, no second default)."""
    from hao_addon.cli.parser import build_parser
    from hao_addon.core.bake.job_options import JobOptions
    assert JobOptions().occluders == "visible"
    assert scene.hao_bake.occluders == 'VISIBLE' and scene.hao_bake.to_options().occluders == "visible"
    args = build_parser().parse_args(["bake", "in.obj", "--out", "ao.png"])
    assert args.occluders == "visible"
