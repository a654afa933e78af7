# SPDX-License-Identifier: GPL-3.0-or-later
"""Pure math and CPU references: numpy (and mathutils for BVH ray casts), never bpy or gpu."""
