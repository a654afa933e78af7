# SPDX-License-Identifier: GPL-3.0-or-later
"""Command-line options made from the core's setting definitions (``core/setting_spec.py``):
the same names, defaults, ranges and descriptions as the panel and the README."""
from __future__ import annotations

import argparse

from ..core.setting_spec import Spec, specs


def option_help(field, spec: Spec) -> str:
    parts = [spec.description]
    if spec.choices:
        parts.append("; ".join(f"{c.value}: {c.description}" for c in spec.choices)
                     + f" (default {field.default})")
    elif not isinstance(field.default, bool):
        parts.append(f"{spec.range_text()}; default {field.default}")
    return (". ".join(parts)).replace("%", "%%")


def add_setting_options(parser: argparse.ArgumentParser, settings_cls) -> None:
    """One option per setting of the dataclass that is on the command line."""
    for f, spec in specs(settings_cls):
        option = spec.option(f.name)
        if option is None:
            continue
        help_text = option_help(f, spec)
        if isinstance(f.default, bool):
            parser.add_argument(option, dest=f.name, action="store_true", default=f.default, help=help_text)
        elif spec.choices:
            parser.add_argument(option, dest=f.name, choices=[c.value for c in spec.choices],
                                type=type(f.default), default=f.default, help=help_text)
        else:
            parser.add_argument(option, dest=f.name, type=type(f.default), default=f.default,
                                metavar=f.name.upper(), help=help_text)


def settings_from_args(args: argparse.Namespace, settings_cls):
    """The dataclass filled from parsed options (settings not on the command line keep their
    defaults); not validated here: the core validates once."""
    return settings_cls(**{f.name: getattr(args, f.name) for f, spec in specs(settings_cls)
                           if spec.option(f.name) is not None})


def option_for(settings_cls, field_name: str) -> str | None:
    """The option that sets a field (to name it in error messages)."""
    for f, spec in specs(settings_cls):
        if f.name == field_name:
            return spec.option(f.name)
    return None
