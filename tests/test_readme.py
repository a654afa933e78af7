# SPDX-License-Identifier: GPL-3.0-or-later
"""What the README and the manual state about the code stays true: their snippets run, their
counts match, their links lead somewhere."""
from __future__ import annotations

import os
import re
import subprocess

import numpy as np
import pytest

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


@pytest.mark.release_independent  # it runs .venv's hao (the newest release) whichever suite runs it
def test_readme_command_line_runs_as_typed(tmp_path):
    """The README's command-line block, line by line as a newcomer types it (bash, in a folder
    holding the repository's .venv, samples and tests, after what tools/sample.sh made): every
    line exits 0, prints our own lines, and writes what it names."""
    block = re.search(r"## A first bake on the command line.*?```sh\n(.*?)```", README, re.S)
    assert block, "README lost its command-line block"
    lines = [line.split("  #")[0].strip() for line in block.group(1).splitlines() if line.strip()]
    assert lines and all(line.startswith(".venv/bin/hao ") for line in lines), lines
    for name in (".venv", "samples", "tests"):
        (tmp_path / name).symlink_to(ROOT / name)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    sample = [".venv/bin/python", "samples/make_scene.py", "out/spot_scene.blend"]  # as tools/sample.sh
    assert subprocess.run(sample, cwd=tmp_path, env=env, capture_output=True).returncode == 0
    for line in lines:
        proc = subprocess.run(["bash", "-c", line], cwd=tmp_path, env=env, capture_output=True, text=True,
                              timeout=600)
        assert proc.returncode == 0 and proc.stdout.strip(), (line, proc.stdout, proc.stderr)
        named = [w for w in line.split() if w.startswith("out/") and w != "out/spot_scene.blend"]
        for path in named:
            target = tmp_path / path
            assert (target.is_dir() and any(target.iterdir())) or target.stat().st_size > 0, (line, path)


def test_readme_pictures_read_on_light_and_dark_pages():
    """The README's pictures are opaque, and what lies around their subject (the corners) is a
    mid grey: a white map or a white cow on a transparent or white background is a faint smudge
    on a light page (GitHub's default), and a black one vanishes on a dark page."""
    import matplotlib.image as mpimg

    pictures = re.findall(r"!\[[^\]]*\]\((docs/images/[^)]+\.png)\)", README)
    assert len(pictures) >= 2, pictures
    for picture in pictures:
        pixels = mpimg.imread(ROOT / picture)
        assert pixels.ndim == 3 and (pixels.shape[2] == 3 or pixels[..., 3].min() == 1.0), picture
        corners = pixels[[0, 0, -1, -1], [0, -1, 0, -1], :3] if "viewport" not in picture else pixels[[0, 0], [0, -1], :3]
        assert np.all((corners > 0.25) & (corners < 0.65)), (picture, corners)
