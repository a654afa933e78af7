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
