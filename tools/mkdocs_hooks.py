# SPDX-License-Identifier: GPL-3.0-or-later
"""MkDocs hooks of the manual (mkdocs.yml: hooks). MkDocs writes the 404 page with links from
the site's root ('/assets/...', '/index.html'), right on a web server and broken from disk,
where the extension opens its manual; it lies in the root, so those links become relative."""
from __future__ import annotations

import re
from pathlib import Path

ROOT_LINK = re.compile(r'\b(href|src)="/(?!/)')  # not protocol-relative '//host' links
ROOT_BASE = '"base": "/"'  # Material's page config (search, navigation) on the root


def relative_404(html: str) -> str:
    """The 404 page's root links as links relative to the site's root folder."""
    return ROOT_LINK.sub(r'\1="', html).replace(ROOT_BASE, '"base": "."')


def on_post_build(config, **kwargs) -> None:
    page = Path(config["site_dir"]) / "404.html"
    if page.is_file():
        page.write_text(relative_404(page.read_text(encoding="utf-8")), encoding="utf-8")
