# SPDX-License-Identifier: GPL-3.0-or-later
"""The bake panel's layout, drawn into a recording layout (no window needed): laid out as
Cycles' Bake panel (the Bake button and what to bake on top, then Output, Selected to
Active, Maps, Quality, Advanced, the rarely needed ones collapsed), every bake setting drawn
exactly once, the Maps sub-panel made from the map rows, each draw short enough to read."""
from __future__ import annotations

import inspect
import sys
from types import SimpleNamespace

import bpy


class RecordingLayout:
    """What a panel's draw puts on screen, in order: ('prop', name), ('op', idname), ('label', text)."""

    def __init__(self, log: list) -> None:
        self.log = log

    def column(self, **_kw):
        return RecordingLayout(self.log)

    row = column

    def prop(self, _data, name, **_kw):
        self.log.append(("prop", name))

    def prop_search(self, _data, name, *_a, **_kw):
        self.log.append(("prop", name))

    def template_ID(self, _data, name, **_kw):  # noqa: N802 - Blender's name
        self.log.append(("prop", name))

    def operator(self, idname, **_kw):
        self.log.append(("op", idname))
        return SimpleNamespace()  # the operator's properties, as Blender returns them

    def label(self, text="", **_kw):
        self.log.append(("label", text))

    def separator(self, **_kw):
        pass


def drawn(panel, scene) -> list:
    """What `panel` draws, called as Blender calls it (draw_header, then draw) on a stand-in
    for its instance that has the panel's own methods."""
    log: list = []
    fake = SimpleNamespace(layout=RecordingLayout(log))
    if hasattr(panel, "draw_settings"):
        fake.draw_settings = lambda *args: panel.draw_settings(fake, *args)
    context = SimpleNamespace(scene=scene, active_object=None)
    if hasattr(panel, "draw_header"):
        panel.draw_header(fake, context)
    panel.draw(fake, context)
    return log


def bake_panels(addon):
    return sys.modules[f"{addon.__name__}.operators.panels"].BAKE_PANELS


def test_the_bake_panel_is_laid_out_as_cycles_bake_panel(scene, addon):
    panels = bake_panels(addon)
    assert [p.bl_label for p in panels] == ["Bake AO", "Output", "Selected to Active", "Maps", "Quality", "Advanced"]
    assert all(p.bl_parent_id == "VIEW3D_PT_hao_bake" for p in panels[1:])
    collapsed = {p.bl_label for p in panels if "DEFAULT_CLOSED" in getattr(p, "bl_options", set())}
    assert collapsed == {"Selected to Active", "Maps", "Advanced"}
    top = drawn(panels[0], scene)
    assert top[0] == ("op", "object.hao_bake_ao")  # the Bake button first, as in Cycles
    assert ("prop", "target") in top and ("prop", "size") in top


def test_every_bake_setting_is_drawn_once(scene, addon):
    """With every conditional field showing (a named UV map, a colour-attribute target for its
    domain, Custom quality for its direction cap), each property of the bake settings is in
    exactly one sub-panel; a property left out of the panel, or drawn twice, fails."""
    settings = scene.hao_bake
    settings.uv_mode, settings.target, settings.quality = 'NAMED', "color-attribute", "custom"
    names = [name for panel in bake_panels(addon) for kind, name in drawn(panel, scene) if kind == "prop"]
    wanted = {p.identifier for p in settings.bl_rna.properties if p.identifier not in ("rna_type", "name")}
    assert sorted(names) == sorted(wanted), (set(wanted) - set(names), [n for n in names if names.count(n) > 1])


def test_the_maps_sub_panel_is_drawn_from_the_map_rows(scene, addon):
    from hao_addon.core.bake.map_kinds import EXTRA_MAPS
    maps = [name for kind, name in drawn(bake_panels(addon)[3], scene) if kind == "prop"]
    expected = [name for kind in EXTRA_MAPS
                for name in ((kind.setting,) if kind.setting else ()) + kind.settings + (kind.property_name,)]
    assert maps == expected


def test_no_panel_draw_is_longer_than_a_screen(addon):
    panels = sys.modules[f"{addon.__name__}.operators.panels"]
    for panel in (*panels.BAKE_PANELS, panels.VIEW3D_PT_hao_view):
        for draw in (panel.draw, getattr(panel, "draw_settings", panel.draw)):
            assert len(inspect.getsource(draw).splitlines()) <= 60, panel.__name__
    assert bpy.types.VIEW3D_PT_hao_bake_maps.bl_parent_id == "VIEW3D_PT_hao_bake"  # registered as a sub-panel
