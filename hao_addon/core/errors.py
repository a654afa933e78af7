# SPDX-License-Identifier: GPL-3.0-or-later
"""Errors the core raises for input a user can fix (every interface reports them as one line)."""


class UserInputError(ValueError):
    """Input that cannot be used; the message says why in words a user can act on. Every
    interface catches this one class (the command line: exit 2; operators: one report)."""


class BakeInputError(UserInputError):
    """The input cannot be baked."""


class ViewInputError(UserInputError):
    """The scene or view cannot be rendered with viewport AO (HAO)."""


class GPUUnavailableError(RuntimeError):
    """Raised when no GPU context can be created (no EGL/OpenGL driver). Defined here, below
    the GPU module, so that the command line's error handler knows it without loading Blender."""
