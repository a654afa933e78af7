# SPDX-License-Identifier: GPL-3.0-or-later
"""The README's setting tables, made from the settings' one definition (core/setting_spec.py).

    python tools/readme_tables.py           # rewrite the tables in README.md
    python tools/readme_tables.py --check   # exit 1 if README.md differs (the tests do this)

A table sits between ``<!-- settings:NAME -->`` and ``<!-- /settings:NAME -->``; the
bakers' abilities (core/bake/abilities.py) between ``<!-- settings:bakers -->`` and its end.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from hao_addon.core.setting_spec import specs  # noqa: E402
from hao_addon.core.bake import abilities  # noqa: E402
from hao_addon.core.bake.job_options import JobOptions  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.hao.view_settings import RenderSize, ViewAOSettings  # noqa: E402

TABLES = {"bake": (BakeSettings,), "job": (JobOptions,), "view": (ViewAOSettings,), "render-size": (RenderSize,)}


def table(*settings_classes) -> str:
    rows = ["| Setting | Option | Default | Range | What it does |", "|---|---|---|---|---|"]
    for cls in settings_classes:
        for f, spec in specs(cls):
            option = f"`{spec.option(f.name) or spec.cli_via}`" if spec.option(f.name) or spec.cli_via else "(panel only)"
            label = spec.label if spec.ui else "(command line only)"
            default = f"`{f.default}`" if not isinstance(f.default, bool) else ("on" if f.default else "off")
            if spec.cli_default is not None:
                default += f" (command line: `{spec.cli_default}`)"
            what = spec.sentence
            if spec.choices:
                what += ": " + "; ".join(f"*{c.label}* (`{c.value}`) {c.description}" for c in spec.choices)
            rows.append(f"| {label} | {option} | {default} | {spec.range_text() or '-'} | {what}. |")
    return "\n".join(rows)


def bakers_table() -> str:
    """Which method bakes what (the bakers' declarations), and why not where not."""
    heads = [a.label for a in abilities.ABILITIES]
    rows = ["| Method | Runs on | " + " | ".join(heads) + " |", "|---|---|" + "---|" * len(heads)]
    for baker in abilities.BAKERS:
        cells = ["yes" if baker.can(a.name) else "no" for a in abilities.ABILITIES]
        where = "GPU" if baker.gpu else "CPU (for checking)"
        rows.append(f"| `{baker.method}` | {where} | " + " | ".join(cells) + " |")
    notes = [f"- The {baker.label} cannot bake {a.phrase}: {baker.cannot[a.name]}."
             for baker in abilities.BAKERS for a in abilities.ABILITIES if not baker.can(a.name)]
    phrases = {a.name: a.phrase for a in abilities.ABILITIES}
    auto = [f"`{b.method}` when the bake needs {' and '.join(phrases[n] for n in sorted(b.auto_for))} and it can "
            "bake the rest"
            for b in abilities.BAKERS if b.gpu and b.auto_for]
    fallback = next(b.method for b in abilities.BAKERS if b.gpu and not b.auto_for)
    return "\n".join(rows + [""] + notes + ["", f"*Auto* picks {'; '.join(auto)}; otherwise `{fallback}`. "
                                          "A method that cannot bake what is asked is refused before any work, "
                                          "naming the methods that can."])


def render(readme: str) -> str:
    readme = _replace(readme, "bakers", bakers_table())
    for name, classes in TABLES.items():
        readme = _replace(readme, name, table(*classes))
    return readme


def _replace(readme: str, name: str, text: str) -> str:
    pattern = re.compile(rf"(<!-- settings:{re.escape(name)} -->\n)(?:.*?\n)?(<!-- /settings:{re.escape(name)} -->)",
                         re.S)
    if not pattern.search(readme):
        raise SystemExit(f"README.md has no <!-- settings:{name} --> block")
    return pattern.sub(lambda m: m.group(1) + text + "\n" + m.group(2), readme)


def main(argv: list[str]) -> int:
    path = ROOT / "README.md"
    current = path.read_text(encoding="utf-8")
    wanted = render(current)
    if "--check" in argv:
        if wanted != current:
            print("README.md setting tables are out of date: run python tools/readme_tables.py", file=sys.stderr)
            return 1
        return 0
    path.write_text(wanted, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
