# SPDX-License-Identifier: GPL-3.0-or-later
"""One definition per setting: a dataclass field carries its default and a ``Spec`` (label,
description, range, unit, choices). The Blender properties (``operators/setting_props.py``),
the command-line options (``hao_addon/cli/options.py``) and the manual's settings page
(``tools/docs_pages.py``) are generated from it, and ``validate`` is the only range check.
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from typing import Any, Iterator

from .errors import UserInputError


@dataclass(frozen=True)
class Choice:
    """One allowed value: a word (a mode) or a number (a count). Reports and the command
    line use the value as it is; a Blender enum its UPPER_CASE str() (operators/setting_props.py)."""

    value: str | int
    label: str
    description: str

    @property
    def identifier(self) -> str:
        """Its identifier in a Blender enum: UPPER_CASE, as in all of Blender's Python API
        ('color-attribute' -> 'COLOR_ATTRIBUTE', 'near+far' -> 'NEAR_FAR'; '16' stays)."""
        return re.sub(r"[^A-Z0-9]+", "_", str(self.value).upper())


@dataclass(frozen=True)
class Spec:
    """label: UI name. description: tooltip, --help and README text. noun: how messages name
    it (default: the label in lower case). minimum/maximum: inclusive bounds (None: open);
    above_minimum: the minimum itself is excluded. soft_max: the UI slider's end. unit: shown
    in messages and tables. subtype: Blender's property subtype. cli: the option name ('' =
    --field-name, None = not on the command line). cli_via: with cli None, the command-line
    option that turns the setting on (documented, not generated). ui: has a Blender property."""

    label: str
    description: str
    noun: str = ""
    minimum: float | None = None
    maximum: float | None = None
    above_minimum: bool = False
    soft_max: float | None = None
    unit: str = ""
    choices: tuple[Choice, ...] = ()
    subtype: str = ""
    cli: str | None = ""
    cli_via: str = ""
    ui: bool = True

    @property
    def sentence(self) -> str:
        """The description as a tooltip or table cell starts: capitalized."""
        return self.description[:1].upper() + self.description[1:]

    @property
    def message_name(self) -> str:
        return self.noun or self.label.lower()

    def option(self, name: str) -> str | None:
        if self.cli is None:
            return None
        return self.cli or "--" + name.replace("_", "-")

    def range_text(self) -> str:
        """'16 to 16384 texels', '> 0', 'none, wendland' ..."""
        if self.choices:
            return ", ".join(str(c.value) for c in self.choices)
        unit = f" {self.unit}" if self.unit else ""
        low, high = self.minimum, self.maximum
        if low is not None and high is not None:
            return f"{_fmt(low)} to {_fmt(high)}{unit}" if not self.above_minimum else f"> {_fmt(low)}, <= {_fmt(high)}{unit}"
        if low is not None:
            return f"{'>' if self.above_minimum else '>='} {_fmt(low)}{unit}"
        return ""


def _fmt(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


class SettingError(UserInputError):
    """A setting is out of range or of the wrong kind; ``name`` is the dataclass field."""

    def __init__(self, name: str, message: str) -> None:
        super().__init__(message)
        self.name = name


def setting(default: Any, **spec: Any) -> Any:
    """A dataclass field with its Spec (see Spec for the keywords)."""
    return field(default=default, metadata={"spec": Spec(**spec)})


def specs(cls_or_obj) -> Iterator[tuple[dataclasses.Field, Spec]]:
    """(field, spec) of every setting of a settings dataclass, in declaration order."""
    for f in dataclasses.fields(cls_or_obj):
        if "spec" in f.metadata:
            yield f, f.metadata["spec"]


def _kind(f: dataclasses.Field) -> str:
    """'int', 'float', 'bool' or 'str' from the default's type (annotations are strings)."""
    return type(f.default).__name__


def check_value(f: dataclasses.Field, spec: Spec, value: Any) -> None:
    """Raise SettingError unless value is of the field's kind and in its range."""
    kind, name = _kind(f), spec.message_name
    if kind == "bool":
        ok = isinstance(value, bool)
    elif kind == "int":
        ok = isinstance(value, int) and not isinstance(value, bool)
    elif kind == "float":
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    else:
        ok = isinstance(value, str)
    if not ok:
        raise SettingError(f.name, f"{name} must be a finite {'number' if kind == 'float' else kind}, got {value!r}")
    if spec.choices and value not in {c.value for c in spec.choices}:
        raise SettingError(f.name, f"{name} must be one of {spec.range_text()}, got '{value}'")
    low, high = spec.minimum, spec.maximum
    below = low is not None and (value <= low if spec.above_minimum else value < low)
    if below or (high is not None and value > high):
        raise SettingError(f.name, f"{name} must be {_range_words(spec)}, got {value}")


def _range_words(spec: Spec) -> str:
    unit = f" {spec.unit}" if spec.unit else ""
    low, high = spec.minimum, spec.maximum
    if low is not None and high is not None and not spec.above_minimum:
        return f"between {_fmt(low)} and {_fmt(high)}{unit}"
    parts = []
    if low is not None:
        parts.append(f"{'above' if spec.above_minimum else 'at least'} {_fmt(low)}")
    if high is not None:
        parts.append(f"at most {_fmt(high)}")
    return " and ".join(parts) + unit


def validate(obj) -> None:
    """Check every setting of a settings dataclass instance (first failure raised)."""
    for f, spec in specs(obj):
        check_value(f, spec, getattr(obj, f.name))
