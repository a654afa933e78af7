# SPDX-License-Identifier: GPL-3.0-or-later
"""HAO core: numpy math and CPU references (core/), GPU passes (gpu/), Blender data glue
shared by the operators and the command line (blender/). Imports nothing from operators/.

Relative imports only: this package is ``hao_addon`` when run as ``python -m hao_addon`` and
``bl_ext.<repo>.<id>.hao_addon`` inside the installed extension.
"""
__version__ = "0.1.0"
