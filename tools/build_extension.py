# SPDX-License-Identifier: GPL-3.0-or-later
"""Build the installable extension zip with Blender's own builder (shipped in the bpy wheel).

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
    return subprocess.call([sys.executable, str(builder_path()), "build", "--source-dir", str(ROOT),
                            "--output-dir", str(out)])


if __name__ == "__main__":
    sys.exit(main())
