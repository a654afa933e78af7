# SPDX-License-Identifier: GPL-3.0-or-later
"""Build the installable extension zip with Blender's own builder, with only Python (3.11 or
newer) and this repository: tools/blender_ext.py is Blender's extension builder, copied
unchanged from the bpy 5.3.0 wheel (scripts/addons_core/bl_pkg/cli/blender_ext.py;
GPL-2.0-or-later, standard library only); tests/test_extension_and_cli.py checks that it is
the wheel's and that Blender's own validation accepts what it builds.

The manual goes in when it has been built (site/, by tools/docs.sh); without it the zip is
complete and its preferences say where the manual is built from.

    python tools/build_extension.py [OUTPUT_DIR]      (default: dist/)
"""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILDER = ROOT / "tools" / "blender_ext.py"


def main() -> int:
    if sys.version_info < (3, 11):
        print("build_extension: needs Python 3.11 or newer (tomllib)", file=sys.stderr)
        return 2
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "dist").resolve()
    out.mkdir(parents=True, exist_ok=True)  # the builder needs an existing folder
    if not (ROOT / "site" / "index.html").is_file():
        print("build_extension: the manual is not built (site/), so the zip goes without it; "
              "build it first with bash tools/docs.sh to include it", file=sys.stderr)
    return subprocess.call([sys.executable, str(BUILDER), "build", "--source-dir", str(ROOT),
                            "--output-dir", str(out)])


if __name__ == "__main__":
    sys.exit(main())
