# SPDX-License-Identifier: GPL-3.0-or-later
"""What each baker can bake, declared once (pure data, no GPU).

A bake *needs* abilities (a max distance, Selected to Active, bent normals, UDIM tiles, a
colour attribute); each baker declares the ones it lacks and why. Everything that depended
on a baker's reach comes from these rows: Auto's choice (``choose_method``), the refusal
when a chosen method cannot bake what is asked (``check_method``), the methods factory's
list (hao_addon/bakers.py), the manual's table (tools/docs_pages.py) and the tests'
backend lists (``bakers_with``). A new capability is a new row of ABILITIES, and the bakers
that lack it say so in their ``cannot``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from ..errors import BakeInputError
from .target_kinds import TargetKind


@dataclass(frozen=True)
class Ability:
    """name: the key bakers declare. phrase: how a message names what is asked ('Selected
    to Active'). label: the README table's column."""

    name: str
    label: str
    phrase: str


ABILITIES = (
    Ability("max-distance", "Max distance, falloff", "a max distance"),
    Ability("min-distance", "Min distance", "a min distance"),
    Ability("spread", "Spread angle", "a spread angle"),
    Ability("selected-to-active", "Selected to Active", "Selected to Active"),
    Ability("bent-normals", "Bent normals", "bent normals"),
    Ability("udim", "UDIM tiles", "UDIM tiles"),
    Ability("color-attribute", "Colour attribute", "a colour attribute"),
    Ability("thickness", "Thickness", "thickness"),
    Ability("alpha", "Alpha occluders", "occluders that let light through"),
)
ABILITY_NAMES = tuple(a.name for a in ABILITIES)


@dataclass(frozen=True)
class BakerDeclaration:
    """method: the setting's value. label: its name in messages. gpu: runs on the GPU (Auto
    picks among these only). cannot: ability -> why not (in the words of a message, after
    'because'). auto_for: Auto prefers this baker when the bake needs all of these and the
    baker can bake it (the benchmark's fastest at equal error); an empty set is the fallback.
    bakes_all_cells: why the baker bakes every texel of its target even when a plan names the
    cells still needed (BakePlan.cells: the later rounds of a bake to an error); '' when it
    bakes only those. floor_unchecked: why the bake's visibility floor is not measured
    (hao_addon/floor_check.py: exact rays at sampled texels along its own directions); '' when it is.
    crops_views: its light views can be cropped to spheres (BakeRun.window_spheres), a
    receiver outside reading lit: a re-bake by difference (hao_addon/rebake_difference.py).
    traces_contacts: its visibility test misses occluders nearer than its depth slack, so the
    receivers in contact with another surface (core/bake/contacts.py) are traced exactly
    (hao_addon/contact_repair.py). interleaves: it can bake neighbouring texels with
    differently rotated direction sets (core/bake/interleave.py), so that the map's error is
    grain, not the polygons of one set's shadows."""

    method: str
    label: str
    gpu: bool
    cannot: Mapping[str, str] = field(default_factory=dict)
    auto_for: frozenset[str] = frozenset()
    bakes_all_cells: str = ""
    floor_unchecked: str = ""
    crops_views: bool = False
    traces_contacts: bool = False
    interleaves: bool = False

    def can(self, ability: str) -> bool:
        return ability not in self.cannot

    def can_all(self, needs: frozenset[str]) -> bool:
        return all(self.can(a) for a in needs)


# In Auto's order of preference.
BAKERS = (
    BakerDeclaration(
        "scatter", "histogram scatter", gpu=True, auto_for=frozenset({"max-distance"}),
        cannot={"selected-to-active": "it draws the target's own surface, and high-poly points projected onto its "
                                      "texels are no triangles it could draw",
                "bent-normals": "its accumulator packs ambient occlusion's two sums in one word",
                "udim": "it rasterizes one 0..1 UV tile",
                "color-attribute": "it rasterizes the UV layout"},
        bakes_all_cells="it splats every texel its target's triangles cover in each light view"),
    BakerDeclaration(
        "gather", "shadow-map gather", gpu=True, crops_views=True, traces_contacts=True, interleaves=True,
        cannot={"thickness": "from inside a closed surface its max-distance depth lists miss part of the nearest "
                             "walls: 0.006 too thin on a ball, measured by tests/test_thickness.py"}),
    BakerDeclaration("reference", "reference (CPU ray tracing)", gpu=False, interleaves=True,
                     floor_unchecked="its visibility is exact: rays against the triangles"),
)
BAKE_METHODS = tuple(b.method for b in BAKERS)
_BY_METHOD = {b.method: b for b in BAKERS}


def declaration(method: str) -> BakerDeclaration:
    if method not in _BY_METHOD:
        raise ValueError(f"unknown bake method '{method}', expected one of {BAKE_METHODS}")
    return _BY_METHOD[method]


def bakers_with(*abilities: str, gpu_only: bool = False) -> list[str]:
    """The methods that can bake all of `abilities` (the tests' backend lists)."""
    unknown = set(abilities) - set(ABILITY_NAMES)
    if unknown:
        raise ValueError(f"unknown abilities {sorted(unknown)}")
    return [b.method for b in BAKERS if b.can_all(frozenset(abilities)) and (b.gpu or not gpu_only)]


def abilities_needed(max_distance: float, bent_normals: bool, target_kind: TargetKind,
                     tiled: bool, min_distance: float = 0.0, spread: bool = False) -> frozenset[str]:
    """The abilities a bake with these settings, this kind of target (its row's ability:
    Selected to Active, a colour attribute) and, where tiled, a UV layout on UDIM tiles needs."""
    asked = {"max-distance": max_distance > 0.0, "bent-normals": bent_normals, "udim": tiled,
             "min-distance": min_distance > 0.0, "spread": spread}
    needed = {name for name, wanted in asked.items() if wanted}
    return frozenset(needed | ({target_kind.ability} if target_kind.ability else set()))


def choose_method(method: str, needs: frozenset[str]) -> str:
    """The method that runs: `method` itself unless 'auto', which is the first GPU baker
    whose auto_for the bake needs and which can bake it, else the fallback (a GPU baker
    with an empty auto_for) if it can, else the first GPU baker that can."""
    if method != "auto":
        return method
    able = [b for b in BAKERS if b.gpu and b.can_all(needs)]
    for baker in able:
        if baker.auto_for and baker.auto_for <= needs:
            return baker.method
    fallback = [b for b in able if not b.auto_for]
    if fallback or able:
        return (fallback or able)[0].method
    phrases = [a.phrase for a in ABILITIES if a.name in needs]
    raise BakeInputError(f"no GPU baker can bake {_and(phrases)} together; use the reference")


def check_method(method: str, needs: frozenset[str], asked: Mapping[str, str] | None = None) -> None:
    """Raise BakeInputError, naming what cannot be baked, why and which methods can, when
    `method` lacks an ability the bake needs. asked: ability -> how this bake's message names
    it, where more precise than the ability's phrase ('UDIM tiles 1001, 1002')."""
    baker = declaration(method)
    for ability in ABILITIES:
        if ability.name in needs and not baker.can(ability.name):
            auto = [b.method for b in BAKERS if b.gpu and b.auto_for <= needs and b.can_all(needs)][:1]
            use = _or([f"the {b.label}" + (" (also Auto's choice)" if [b.method] == auto else "")
                       for b in BAKERS if b.can_all(needs)])
            phrase = (asked or {}).get(ability.name, ability.phrase)
            raise BakeInputError(f"the {baker.label} cannot bake {phrase} ({baker.cannot[ability.name]}); use {use}")


def _and(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _or(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]
