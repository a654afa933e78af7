# SPDX-License-Identifier: GPL-3.0-or-later
"""What the README states about the code stays true: its snippet runs, its counts match."""
from __future__ import annotations

import re

import numpy as np

from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_core_api_snippet_runs_as_written(gpu_context, monkeypatch):
    block = re.search(r"blocking \(`execute`\)\. The core is also callable.*?```python\n(.*?)```", README, re.S)
    assert block, "README lost its core-API snippet"
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    exec(compile(block.group(1), "README.md", "exec"), namespace)  # noqa: S102 - our own README
    result = namespace["result"]
    assert result.ao.shape == (1024, 1024) and result.ao.dtype == np.float32 and "covered_texels" in result.stats
    assert namespace["per_vertex"].ao.shape == (len(namespace["v"]),)
    again = namespace["bake"](namespace["target"], namespace["occluders"], namespace["BakeSettings"](size=1024))
    assert again.stats["cache_hit"] and again.ao is result.ao  # "an identical call returns the cached result"


def test_bad_input_class_count_is_the_suite_s():
    import test_bad_input
    stated = int(re.search(r"`tests/test_bad_input\.py` tries (\d+) classes", README).group(1))
    operator_cases = sum(len(m.args[1]) for f in (test_bad_input.test_bake_operator_bad_input,
                                                  test_bad_input.test_render_operator_bad_input)
                         for m in f.pytestmark if m.name == "parametrize")
    assert stated == len(test_bad_input.CASES) + operator_cases
