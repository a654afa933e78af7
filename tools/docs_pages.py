# SPDX-License-Identifier: GPL-3.0-or-later
"""The manual's generated pages, from their one source each:

    docs/settings.md       the setting definitions (core/setting_spec.py) and the bakers'
                           declared abilities (core/bake/abilities.py)
    docs/cli-reference.md  the command line's argparse definitions (hao_addon/cli/parser.py)
    docs/benchmarks.md     the latest run of each benchmark: bench/results/<name>.json, its
                           plot (copied to docs/benchmarks/) and the script's own description
    README.md              its numbers (between <!-- numbers --> and <!-- /numbers -->), one
                           sentence per benchmark, from the same results files

    python tools/docs_pages.py           # write them
    python tools/docs_pages.py --check   # exit 1 if any differs (the tests do this)

Earlier benchmark runs stay in bench/results/runs/ as JSON; the report shows the latest.
"""
from __future__ import annotations

import ast
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench"), str(ROOT / "tools")]
os.environ["COLUMNS"] = "100"  # argparse's help width: the same text on every terminal

from hao_addon.core.setting_spec import specs  # noqa: E402
from hao_addon.core.bake import abilities  # noqa: E402
from hao_addon.core.bake.job_options import JobOptions  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.hao.view_settings import RenderSize, ViewAOSettings  # noqa: E402
from bench_tables import results_tables  # noqa: E402

DOCS = ROOT / "docs"
RESULTS = ROOT / "bench" / "results"
TABLES = [("bake", "Bake settings", "The Bake AO panel, `bake`'s options and `BakeSettings`.", (BakeSettings,)),
          ("job", "Bake job options", "Which meshes occlude and how the outputs are laid out (`JobOptions`).",
           (JobOptions,)),
          ("view", "Viewport AO settings", "The Viewport AO panel and `render-ao`'s options (`ViewAOSettings`).",
           (ViewAOSettings,)),
          ("render-size", "Render size", "`render-ao`'s image size (`RenderSize`).", (RenderSize,))]
# Benchmarks in the report's order: (script stem, heading).
BENCHES = [("bake_bench", "Bake: time against error, beside Cycles"),
           ("error_bench", "A bake's own error estimate, and baking to an error"),
           ("floor_bench", "The error floor, against an independent truth"),
           ("cycles_error_bench", "Cycles' time to a stated error"),
           ("unwrap_bench", "Auto-unwrap"),
           ("hao_bench", "Viewport AO (HAO)"),
           ("spheres_bench", "Sphere proxies for animated characters"),
           ("farm_bench", "Farm tasks"),
           ("groups_bench", "Bake groups matched by name"),
           ("alpha_bench", "Alpha-aware occluders"),
           ("list_forms_bench", "Lists as textures or storage buffers (Blender 5.3)"),
           ("rebake_bench", "Re-bake Changed against a whole bake"),
           ("regression_bench", "Same-run regression check")]


def table(*settings_classes) -> str:
    rows = ["| Setting | Option | Default | Range | What it does |", "|---|---|---|---|---|"]
    for cls in settings_classes:
        for f, spec in specs(cls):
            option = f"`{spec.option(f.name) or spec.cli_via}`" if spec.option(f.name) or spec.cli_via else "(panel only)"
            label = spec.label if spec.ui else "(command line only)"
            default = f"`{f.default}`" if not isinstance(f.default, bool) else ("on" if f.default else "off")
            what = spec.sentence
            if spec.choices:
                what += ": " + "; ".join(f"*{c.label}* (`{c.value}`, Python `'{c.identifier}'`) {c.description}" for c in spec.choices)
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


def maps_table() -> str:
    """The maps a bake writes, from their rows (core/bake/map_kinds.py)."""
    from hao_addon.core.bake.map_kinds import MAP_KINDS
    rows = ["| Map | `--maps` | Command line | Panel | Channels | What it holds |", "|---|---|---|---|---|---|"]
    for kind in MAP_KINDS:
        rows.append(f"| {kind.noun.removeprefix('the ')} | `{kind.name}` | `{kind.flag}` | *{kind.panel_label}* | "
                    f"{kind.channels} | {kind.help} |")
    return "\n".join(rows)


def settings_page() -> str:
    parts = ["# Settings", "",
             "Generated by `tools/docs_pages.py` from the one definition of each setting "
             "(`hao_addon/core/setting_spec.py`): the Blender panels, the command-line options, "
             "validation and these tables all come from it.", ""]
    for anchor, title, intro, classes in TABLES:
        parts += [f"## {title} {{#{anchor}}}", "", intro, "", table(*classes), ""]
        if anchor == "bake":
            parts += ["## What each method bakes {#bakers}", "",
                      "Declared once, in `hao_addon/core/bake/abilities.py`: Auto's choice, the refusals, "
                      "this table and the tests' backend lists come from it.", "", bakers_table(), ""]
            parts += ["## The maps {#maps}", "",
                      "One row each in `hao_addon/core/bake/map_kinds.py`: the command line's file options and "
                      "`--maps`, the panel's file fields, the job's files and checks and the `--skip-existing` key "
                      "come from it. `--maps` writes each map beside `--out`, named after it with `_MAP`; the "
                      "panel's *Maps* sub-panel draws one block per row.", "", maps_table(), ""]
    return "\n".join(parts)


def cli_page() -> str:
    from hao_addon.cli.parser import build_parser
    parser = build_parser()
    parts = ["# Command-line reference", "",
             "Generated by `tools/docs_pages.py` from the argparse definitions "
             "(`hao_addon/cli/parser.py`; the bake options from the setting definitions). "
             "`python -m hao_addon COMMAND --help` prints the same. With Blender and the "
             "extension installed, `blender -b -c hao COMMAND ...` runs the same command line.", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    for name, sub in _subcommands(parser):
        parts += [f"## `{name}`", "", "```text", sub.format_help().rstrip(), "```", ""]
        for inner, subsub in _subcommands(sub):
            parts += [f"### `{name} {inner}`", "", "```text", subsub.format_help().rstrip(), "```", ""]
    return "\n".join(parts)


def _subcommands(parser):
    import argparse
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            yield from action.choices.items()


def bench_description(stem: str) -> str:
    """The benchmark script's module docstring, its usage line as a sentence."""
    doc = ast.get_docstring(ast.parse((ROOT / "bench" / f"{stem}.py").read_text())) or stem
    head, _, body = doc.partition("\n\n")
    lines = body.splitlines()
    usage = [line.strip() for line in lines if line.startswith("    ") and "bench/" in line]
    kept = [line for line in lines if not (line.startswith("    ") and "bench/" in line)]
    prose = "\n".join(("\n" + line) if line.startswith("- ") and k and kept[k - 1].strip()
                      and not kept[k - 1].startswith(("- ", "  ")) else line
                      for k, line in enumerate(kept)).strip()  # Markdown wants a blank line before a list
    return " ".join(head.split()) + "\n\n" + ("Run: `" + "`, `".join(usage) + "`.\n\n" if usage else "") + prose


def bench_section(stem: str, title: str) -> tuple[str, list[str]]:
    """A benchmark's section and the plots it shows."""
    description = bench_description(stem)
    data = json.loads((RESULTS / f"{stem}.json").read_text())
    parts = [f"## {title}", "", f"`bench/{stem}.py`, results `bench/results/{stem}.json`.", "", description, ""]
    plots = []
    if (RESULTS / f"{stem}.png").exists():
        plots.append(f"{stem}.png")
        parts += [f"[![{title}](benchmarks/{stem}.png)](benchmarks/{stem}.png)", ""]
    if stem in ("bake_bench", "hao_bench", "spheres_bench"):
        import report
        parts += [report.tables(data), ""]
    else:
        parts += results_tables(data)
    return "\n".join(parts), plots


def benchmarks_page() -> tuple[str, list[str]]:
    parts = ["# Benchmarks", "",
             "Generated by `tools/docs_pages.py` from the latest run of each benchmark "
             "(`bench/results/*.json`; earlier runs stay in `bench/results/runs/`). Every "
             "number comes from its results file; each benchmark compares its rows in one run "
             "on one machine (2 CPU cores, Mesa llvmpipe, no GPU unless its machine line says "
             "otherwise), as ratios, because timings on shared machines vary between runs.", "",
             "How to read the ratios: a *ratio* of times is the first-named time over the second "
             "(below 1: the first is faster); a *speed-up* is the other way round, the baseline's "
             "time over this row's (above 1: faster; below 1: slower, 0.85 is 15 % slower). Error "
             "ratios (*rmse ratio*, *p99 ratio*) are measured over stated: 1 is a stated error that "
             "holds. Each plot opens at full size when clicked.", ""]
    plots = []
    for stem, title in BENCHES:
        if (RESULTS / f"{stem}.json").exists():
            text, shown = bench_section(stem, title)
            parts.append(text)
            plots += shown
    return "\n".join(parts), plots


def _load(stem: str) -> dict:
    return json.loads((RESULTS / f"{stem}.json").read_text())


def readme_numbers() -> str:
    """The README's numbers: one sentence per benchmark, from its latest results file."""
    import report
    lines = []
    bake = _load("bake_bench")
    speedups = [r["seconds"] / t for m in bake["smooth"].values() for r in m["runs"]["cycles"]
                if (t := report.time_at_rmse(m["runs"]["gather"], r["rmse"])) is not None]
    lines.append(f"- **Bake against Cycles**: at equal error against Cycles' own bake, the gather is "
                 f"{min(speedups):.1f}-{max(speedups):.1f}x faster than Cycles' CPU AO bake on the smooth rocker arm "
                 f"and bunny at 1024², on {_cores(bake)} ([report](docs/benchmarks.md#bake-time-against-error-beside-cycles)).")
    rows = _load("floor_bench")["rows"]

    def span(method, meshes, shadings=("flat", "smooth")):
        ratios = [r["rmse_ratio"] for r in rows if r["method"] == method and r["mesh"] in meshes
                  and r["shading"] in shadings]
        return f"{min(ratios):.2f}-{max(ratios):.2f}"

    def everywhere():
        return all(abs(r[k] - 1.0) <= 0.25 for r in rows for k in ("rmse_ratio", "p99_ratio"))
    lines.append(f"- **A bake states its whole error**: direction noise plus the visibility floor it measures with "
                 f"exact rays at sampled texels; against an exact ray-traced truth (128², 64 to 16384 directions) "
                 f"the measured RMSE is {span('reference', ('spot', 'rocker-arm', 'stanford-bunny', 'fandisk'))} "
                 f"of the stated one for the reference, flat and smooth, "
                 f"{span('gather', ('spot', 'rocker-arm'))} for the gather on Spot and the rocker arm "
                 f"({span('gather', ('stanford-bunny', 'fandisk'))} on the bunny and fandisk), and "
                 f"{span('scatter', ('spot', 'rocker-arm', 'stanford-bunny', 'fandisk'))} for the scatter; "
                 f"{'within' if everywhere() else 'not yet within'} 25 % everywhere "
                 f"([report](docs/accuracy.md#a-bake-states-its-whole-error)).")
    hao = _load("hao_bench")
    ours = [row["hao"]["rmse"] for scene in hao["distances"].values() for row in scene["rows"]]
    eevee = [row["eevee"]["rmse"] for scene in hao["distances"].values() for row in scene["rows"] if "eevee" in row]
    lines.append(f"- **Viewport AO**: RMSE {min(ours):.3f}-{max(ours):.3f} against ray-traced AO of the same points "
                 f"at every distance on every benchmark scene (EEVEE's AO: {min(eevee):.3f}-{max(eevee):.2f}) "
                 f"([report](docs/benchmarks.md#viewport-ao-hao)).")
    unwrap = {(r["atlas"].split()[0], r["size"]): r for r in _load("unwrap_bench")["rows"]}
    new, old = unwrap[("HAO", 256)], unwrap[("xatlas", 256)]
    lines.append(f"- **Auto-unwrap**: the 69,451-triangle bunny without UVs unwraps in {new['seconds']:.1f} s at 256² "
                 f"(xatlas alone: {old['seconds']:.1f} s), covering {new['coverage']:.2f} of the texels "
                 f"(xatlas: {old['coverage']:.2f}), no overlaps ([report](docs/benchmarks.md#auto-unwrap)).")
    rebakes = _load("rebake_bench")
    rows = rebakes["rows"]
    repeats = rebakes.get("repeats", 1)
    largest, smaller = max(r["size"] for r in rows), min(r["size"] for r in rows)
    spans = ", ".join(f"{100 * r['rebaked_share']:.2g} % in {r['incremental_s']:.1f} s against {r['full_s']:.1f} s "
                      f"({r['speedup']:.1f}x)" for r in rows if r["size"] == largest)
    also = ", ".join(f"{r['speedup']:.1f}x at {100 * r['rebaked_share']:.2g} %" for r in rows
                     if r["size"] == smaller and smaller != largest)
    lines.append(f"- **Re-bake Changed**: after moving one ball of a scene, re-baking only the texels it can have "
                 f"changed at {largest}²: {spans}" + (f" (at {smaller}²: {also})" if also else "")
                 + (f" (medians of {repeats} runs)" if repeats > 1 else "") + "; "
                 f"{held(rows)} ([report](docs/benchmarks.md#re-bake-changed-against-a-whole-bake)).")
    farm = _load("farm_bench")
    lines.append(f"- **Farms**: {farm['inputs']} inputs as one farm task cost {farm['ratio_one_task_to_local_batch']:.2f}x "
                 f"one local batch; a bundle of {farm['bundle_inputs']:,} inputs is written in "
                 f"{farm['bundle_seconds']:.1f} s ([report](docs/benchmarks.md#farm-tasks)).")
    return "\n".join(lines)


# A re-bake by difference adds float32 sums: its texels may differ from a whole bake by this.
REBAKE_ROUNDING = 1e-6


def held(rows: list[dict]) -> str:
    """Whether every kept texel of the re-bake benchmark lay within its report's bound, and
    every re-baked one equal to a whole bake's (up to rounding)."""
    if all(r["kept_max_difference"] <= r["kept_bound"] + 1e-6 for r in rows):
        worst = max(r["rebaked_max_difference"] for r in rows)
        if worst == 0.0:
            return "every kept texel within the stated bound of a whole bake, every re-baked one equal to it"
        if worst <= REBAKE_ROUNDING:
            return (f"every kept texel within the stated bound of a whole bake, every re-baked one equal to it up to "
                    f"float rounding (at most {worst:.1e})")
    return "NOT every texel within the stated bound of a whole bake: see the report"


def _cores(result: dict) -> str:
    cores = result.get("machine", {}).get("cpu_count") if isinstance(result.get("machine"), dict) else None
    return f"{cores} CPU cores" if cores else "2 CPU cores, without a GPU"


def readme_with_numbers() -> bytes:
    import re
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    pattern = re.compile(r"(<!-- numbers -->\n)(?:.*?\n)?(<!-- /numbers -->)", re.S)
    if not pattern.search(readme):
        raise SystemExit("README.md has no <!-- numbers --> block")
    return pattern.sub(lambda m: m.group(1) + readme_numbers() + "\n" + m.group(2), readme).encode()


def wanted() -> dict[Path, bytes]:
    """Every generated file and its bytes."""
    files = {DOCS / "settings.md": settings_page().encode(), DOCS / "cli-reference.md": cli_page().encode(),
             ROOT / "README.md": readme_with_numbers()}
    text, plots = benchmarks_page()
    files[DOCS / "benchmarks.md"] = text.encode()
    for name in plots:
        files[DOCS / "benchmarks" / name] = (RESULTS / name).read_bytes()
    return files


def main(argv: list[str]) -> int:
    files = wanted()
    stale = [p for p, data in files.items() if not p.exists() or p.read_bytes() != data]
    if "--check" in argv:
        if stale:
            print("generated manual pages are out of date: run python tools/docs_pages.py\n  "
                  + "\n  ".join(str(p.relative_to(ROOT)) for p in stale), file=sys.stderr)
            return 1
        return 0
    for path in stale:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(files[path])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
