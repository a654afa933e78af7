# SPDX-License-Identifier: GPL-3.0-or-later
"""``python -m hao_addon ...`` (see hao_addon.cli)."""
import os
import signal


def _stop_during_startup(signum, frame):
    # Nothing exists yet (no bpy, no file, no temporary folder): say so and end.
    word = "interrupted" if signum == signal.SIGINT else "terminated"
    os.write(2, f"hao: error: {word} ({signal.Signals(signum).name}): nothing was written\n".encode())
    os._exit(130 if signum == signal.SIGINT else 143)


# First, before the imports: main() installs its own handlers and restores these after.
signal.signal(signal.SIGINT, _stop_during_startup)
signal.signal(signal.SIGTERM, _stop_during_startup)

from .cli import main  # noqa: E402
from .cli.io import exit_process  # noqa: E402

exit_process(main())
