# SPDX-License-Identifier: GPL-3.0-or-later
"""The bakers' declared abilities (core/bake/abilities.py, issue 30 item 0): Auto's choice,
the refusals and the factory come from one table, and the plan refuses a method before any
work (a Selected-to-Active projection included)."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from hao_addon.core import scenes
from hao_addon.core.bake.abilities import (ABILITIES, ABILITY_NAMES, BAKE_METHODS, BAKERS, bakers_with,
                                           choose_method, declaration)
from hao_addon.core.bake.bake_run import BakeRun
from hao_addon.core.bake.plan import make_plan
from hao_addon.core.bake.projection import HighToLow
from hao_addon.core.bake.settings import METHODS, BakeSettings
from hao_addon.core.bake.vertex_target import indexed_vertex_target
from hao_addon.core.errors import BakeInputError
from hao_addon.core.steps import drain
from hao_addon.core.geometry import TriangleSoup


def plan_needing(ability: str, method: str):
    """make_plan of a small scene that needs `ability` (and nothing else but what it implies)."""
    plane = scenes.grid_plane(2.0, 4, name="plane")
    kw = dict(size=32, directions=4, method=method)
    if ability == "max-distance":
        return make_plan(plane, [], BakeSettings(max_distance=1.0, **kw))
    if ability == "selected-to-active":
        def no_cast(*_args, **_kw):
            raise AssertionError("the projection ran before the method was refused")
        import bpy  # noqa: F401 - makes mathutils (the CPU cast's BVH) importable
        from hao_addon.core.bake.projection import project_steps
        cast = project_steps if method == "auto" or declaration(method).can(ability) else no_cast
        return make_plan(scenes.grid_plane(2.0, 2, z=0.5, name="low"), [], BakeSettings(**kw),
                         high_to_low=HighToLow([plane]), cast=cast)
    if ability == "bent-normals":
        return make_plan(plane, [], BakeSettings(bent_normals=True, **kw))
    if ability == "udim":
        uvs = plane.uvs.copy()
        uvs[: len(uvs) // 2, :, 0] += 1.0  # half the faces on tile 1002
        return make_plan(TriangleSoup(plane.positions, uvs, "plane"), [], BakeSettings(**kw))
    if ability == "color-attribute":
        points = plane.positions.reshape(-1, 3)
        verts, index = np.unique(points.round(9), axis=0, return_inverse=True)
        return make_plan(TriangleSoup(plane.positions, None, "plane"), [], BakeSettings(target="color-attribute", **kw),
                         vertex_target=indexed_vertex_target(index.reshape(-1, 3), len(verts)))
    if ability == "min-distance":
        return make_plan(plane, [], BakeSettings(min_distance=0.5, **kw))
    if ability == "spread":
        return make_plan(plane, [], BakeSettings(spread_angle=60.0, **kw))
    if ability == "alpha":
        from hao_addon.core.bake.alpha import SoupAlpha
        card = scenes.grid_plane(2.0, 2, z=0.5, name="card")
        card = TriangleSoup(card.positions, None, "card", alpha=SoupAlpha(np.full(card.face_count, 0.5, np.float32)))
        return make_plan(plane, [card], BakeSettings(**kw))
    if ability == "thickness":  # a need of thickness_steps' run (tests/test_thickness.py), not of its settings
        settings = BakeSettings(max_distance=1.0, **kw)
        return make_plan(plane, [], settings, run=BakeRun.of(settings, frozenset({"thickness"})))
    raise AssertionError(f"no scene needs {ability}")


@pytest.mark.parametrize("baker,ability", [(b, a) for b in BAKERS for a in ABILITIES])
def test_a_plan_is_refused_exactly_where_its_method_lacks_the_ability(baker, ability):
    """Every (baker, ability): a bake needing it plans when the baker declares it, and is
    refused before any work otherwise, naming what is asked, why, and the methods that can."""
    if baker.can(ability.name):
        plan = plan_needing(ability.name, baker.method)
        assert ability.name in plan.abilities_needed
        plan.check_method(baker.method)
        return
    with pytest.raises(BakeInputError) as refused:
        plan_needing(ability.name, baker.method)
    message = str(refused.value)
    assert message.startswith(f"the {baker.label} cannot bake ")
    assert baker.cannot[ability.name] in message
    for other in bakers_with(ability.name):
        assert f"the {declaration(other).label}" in message


def test_udim_refusal_names_the_tiles():
    with pytest.raises(BakeInputError, match="cannot bake UDIM tiles 1001, 1002 "):
        plan_needing("udim", "scatter")


def test_every_ability_has_a_gpu_baker_and_the_reference():
    for name in ABILITY_NAMES:
        assert bakers_with(name, gpu_only=True), name
        assert "reference" in bakers_with(name), name  # the GPU bakers' truth bakes all of it


def test_auto_takes_the_scatter_for_a_max_distance_alone_otherwise_the_gather():
    """Auto's rule as the benchmark set it, over every combination of needs: the scatter for
    a max distance alone, the gather otherwise; thickness, which the gather declares it
    cannot bake, with the scatter where it can bake the rest, else refused."""
    scatter_can = {"max-distance", "thickness", "min-distance", "spread", "alpha"}
    for k in range(len(ABILITY_NAMES) + 1):
        for needs in map(frozenset, itertools.combinations(ABILITY_NAMES, k)):
            assert choose_method("reference", needs) == "reference"
            if "thickness" in needs and not needs <= scatter_can:
                with pytest.raises(BakeInputError, match="no GPU baker can bake"):
                    choose_method("auto", needs)
                continue
            by_scatter = needs <= scatter_can and ("max-distance" in needs or "thickness" in needs)
            assert choose_method("auto", needs) == ("scatter" if by_scatter else "gather"), needs


def test_the_plan_chooses_through_the_declarations():
    """The one place a method is chosen (issue 40 item 4): the plan, from what the bake needs."""
    for ability, method in (("max-distance", "scatter"), ("selected-to-active", "gather"), ("udim", "gather"),
                            ("color-attribute", "gather"), ("thickness", "scatter"), ("bent-normals", "gather")):
        assert plan_needing(ability, "auto").method == method, ability


def test_the_methods_setting_and_the_factory_list_the_declared_bakers():
    from hao_addon.bakers import BAKE_METHODS as FACTORY_METHODS
    assert METHODS == ("auto", *BAKE_METHODS) and FACTORY_METHODS == BAKE_METHODS
    with pytest.raises(ValueError, match="unknown abilities"):
        bakers_with("groups-by-name")


def test_each_baker_class_is_its_declared_method(gpu_context):
    from hao_addon.bakers import baker_for
    for method in BAKE_METHODS:
        assert baker_for(method).METHOD == method


def test_the_plan_chooses_the_method_once_and_the_result_carries_it(gpu_context, monkeypatch):
    """One place chooses the method (the plan: BakePlan.method); the bake runs that baker and
    the result carries it as a value (BakeResult.method), with no second choice after the plan."""
    from hao_addon import bake as bake_module
    from hao_addon.core.bake import plan as plan_module

    sphere = scenes.uv_sphere(1.0, (0.0, 0.0, 0.0), 16, 8)
    for settings, method in ((BakeSettings(size=32, directions=8, max_distance=0.5), "scatter"),
                             (BakeSettings(size=32, directions=8), "gather")):
        assert make_plan(sphere, [], settings).method == method
    calls = []
    real = plan_module.choose_method
    monkeypatch.setattr(plan_module, "choose_method", lambda *a: calls.append(a) or real(*a))
    monkeypatch.setattr(bake_module, "choose_method", lambda *a: pytest.fail("chosen again after the plan"),
                        raising=False)
    result = bake_module.bake(sphere, [], BakeSettings(size=32, directions=8, max_distance=0.5), use_cache=False)
    assert result.method == result.stats["method"] == "scatter" and len(calls) == 1


def test_rounds_and_verification_take_their_run_as_a_value(gpu_context, monkeypatch):
    """Issue 40 item 4: a bake to an error's rounds and a verification plan the user's settings
    unchanged, each with its own BakeRun (directions, seed, method, cells); a thickness bake's
    need of the thickness ability is its run's, and the plan alone chooses the method."""
    from hao_addon import bake as bake_module
    from hao_addon import verify as verify_module
    from hao_addon.core.bake import plan as plan_module

    planned = []
    real = plan_module.make_plan_steps

    def recorded(target, occluders, settings, *args, **kwargs):
        planned.append((settings, kwargs.get("run")))
        return real(target, occluders, settings, *args, **kwargs)

    monkeypatch.setattr(bake_module, "make_plan_steps", recorded)
    monkeypatch.setattr(verify_module, "make_plan_steps", recorded)
    sphere, floor = scenes.uv_sphere(0.6, (0.0, 0.0, 0.6), 16, 8), scenes.grid_plane(4.0, 4, name="floor")
    settings = BakeSettings(size=32, directions=4096, max_error=0.05, seed=3)
    result = bake_module.bake(floor, [sphere], settings, use_cache=False)
    assert len(planned) == len(result.stats["rounds"]) > 1
    assert all(s == settings.validated() for s, _run in planned)  # never rewritten
    runs = [run for _s, run in planned]
    assert [r.directions for r in runs] == result.stats["rounds"] and len({r.seed for r in runs}) == len(runs)
    assert runs[0].seed == settings.seed and {r.method for r in runs} == {"auto"}

    planned.clear()
    verification = drain(verify_module.verify_steps(floor, [sphere], settings, result, 16))
    assert verification is not None and len(planned) == 1
    (s, run), = planned
    assert s == settings and run.method == "reference" and run.ao_only and len(run.cells) == 16

    planned.clear()
    thickness = drain(bake_module.thickness_steps(sphere, BakeSettings(size=32, directions=16, thickness=True),
                                                  use_cache=False))
    (s, run), = planned
    assert run.needs == frozenset({"thickness"}) and thickness.method == "scatter"
