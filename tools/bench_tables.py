# SPDX-License-Identifier: GPL-3.0-or-later
"""A benchmark's results file (bench/results/<name>.json) as tables a person reads, for the
manual's benchmark report (tools/docs_pages.py): keys in words, not dotted paths; one row per
record of a list, one column per member of a family (the meshes of a benchmark); columns and
rows that are empty everywhere left out; the set-up as a short list."""
from __future__ import annotations

FAMILY_MIN = 2  # a dict of at least this many dicts is a family: its members become columns


# Keys whose plain words would mislead or stay cryptic.
WORDS = {"vs_cycles": "against Cycles", "vs_converged": "against converged", "p99_noise_out": "p99, truth's noise out",
         "with_estimate_s": "with estimate (s)", "one_set_s": "one set (s)", "seconds": "seconds", "rmse": "RMSE",
         "speedup_vs_smallest_fixed": "speed-up vs smallest fixed count",
         "speedup_from_skipping": "speed-up from skipping"}


def words(key: str) -> str:
    """A JSON key as words: 'p99_noise_out' -> "p99, truth's noise out", 'floor_texels' ->
    'floor texels'."""
    return WORDS.get(str(key), str(key).replace("_", " "))


def fmt(value) -> str:
    """A value for a table cell: floats to 4 significant digits, lists joined, None empty."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        shown = ", ".join(fmt(v) for v in value[:12])
        return shown + (" ..." if len(value) > 12 else "")
    return str(value).replace("|", "/")


def _is_records(value) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _is_family(value) -> bool:
    return (isinstance(value, dict) and len(value) >= FAMILY_MIN
            and all(isinstance(v, dict) for v in value.values()))


def leaves(value: dict, path: tuple = ()) -> list[tuple[tuple, object]]:
    """(key path, value) of every value inside nested dicts that is not a dict (record lists
    included, as they are)."""
    out = []
    for key, item in value.items():
        if isinstance(item, dict) and item:
            out += leaves(item, path + (key,))
        else:
            out.append((path + (key,), item))
    return out


def label(path: tuple) -> str:
    """A key path as a row or column name: 'to error: vs converged p99'."""
    head, rest = words(path[0]), " ".join(words(k) for k in path[1:])
    return f"{head}: {rest}" if rest else head


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)] + ["| " + " | ".join(r) + " |" for r in rows]


def records_table(records: list[dict]) -> list[str]:
    """One row per record, one column per (nested) key that some record fills."""
    flat = [dict((path, v) for path, v in leaves(r) if not _is_records(v)) for r in records]
    keys = [k for k in dict.fromkeys(k for r in flat for k in r) if any(fmt(r.get(k)) for r in flat)]
    return _table([label(k) for k in keys], [[fmt(r.get(k)) for k in keys] for r in flat])


def family_tables(name: str, family: dict) -> list[str]:
    """A family's values side by side, a column per member; its members' record lists as
    tables of their own."""
    members = list(family)
    per_member = {m: leaves(family[m]) for m in members}
    paths = list(dict.fromkeys(p for m in members for p, v in per_member[m] if not _is_records(v)))
    values = {m: dict(per_member[m]) for m in members}
    rows = [[label(p)] + [fmt(values[m].get(p)) for m in members] for p in paths
            if any(fmt(values[m].get(p)) for m in members)]
    out = [f"**{words(name)}**", ""] + _table([""] + [words(m) for m in members], rows) + [""]
    for m in members:
        for path, value in per_member[m]:
            if _is_records(value):
                out += [f"**{words(m)}: {label(path)}**", ""] + records_table(value) + [""]
    return out


def _machine(value) -> str:
    if isinstance(value, dict):
        return ", ".join(f"{words(k)} {fmt(v)}" for k, v in value.items())
    return fmt(value)


def results_tables(data: dict, heading: str = "") -> list[str]:
    """The Markdown of a results file (or a part of one under heading): its set-up as a list,
    then its record lists, families and other groups as tables."""
    out = [f"**{heading}**", ""] if heading else []
    setup = [(k, v) for k, v in data.items() if not isinstance(v, dict) and not _is_records(v)]
    if setup:
        out += [f"- {words(k)}: {_machine(v) if k == 'machine' else fmt(v)}" for k, v in setup] + [""]
    for key, value in data.items():
        if key == "machine" and isinstance(value, dict):
            out += [f"- machine: {_machine(value)}", ""]
        elif _is_records(value):
            out += [f"**{words(key)}**", ""] + records_table(value) + [""]
        elif _is_family(value):
            out += family_tables(key, value)
        elif isinstance(value, dict) and value and all(not isinstance(v, dict) for v in value.values()):
            out += [f"**{words(key)}**", ""] + _table(["", "value"], [[words(k), fmt(v)] for k, v in value.items()
                                                                        if fmt(v)]) + [""]
        elif isinstance(value, dict) and value:
            out += results_tables(value, f"{heading}: {words(key)}" if heading else words(key))
    return out
