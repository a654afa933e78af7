# SPDX-License-Identifier: GPL-3.0-or-later
"""--maps (issue 30 item 3): several maps of one bake named after --out, each as its own
option would write it."""
from __future__ import annotations

import json


def test_maps_write_each_map_beside_the_ao_as_their_own_options_do(tmp_path):
    from test_cli_runs import SPOT, run

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    bake = ["bake", SPOT, "--size", "64", "--directions", "16", "--quiet"]
    done = run([*bake, "--out", tmp_path / "ao.png", "--maps", "ao,bent-normal,thickness,orm", "--json",
                tmp_path / "r.json"], tmp)
    assert done.returncode == 0, done.stderr
    names = [p.rsplit("/", 1)[-1] for p in json.loads((tmp_path / "r.json").read_text())["outputs"]]
    assert names == ["ao.png", "ao_bent_normal.png", "ao_thickness.png", "ao_orm.png"]
    (tmp_path / "own").mkdir()
    own = tmp_path / "own"
    done = run([*bake, "--out", own / "ao.png", "--bent-normal-out", own / "ao_bent_normal.png", "--thickness-out",
                own / "ao_thickness.png", "--orm-out", own / "ao_orm.png"], tmp)
    assert done.returncode == 0, done.stderr
    for name in names:  # the same bake (the files' bake key differs with the options: compare pixels)
        from bake_helpers import load_image_rgba
        assert (load_image_rgba(tmp_path / name) == load_image_rgba(own / name)).all(), name


def test_every_map_is_one_row_everywhere(addon):
    """Each row of core/bake/map_kinds.py is a --maps word, a file option, a panel field, an
    entry of the --skip-existing key and a row of the manual's table; the key counts whether
    a map is written, not where (a farm task and a local run share it)."""
    import argparse

    import bpy
    from conftest import ROOT
    from hao_addon.cli.parser import MAP_OUTPUTS, build_parser
    from hao_addon.cli.skip import run_key
    from hao_addon.core.bake.map_kinds import EXTRA_MAPS, MAP_KINDS
    from test_cli_runs import SPOT

    assert list(MAP_OUTPUTS) == [kind.name for kind in MAP_KINDS]
    base = build_parser().parse_args(["bake", str(SPOT), "--out", "a.png"])
    key = run_key(base, [SPOT])
    panel = bpy.types.Scene.bl_rna.properties["hao_bake"].fixed_type.bl_rna.properties
    settings_page = (ROOT / "docs" / "settings.md").read_text(encoding="utf-8")
    for kind in MAP_KINDS:
        assert kind.property_name in panel and panel[kind.property_name].subtype == 'FILE_PATH', kind.name
        assert f"| `{kind.name}` | `{kind.flag}` | *{kind.panel_label}* |" in settings_page, kind.name
    for kind in EXTRA_MAPS:
        asked = argparse.Namespace(**{**vars(base), kind.option: "m.png"})
        elsewhere = argparse.Namespace(**{**vars(base), kind.option: "other/m.png"})
        assert run_key(asked, [SPOT]) != key, kind.name
        assert run_key(asked, [SPOT]) == run_key(elsewhere, [SPOT]), kind.name


def test_the_panel_writes_every_map_it_has_a_field_for(scene, tmp_path):
    """The panel's file fields come from the rows, the ORM texture's too (the panel had none):
    each writes its file, and the ORM texture's red channel is the AO map."""
    import bpy
    import numpy as np
    from bake_helpers import load_image_rgba
    from conftest import select_only, small_settings
    from hao_addon.core.bake.map_kinds import EXTRA_MAPS

    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.active_object
    select_only(obj)
    paths = {kind.property_name: str(tmp_path / f"{kind.key}.png") for kind in EXTRA_MAPS}
    small_settings(scene, filepath=str(tmp_path / "ao.png"), bent_normals=True, thickness=True, size=64,
                   directions=16, **paths)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["ao.png", *(f"{k.key}.png" for k in EXTRA_MAPS)])
    ao, orm = load_image_rgba(tmp_path / "ao.png"), load_image_rgba(tmp_path / "orm.png")
    np.testing.assert_array_equal(orm[..., 0], ao[..., 0])


def test_a_new_map_row_leaves_the_skip_key_of_bakes_without_it(monkeypatch):
    """The --skip-existing key counts the maps a bake writes, so adding a map row does not
    make every earlier file look stale."""
    from dataclasses import replace

    from hao_addon.cli import skip
    from hao_addon.cli.parser import build_parser
    from hao_addon.core.bake.map_kinds import EXTRA_MAPS
    from test_cli_runs import SPOT

    base = build_parser().parse_args(["bake", str(SPOT), "--out", "a.png"])
    key = skip.run_key(base, [SPOT])
    future = replace(EXTRA_MAPS[-1], name="future", key="future", skip_key="future_file")
    monkeypatch.setattr(skip, "EXTRA_MAPS", (*EXTRA_MAPS, future))
    assert skip.run_key(base, [SPOT]) == key
