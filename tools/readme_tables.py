# SPDX-License-Identifier: GPL-3.0-or-later
"""The README's setting tables, made from the settings' one definition (core/setting_spec.py).

    python tools/readme_tables.py           # rewrite the tables in README.md
    python tools/readme_tables.py --check   # exit 1 if README.md differs (the tests do this)

A table sits between ``<!-- settings:NAME -->`` and ``<!-- /settings:NAME -->``.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from hao_addon.core.setting_spec import specs  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.hao.view_settings import RenderSize, ViewAOSettings  # noqa: E402

TABLES = {"bake": (BakeSettings,), "view": (ViewAOSettings,), "render-size": (RenderSize,)}


def table(*settings_classes) -> str:
    rows = ["| Setting | Option | Default | Range | What it does |", "|---|---|---|---|---|"]
    for cls in settings_classes:
        for f, spec in specs(cls):
            option = f"`{spec.option(f.name) or spec.cli_via}`" if spec.option(f.name) or spec.cli_via else "(panel only)"
            label = spec.label if spec.ui else "(command line only)"
            default = f"`{f.default}`" if not isinstance(f.default, bool) else ("on" if f.default else "off")
            what = spec.sentence
            if spec.choices:
                what += ": " + "; ".join(f"*{c.label}* (`{c.value}`) {c.description}" for c in spec.choices)
            rows.append(f"| {label} | {option} | {default} | {spec.range_text() or '-'} | {what}. |")
    return "\n".join(rows)


def render(readme: str) -> str:
    for name, classes in TABLES.items():
        pattern = re.compile(rf"(<!-- settings:{re.escape(name)} -->\n)(?:.*?\n)?(<!-- /settings:{re.escape(name)} -->)",
                             re.S)
        if not pattern.search(readme):
            raise SystemExit(f"README.md has no <!-- settings:{name} --> block")
        readme = pattern.sub(lambda m: m.group(1) + table(*classes) + "\n" + m.group(2), readme)
    return readme


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
