# SPDX-License-Identifier: GPL-3.0-or-later
"""Errors the core raises for input a user can fix (every interface reports them as one line)."""


class BakeInputError(ValueError):
    """The input cannot be baked or rendered; the message says why in words a user can act on."""
