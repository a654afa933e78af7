# SPDX-License-Identifier: GPL-3.0-or-later
"""One definition per setting: the panel's properties, the command-line options, the core's
validation and the README tables agree on every default, range and description."""
from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import fields

import pytest

import bpy
from conftest import ROOT
from hao_addon.cli.parser import build_parser
from hao_addon.core.setting_spec import SettingError, check_value, specs
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.hao.view_settings import RenderSize, ViewAOSettings

SETTINGS = [(BakeSettings, "bake", "hao_bake"), (ViewAOSettings, "render-ao", "hao_view"),
            (RenderSize, "render-ao", None)]


def subparser(command):
    parser = build_parser()
    action = next(a for a in parser._actions if a.dest == "command")
    return action.choices[command]


@pytest.mark.parametrize("cls, command, group", SETTINGS, ids=[s[0].__name__ for s in SETTINGS])
def test_cli_options_match_the_core(cls, command, group):
    options = {a.dest: a for a in subparser(command)._actions}
    for f, spec in specs(cls):
        if spec.option(f.name) is None:
            assert f.name not in options
            continue
        action = options[f.name]
        assert spec.option(f.name) in action.option_strings
        assert action.default == f.default, f.name
        assert action.help and spec.description.split(";")[0] in action.help.replace("%%", "%"), f.name
        if spec.choices:
            assert list(action.choices) == [c.value for c in spec.choices]
        elif not isinstance(f.default, bool):
            assert action.type is type(f.default)


@pytest.mark.parametrize("cls, command, group", [s for s in SETTINGS if s[2]], ids=["bake", "view"])
def test_panel_properties_match_the_core(addon, cls, command, group):
    rna = bpy.types.Scene.bl_rna.properties[group].fixed_type.bl_rna.properties
    for f, spec in specs(cls):
        if not spec.ui:
            continue
        prop = rna[f.name]
        assert prop.name == spec.label and prop.description.lower().startswith(spec.description[:20].lower())
        if spec.choices:
            assert [i.identifier for i in prop.enum_items] == [c.identifier for c in spec.choices]
            assert prop.default == next(c.identifier for c in spec.choices if c.value == f.default)
            continue
        if isinstance(f.default, bool):
            assert prop.default == f.default
            continue
        assert math.isclose(prop.default, f.default, rel_tol=1e-6), f.name
        # The panel admits exactly what the core accepts (an excluded minimum starts just above it).
        low = prop.hard_min
        if spec.minimum is None:
            assert low <= -1e30 or low == -(2**31)
        elif spec.above_minimum:
            assert spec.minimum < low <= spec.minimum + 1e-5
        else:
            assert math.isclose(low, spec.minimum, rel_tol=1e-6, abs_tol=1e-9), f.name
        if spec.maximum is not None:
            assert math.isclose(prop.hard_max, spec.maximum, rel_tol=1e-6), f.name
        check_value(f, spec, type(f.default)(low))  # the panel's own bounds pass validation
        check_value(f, spec, type(f.default)(prop.hard_max) if spec.maximum is not None else f.default)


@pytest.mark.parametrize("cls", [s[0] for s in SETTINGS], ids=[s[0].__name__ for s in SETTINGS])
def test_core_validation_is_the_spec(cls):
    cls().validated()  # defaults are valid
    for f, spec in specs(cls):
        if spec.choices:
            with pytest.raises(SettingError, match=spec.message_name):
                cls(**{f.name: "nope"}).validated()
            continue
        if isinstance(f.default, bool):
            continue
        is_int = isinstance(f.default, int)
        bad = [1.5] if is_int else [float("nan"), float("inf")]  # wrong kind, not finite
        step = 1 if is_int else 1e-3
        if spec.minimum is not None:
            bad.append(spec.minimum if spec.above_minimum else spec.minimum - step)
        if spec.maximum is not None:
            bad.append(spec.maximum + step)
        for value in bad:
            with pytest.raises(SettingError, match=spec.message_name) as err:
                cls(**{f.name: value}).validated()
            assert err.value.name == f.name


@pytest.mark.parametrize("cls", [s[0] for s in SETTINGS], ids=[s[0].__name__ for s in SETTINGS])
def test_a_choice_is_of_its_settings_kind(cls):
    """Reports and --json carry a setting as the core holds it: a mode as a word, a count as a
    number, never a count as a string ("1")."""
    for f, spec in specs(cls):
        assert all(type(c.value) is type(f.default) for c in spec.choices), f.name
        if spec.choices and isinstance(f.default, str):
            assert not any(c.value.isdigit() for c in spec.choices), f.name


def test_panel_values_reach_the_settings_as_their_kind(addon, scene):
    """A count chosen in the panel (an enum whose identifiers are strings) reaches the bake
    as a number."""
    scene.hao_bake.samples_per_texel = "4"
    try:
        assert scene.hao_bake.to_settings().samples_per_texel == 4
    finally:
        scene.hao_bake.samples_per_texel = "1"


def test_every_setting_is_described_once():
    for cls, _command, _group in SETTINGS:
        for f in fields(cls):
            assert "spec" in f.metadata, f"{cls.__name__}.{f.name} has no setting definition"


def test_the_manuals_generated_pages_are_current():
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "docs_pages.py"), "--check"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
