# SPDX-License-Identifier: GPL-3.0-or-later
"""``python -m hao_addon ...`` (see hao_addon.cli)."""
import sys

from .cli import main

sys.exit(main())
