# SPDX-License-Identifier: GPL-3.0-or-later
"""GPU passes. Each pass owns its shaders and resources and frees them deterministically.
The bake passes are chosen through hao_addon.bakers.baker_for."""
