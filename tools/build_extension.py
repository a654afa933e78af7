# SPDX-License-Identifier: GPL-3.0-or-later
"""Build the installable extension zip with Blender's own builder (shipped in the bpy wheel),
with the manual built into it (site/, tools/docs.sh): there is no public website, so the
extension carries its manual, opened from the add-on's preferences.

    python tools/build_extension.py [OUTPUT_DIR]      (default: dist/)
"""
import subprocess
import sys
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parent.parent


def builder_path() -> Path:
    return Path(bpy.utils.system_resource('SCRIPTS')) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"


def main() -> int:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "dist").resolve()
    out.mkdir(parents=True, exist_ok=True)  # the builder needs an existing folder
    manual = subprocess.run(["bash", str(ROOT / "tools" / "docs.sh")], capture_output=True, text=True)
    if manual.returncode != 0 or not (ROOT / "site" / "index.html").is_file():
        print(manual.stdout[-2000:] + manual.stderr[-2000:], file=sys.stderr)
        print("build_extension: the manual did not build (tools/docs.sh)", file=sys.stderr)
        return 1
    return subprocess.call([sys.executable, str(builder_path()), "build", "--source-dir", str(ROOT),
                            "--output-dir", str(out)])


if __name__ == "__main__":
    sys.exit(main())
