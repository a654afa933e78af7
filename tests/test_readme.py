# SPDX-License-Identifier: GPL-3.0-or-later
"""What the README and the manual state about the code stays true: their snippets run, their
counts match, their links lead somewhere."""
from __future__ import annotations

import re

import numpy as np

from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")
BAKING_PAGE = (ROOT / "docs" / "baking-in-blender.md").read_text(encoding="utf-8")
COMMAND_LINE_PAGE = (ROOT / "docs" / "command-line.md").read_text(encoding="utf-8")


def test_readme_first_bake_from_python_runs_as_written(gpu_context, monkeypatch, capsys):
    block = re.search(r"## A first bake from Python.*?```python\n(.*?)```", README, re.S)
    assert block, "README lost its Python snippet"
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    exec(compile(block.group(1), "README.md", "exec"), namespace)  # noqa: S102 - our own README
    assert namespace["result"].ao.shape == (512, 512)
    assert capsys.readouterr().out.startswith("(512, 512) ")


def heading_slugs(text: str) -> set[str]:
    """The anchors a Markdown page's headings (and explicit {#ids}) give, as MkDocs and GitHub make them."""
    slugs = {re.sub(r"[^a-z0-9 -]", "", h.lower()).strip().replace(" ", "-")
             for h in re.findall(r"^#+ (.*?)(?: \{#.*\})?$", text, re.M)}
    return slugs | set(re.findall(r"\{#([a-z0-9-]+)\}", text))


def test_readme_links_lead_to_files_and_headings():
    """Every relative link and picture of the README (a file, a folder, or a heading of a page
    or of the README itself) leads somewhere; a README whose links this stops finding fails too."""
    links = [t for t in re.findall(r"\]\(([^)\s]+)\)", README) if not re.match(r"[a-z]+:", t)]
    assert len(links) >= 10, links  # the README links the manual's pages and its pictures
    for link in links:
        target, _, anchor = link.partition("#")
        if target:
            assert (ROOT / target).exists(), link
        if anchor:
            page = (ROOT / target).read_text(encoding="utf-8") if target else README
            assert target == "" or target.endswith(".md"), link
            assert anchor in heading_slugs(page), link


def test_core_api_snippet_runs_as_written(gpu_context, monkeypatch):
    block = re.search(r"blocking \(`execute`\)\. The core is also callable.*?```python\n(.*?)```", BAKING_PAGE, re.S)
    assert block, "the manual lost its core-API snippet"
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    exec(compile(block.group(1), "baking-in-blender.md", "exec"), namespace)  # noqa: S102 - our own manual
    result = namespace["result"]
    assert result.ao.shape == (1024, 1024) and result.ao.dtype == np.float32 and "covered_texels" in result.stats
    assert namespace["per_vertex"].ao.shape == (len(namespace["v"]),)
    again = namespace["bake"](namespace["target"], namespace["occluders"], namespace["BakeSettings"](size=1024))
    assert again.stats["cache_hit"] and again.ao is result.ao  # "an identical call returns the cached result"


def test_bad_input_class_count_is_the_suite_s():
    import test_bad_input
    stated = int(re.search(r"`tests/test_bad_input\.py` tries (\d+) classes", COMMAND_LINE_PAGE).group(1))
    operator_cases = sum(len(m.args[1]) for f in (test_bad_input.test_bake_operator_bad_input,
                                                  test_bad_input.test_render_operator_bad_input)
                         for m in f.pytestmark if m.name == "parametrize")
    assert stated == len(test_bad_input.CASES) + operator_cases
    accepted = int(re.search(r"and (\d+) classes of odd but valid input", COMMAND_LINE_PAGE).group(1))
    assert accepted == len(test_bad_input.ACCEPTED)
