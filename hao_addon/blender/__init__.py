# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender data glue shared by the operators and the command line (bpy, no GPU passes)."""
