# SPDX-License-Identifier: GPL-3.0-or-later
"""Render-farm jobs of bakes, in the job systems' own formats (pure Python, no bpy): the
manifest of a job's inputs and chunks, and the job descriptions built on it (Open Job
Description bundles, Flamenco job types, OpenCue command files). Every farm task runs the
same ``bake`` command line a workstation runs (task_args)."""
