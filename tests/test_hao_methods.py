# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport AO methods as data (core/hao/methods.py) run by one sequencer
(gpu/hao_renderer.py), and the viewport session that owns the renderers."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.core.hao.methods import METHOD_PLANS
from hao_addon.core.hao.view_settings import METHODS, ViewAOSettings
from test_hao import view
from test_spheres_gpu import CENTRES, RADII, _scene

def test_every_method_is_a_plan_of_known_passes_in_dependency_order():
    from hao_addon.gpu.hao_renderer import AO_MAP, FRAME_INPUTS, PASSES
    assert set(METHOD_PLANS) == set(METHODS)
    for plan in METHOD_PLANS.values():
        written = set(FRAME_INPUTS)
        for name in plan.passes:
            spec = PASSES[name]
            assert callable(spec.run) and spec.run.__qualname__.startswith("HaoRenderer."), name
            missing = set(spec.reads) - written
            assert not missing, f"{plan.name}: {name} reads {missing} before anything wrote it"
            written.add(spec.writes or name)
        assert plan.passes[-1] == "filter" and AO_MAP in written
        assert plan.spheres == ("spheres" in plan.passes)


def test_the_viewport_refuses_its_input_as_view_input_not_bake_input(renderer):
    """What the viewport cannot render is a ViewInputError (a UserInputError every interface
    reports as one line), not a bake's error."""
    from hao_addon.core.errors import BakeInputError, UserInputError, ViewInputError
    objs, _ = _scene()
    vp, _w, _h = view((2.2, -2.6, 2.4), target=(0.0, 0.0, 0.2))
    with pytest.raises(ViewInputError, match="image size must be positive") as refused:
        renderer.render(objs, vp, 0, 16, ViewAOSettings(rays=8, grid=64))
    assert isinstance(refused.value, UserInputError) and not isinstance(refused.value, BakeInputError)
    with pytest.raises(ViewInputError, match="needs sphere proxies"):
        renderer.render(objs, vp, 16, 16, ViewAOSettings(rays=8, grid=64, method="far"))


@pytest.mark.parametrize("other", ["near", "far"])
def test_switching_methods_reruns_what_the_other_method_changed(renderer, other):
    """The AO map is written in place (by voxel_ao, near_field or open_ao, then spheres
    multiply into it): after a frame of another method, the same 'hao' frame as before is
    rendered, not the other method's leftovers."""
    objs, _ = _scene()
    settings = ViewAOSettings(rays=8, grid=64)
    vp, w, h = view((2.2, -2.6, 2.4), target=(0.0, 0.0, 0.2))
    spheres = (CENTRES, RADII)
    renderer.render(objs, vp, w, h, settings, spheres=spheres)
    first = renderer.read_ao()
    renderer.render(objs, vp, w, h, settings.with_(method=other), spheres=spheres)
    assert np.abs(renderer.read_ao() - first).max() > 0.05  # the other method differs
    ao_runs = renderer.stats["ao"]
    renderer.render(objs, vp, w, h, settings, spheres=spheres)
    np.testing.assert_array_equal(renderer.read_ao(), first)
    assert renderer.stats["ao"] == ao_runs + 1
    renderer.render(objs, vp, w, h, settings, spheres=spheres)  # and then nothing runs
    assert renderer.stats["ao"] == ao_runs + 1


def test_session_frees_the_renderers_of_closed_regions(gpu_context):
    from hao_addon.blender.viewport_session import ViewportSession
    from hao_addon.gpu import util
    session = ViewportSession()
    before = util.live_pass_count()
    a = session.renderer_for(1, {1})
    assert session.renderer_for(1, {1}) is a
    session.renderer_for(2, {1, 2})
    assert set(session.renderers) == {1, 2}
    session.renderer_for(3, {3})  # regions 1 and 2 were closed
    assert set(session.renderers) == {3} and a._freed
    session.free()
    assert not session.renderers and util.live_pass_count() == before
