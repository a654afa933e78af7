# SPDX-License-Identifier: GPL-3.0-or-later
"""The house's rules as tests: the floors' import contract (.importlinter, checked by
import-linter: each floor imports only those below it, the core neither bpy nor gpu, no import
cycle between sibling modules at any depth) and the linter (ruff.toml). Each check is shown
to catch the mistake it is for, on a copy of the package with that mistake put in."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT

BIN = Path(sys.executable).parent
pytestmark = pytest.mark.release_independent  # the same source on every release


def lint_imports(root: Path) -> subprocess.CompletedProcess:
    """lint-imports over the hao_addon package found under `root`, with the repository's contract."""
    return subprocess.run([str(BIN / "lint-imports"), "--config", str(ROOT / ".importlinter"), "--no-cache"],
                          capture_output=True, text=True, cwd=root, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(root)})


def package_copy(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "hao_addon", tmp_path / "hao_addon", ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path


def test_the_floors_import_contract_holds():
    done = lint_imports(ROOT)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "3 kept, 0 broken" in done.stdout


@pytest.mark.parametrize("module, line, broken", [
    ("core/geometry.py", "from ..blender import paths", "The floors"),  # the core climbs to Blender
    ("gpu/util.py", "from ..cli import errors", "The floors"),  # a pass imports the command line
    ("core/kernels.py", "import bpy", "The core imports neither bpy nor gpu"),
    ("core/components.py", "from . import geometry", "No import cycles"),  # geometry imports components
])
def test_the_contract_catches_an_import_against_it(tmp_path, module, line, broken):
    root = package_copy(tmp_path)
    path = root / "hao_addon" / module
    path.write_text(path.read_text(encoding="utf-8") + f"\n{line}  # put in by the test\n", encoding="utf-8")
    done = lint_imports(root)
    assert done.returncode != 0
    assert f"{broken}" in done.stdout.split("Broken contracts")[-1], done.stdout[-3000:]


def test_ruff_finds_nothing():
    done = subprocess.run([str(BIN / "ruff"), "check", "--no-cache", "."], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]


def test_ruff_catches_an_unused_import(tmp_path):
    (tmp_path / "ruff.toml").write_text((ROOT / "ruff.toml").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "bad.py").write_text("import os\n", encoding="utf-8")
    done = subprocess.run([str(BIN / "ruff"), "check", "--no-cache", "."], capture_output=True, text=True,
                          cwd=tmp_path, timeout=60)
    assert done.returncode == 1 and "F401" in done.stdout


def test_every_python_file_compiles():
    """What ruff's parser lets through and Python refuses (a name used before its `global`
    declaration kept bench/hao_bench.py from running at all): every file of the repository
    compiled as Python compiles it."""
    skipped = {"site", "wheels", "out", "dist"}
    files = [f for f in ROOT.rglob("*.py") if not {p for p in f.relative_to(ROOT).parts[:-1]} & skipped
             and not any(part.startswith(".") for part in f.relative_to(ROOT).parts)]
    assert len(files) > 100
    for path in files:
        compile(path.read_text(encoding="utf-8"), str(path), "exec")
    with pytest.raises(SyntaxError, match="used prior to global declaration"):
        compile("def f():\n    print(X)\n    global X\n", "planted.py", "exec")


MAX_FILE_LINES = 500
MAX_FUNCTION_LINES = 60


def oversized(paths) -> list[str]:
    """The files over MAX_FILE_LINES lines and the functions over MAX_FUNCTION_LINES among `paths`."""
    import ast
    found = []
    for path in paths:
        text = Path(path).read_text(encoding="utf-8")
        if len(text.splitlines()) > MAX_FILE_LINES:
            found.append(f"{path}: {len(text.splitlines())} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    found.append(f"{path}:{node.lineno} {node.name}: {length} lines")
    return found


def test_no_product_file_or_function_is_too_long_to_read(tmp_path):
    """Small modules with one job, functions short enough to read at once: no product file
    over 500 lines, no function over 60 (a 61-line function is caught)."""
    product = [*(ROOT / "hao_addon").rglob("*.py"), *(ROOT / "operators").rglob("*.py"), ROOT / "__init__.py"]
    assert oversized(product) == []
    long = tmp_path / "long.py"
    long.write_text("def f():\n" + "    x = 1\n" * 59 + "    return x\n", encoding="utf-8")
    assert oversized([long]) == [f"{long}:1 f: 61 lines"]


def kind_literals(paths) -> list[str]:
    """Where `paths` compare or spell a target kind or the Target setting's values as strings
    in code (docstrings and comments aside)."""
    import ast
    from hao_addon.core.bake.target_kinds import TARGET_KINDS
    kinds = set(TARGET_KINDS)
    targets = {kind.target for kind in TARGET_KINDS.values()}  # 'image' also names other things: compared
    found = []
    for path in paths:
        tree = ast.parse(Path(path).read_text(encoding="utf-8"))
        docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                      if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef)) and node.body
                      and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant)}
        compared = {id(c) for node in ast.walk(tree) if isinstance(node, ast.Compare)
                    for c in (node.left, *node.comparators)}
        compared |= {id(node.value) for node in ast.walk(tree) if isinstance(node, ast.keyword) and node.arg == "target"}
        found += [f"{path}:{node.lineno} {node.value!r}" for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and id(node) not in docstrings
                  and (node.value in kinds or (node.value in targets and id(node) in compared))]
    return found


def test_only_the_core_names_the_target_kinds(tmp_path):
    """Issue 40 item 3: the Blender layer, the GPU passes, the CLI and the operators read the
    kind's row (core/bake/target_kinds.py: writes_images, needs_uvs, its settings) and its
    plan's layout (core/bake/target_layouts.py), never its name or the Target's value as a
    string; a check like the ones they replaced is caught."""
    above = [p for folder in ("blender", "gpu", "cli") for p in (ROOT / "hao_addon" / folder).rglob("*.py")]
    above += [*(ROOT / "operators").rglob("*.py"), *(ROOT / "hao_addon").glob("*.py")]
    assert kind_literals(above) == []
    check = tmp_path / "check.py"
    check.write_text('def f(settings):\n    """color-attribute"""\n    return settings.target == "image"\n',
                     encoding="utf-8")
    assert kind_literals([check]) == [f"{check}:3 'image'"]
