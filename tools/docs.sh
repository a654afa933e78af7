#!/usr/bin/env bash
# Build the manual (docs/, MkDocs with the Material theme) into site/, strict: a broken link,
# a missing page or a generated page out of date (tools/docs_pages.py --check) fails it.
# Sets up .venv-docs (requirements/docs.txt) on the first run; the generated pages are
# checked with the default Blender environment (.venv, tools/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/bpy_releases.sh
# The default environment first: it installs the apt packages and finds the Python both use.
venv="$(bash tools/setup.sh | tail -n 1)"
py="$(find_python 3.13 2>/dev/null || command -v python3)"
if [ ! -x .venv-docs/bin/mkdocs ] || ! cmp -s requirements/docs.txt .venv-docs/.requirements.installed; then
  "$py" -m venv .venv-docs
  .venv-docs/bin/python -m pip install -q --disable-pip-version-check -r requirements/docs.txt
  cp requirements/docs.txt .venv-docs/.requirements.installed
fi
"$venv/bin/python" tools/docs_pages.py --check
NO_MKDOCS_2_WARNING=1 .venv-docs/bin/mkdocs build --strict --quiet
echo "manual: $(pwd)/site/index.html"
