# SPDX-License-Identifier: GPL-3.0-or-later
"""The texture bake's math (McGraw & Sowers): settings, the plan, receivers and the
high-to-low projection, directions' light views, normalization, normal bins and face chunks
for the gather, UV raster and checks, seam repair, the automatic unwrap, the CPU twin baker."""
