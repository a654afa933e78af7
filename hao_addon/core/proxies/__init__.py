# SPDX-License-Identifier: GPL-3.0-or-later
"""Shanmugam & Arikan's sphere proxies: Lloyd clustering of the rest pose and per-frame sync,
the distant spheres' AO formulas, the image-space near-field mirror."""
