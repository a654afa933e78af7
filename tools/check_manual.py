# SPDX-License-Identifier: GPL-3.0-or-later
"""Open the built manual (site/, tools/docs.sh) from disk in headless Chromium, as the
extension opens it, with no network: its search finds pages, the 404 page's links lead to
files, no page loads a script from elsewhere; screenshots of the home, settings and benchmarks
pages for a person to look at.

    python tools/check_manual.py [SCREENSHOT_DIR]     (default: out/manual/; Debian: apt install chromium)

Prints one line per check; exits 1 if any fails, 2 without Chromium or a built manual.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SITE = ROOT / "site"
SEARCH_WORD = "occluders"  # in several pages: a search that finds nothing is a broken search
SCREENSHOTS = ("index", "settings", "benchmarks")
# As root, with a fresh profile, and without the background connections a closed network refuses.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync", "--hide-scrollbars"]
LINK = re.compile(r'\b(?:href|src)="([^"#?]*)[^"]*"')


def chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


def browse(browser: str, url: str, *extra: str) -> str:
    """The page's DOM after its scripts ran (a virtual 8 s), or '' for a screenshot."""
    with tempfile.TemporaryDirectory() as profile:
        proc = subprocess.run([browser, *FLAGS, f"--user-data-dir={profile}", "--virtual-time-budget=8000", *extra,
                               url], capture_output=True, text=True, timeout=120)
    return proc.stdout


def search_results(browser: str) -> int:
    """How many results the manual's own search lists for SEARCH_WORD, opened from disk."""
    dom = browse(browser, (SITE / "index.html").as_uri() + f"?q={SEARCH_WORD}", "--dump-dom")
    return dom.count('class="md-search-result__item"')


def broken_links(page: Path) -> list[str]:
    """The page's local links (href, src) that lead to no file."""
    html = page.read_text(encoding="utf-8")
    return [link for link in LINK.findall(html) if link and not re.match(r"[a-z]+:|//", link)
            and not (page.parent / link).exists()]


def remote_scripts() -> list[str]:
    """Scripts any page loads from elsewhere (a manual opened offline cannot)."""
    return sorted({f"{page.name}: {src}" for page in SITE.glob("*.html")
                   for src in re.findall(r'<script[^>]*\bsrc="((?:https?:)?//[^"]+)"', page.read_text(encoding="utf-8"))})


def main(argv: list[str]) -> int:
    browser = chromium()
    if browser is None or not (SITE / "index.html").is_file():
        print("check_manual: needs Chromium (Debian: apt install chromium) and the built manual (bash tools/docs.sh)",
              file=sys.stderr)
        return 2
    shots = Path(argv[0] if argv else ROOT / "out" / "manual")
    shots.mkdir(parents=True, exist_ok=True)
    found = search_results(browser)
    broken = broken_links(SITE / "404.html")
    remote = remote_scripts()
    checks = [(found > 0, f"search from disk: {found} results for '{SEARCH_WORD}'"),
              (not broken, f"404 page: {len(broken)} broken links {broken[:5]}"),
              (not remote, f"scripts from elsewhere: {remote[:5]}")]
    for name in SCREENSHOTS:
        path = shots / f"{name}.png"
        browse(browser, (SITE / f"{name}.html").as_uri(), f"--screenshot={path}", "--window-size=1280,1600")
        checks.append((path.is_file() and path.stat().st_size > 10000, f"screenshot: {path}"))
    for ok, line in checks:
        print(("ok    " if ok else "FAIL  ") + line)
    return 0 if all(ok for ok, _ in checks) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
