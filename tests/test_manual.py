# SPDX-License-Identifier: GPL-3.0-or-later
"""The built manual (site/, tools/docs.sh: CI builds it before the tests) works where the
extension opens it, from disk with no network, and its benchmark report reads as tables.
The browser check (tools/check_manual.py) runs where Chromium is installed."""
from __future__ import annotations

import re
import struct
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tools"))
import check_manual  # noqa: E402
import mkdocs_hooks  # noqa: E402

SITE = ROOT / "site"
BENCHMARKS = (ROOT / "docs" / "benchmarks.md").read_text(encoding="utf-8")
PAGE_PLOT_PX = 1000  # about 1.4x the page's text column: labels keep about 3/4 of their size


@pytest.fixture(scope="module")
def site():
    assert (SITE / "index.html").is_file(), "the manual is not built: bash tools/docs.sh"
    return SITE


def test_search_index_and_scripts_work_from_disk(site):
    """The offline plugin's inlined index is there, and every script is the manual's own (the
    iframe-worker shim is carried, not loaded from its CDN)."""
    assert (site / "search" / "search_index.js").read_text(encoding="utf-8").startswith("var __index = ")
    assert check_manual.remote_scripts() == []
    assert 'src="assets/iframe-worker/shim.js"' in (site / "index.html").read_text(encoding="utf-8")
    assert (site / "assets" / "iframe-worker" / "shim.js").is_file()


def test_the_404_page_links_work_from_disk(site):
    page = (site / "404.html").read_text(encoding="utf-8")
    assert len(check_manual.LINK.findall(page)) > 10 and check_manual.broken_links(site / "404.html") == []
    assert '"base": "."' in page
    # What MkDocs writes without the hook is what breaks from disk.
    assert mkdocs_hooks.relative_404('<a href="/index.html"><link href="//cdn.x/y.css">') == \
        '<a href="index.html"><link href="//cdn.x/y.css">'


def _tables(markdown: str) -> list[list[list[str]]]:
    tables, rows = [], []
    for line in markdown.splitlines() + [""]:
        if line.startswith("|"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif rows:
            tables.append(rows)
            rows = []
    return [t for t in tables if len(t) > 1 and all(set(c) <= set("-:") and c for c in t[1])]


def test_the_benchmark_report_reads_as_tables():
    """No dotted key paths, no column empty on every row, no 'None', ratios explained, every
    plot linked to its full size and no wider than the page reads."""
    tables = _tables(BENCHMARKS)
    assert len(tables) > 20
    for table in tables:
        header, body = table[0], table[2:]
        for cell in header + [row[0] for row in body]:
            assert not re.search(r"\w\.\w+\.\w", cell) or re.search(r"\d\.\d", cell), cell
        for k, name in enumerate(header):
            assert name == "" or any(k < len(row) and row[k] for row in body), (name, header)
        assert not any("None" in row for row in body), header
    assert "How to read the ratios" in BENCHMARKS
    plots = re.findall(r"!\[[^\]]*\]\((benchmarks/[^)]+\.png)\)", BENCHMARKS)
    assert plots and all(f"]({p})]({p})" in BENCHMARKS for p in plots)
    for plot in plots:
        width = struct.unpack(">I", (ROOT / "docs" / plot).read_bytes()[16:20])[0]
        assert width <= PAGE_PLOT_PX, (plot, width)


@pytest.mark.release_independent
def test_the_manual_in_a_browser_from_disk(site, tmp_path):
    """Headless Chromium opens site/ from file:// with no network: the search lists results,
    the 404 page's links lead to files, and the three screenshots are written."""
    if check_manual.chromium() is None:
        pytest.skip("Chromium is not installed (Debian: apt install chromium); CI runs the static checks above")
    assert check_manual.main([str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["benchmarks.png", "index.png", "settings.png"]
