# SPDX-License-Identifier: GPL-3.0-or-later
"""Draw the benchmarks' plots again from their latest results (bench/results/<name>.json),
without running them: for a change of layout or labels, not of numbers.

    .venv/bin/python bench/replot.py [NAME ...]      (default: every benchmark with a plot)
"""
from __future__ import annotations

import importlib
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
PLOTTED = ("bake_bench", "error_bench", "hao_bench", "spheres_bench", "unwrap_bench", "farm_bench", "groups_bench",
           "alpha_bench")


def main(names: list[str]) -> int:
    sys.path[:0] = [str(HERE), str(HERE.parent)]
    for name in names or PLOTTED:
        results = json.loads((RESULTS / f"{name}.json").read_text())
        importlib.import_module(name).plot(results, RESULTS / f"{name}.png")
        print(f"replot: {RESULTS / f'{name}.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
