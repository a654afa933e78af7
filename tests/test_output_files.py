# SPDX-License-Identifier: GPL-3.0-or-later
"""The numpy floor of issue 28 (no bpy): the one collision check of a run's files, writes
that are all or none, byte sizes in words, the warning for zero-area UV triangles, and the
float32 bound of a cage extrusion."""
from __future__ import annotations

import os

import numpy as np
import pytest

from hao_addon.core.bake.projection import EXTRUSION_RESOLUTION, FLOAT32_SPACING, HighToLow, max_extrusion
from hao_addon.core.bake.uv_checks import uv_layout_warnings
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.folders import unmakeable_reason
from hao_addon.core.imageio import StagedFiles, atomic_write_bytes, byte_size
from hao_addon.core.output_files import OutputCollision, check_output_files


def test_two_outputs_on_one_file_are_refused_naming_both(tmp_path):
    with pytest.raises(OutputCollision, match="the map of 'a' and the map of 'b' would both be written to") as err:
        check_output_files([(str(tmp_path / "x.png"), "the map of 'a'"), (str(tmp_path / "x.png"), "the map of 'b'")])
    assert err.value.parties == ("the map of 'a'", "the map of 'b'")


@pytest.mark.parametrize("spelling", ["X.PNG", "sub/../x.png", "./x.png", "link.png"])
def test_one_file_under_other_spellings_is_one_file(tmp_path, spelling):
    """Case (macOS's and Windows' file systems), '..', '.', and a link to it."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "x.png").write_bytes(b"")
    os.symlink(tmp_path / "x.png", tmp_path / "link.png")
    with pytest.raises(OutputCollision, match="would both be written to"):
        check_output_files([(str(tmp_path / "x.png"), "one"), (os.path.join(tmp_path, spelling), "two")])


def test_an_output_on_an_input_is_refused_and_distinct_files_pass(tmp_path):
    inputs = [(str(tmp_path / "in.obj"), "the input file")]
    with pytest.raises(OutputCollision, match=r"the report \(--json\) would overwrite the input file"):
        check_output_files([(str(tmp_path / "IN.obj"), "the report (--json)")], inputs)
    outputs = [(str(tmp_path / f"{k:04d}.png"), f"frame {k}") for k in range(10_000)] + [("", "none"), ("-", "stdout")]
    assert check_output_files(outputs, inputs) == 10_000


def test_staged_files_are_all_or_none(tmp_path):
    (tmp_path / "old.png").write_bytes(b"earlier")
    staged = StagedFiles()
    staged.write_bytes(tmp_path / "old.png", b"new")
    staged.write_bytes(tmp_path / "new.png", b"new")
    assert sorted(os.listdir(tmp_path)) != ["new.png", "old.png"]  # staged under temporary names only
    assert (tmp_path / "old.png").read_bytes() == b"earlier" and not (tmp_path / "new.png").exists()
    staged.commit()
    assert (tmp_path / "old.png").read_bytes() == b"new" and (tmp_path / "new.png").read_bytes() == b"new"
    staged.rollback()  # what it replaced comes back, what it added goes
    assert sorted(os.listdir(tmp_path)) == ["old.png"] and (tmp_path / "old.png").read_bytes() == b"earlier"
    staged = StagedFiles()
    staged.write_bytes(tmp_path / "old.png", b"new")
    staged.commit()
    staged.release()
    assert sorted(os.listdir(tmp_path)) == ["old.png"] and (tmp_path / "old.png").read_bytes() == b"new"


def test_a_failed_write_leaves_nothing(tmp_path):
    staged = StagedFiles()
    staged.write_bytes(tmp_path / "a.png", b"a")
    with pytest.raises(ValueError, match="NaN"):
        staged.write_image(tmp_path / "b.png", np.full((4, 4), np.nan))
    (tmp_path / "file").write_bytes(b"")
    with pytest.raises(OSError):
        staged.write_bytes(tmp_path / "file" / "c.png", b"c")
    staged.write_bytes(tmp_path / "made" / "deeper" / "d.png", b"d")  # its folders are made...
    assert (tmp_path / "made" / "deeper").is_dir()
    staged.discard()
    assert os.listdir(tmp_path) == ["file"]  # ...and removed with the staged files


def test_missing_folders_are_made_for_the_files_and_kept_with_them(tmp_path):
    staged = StagedFiles()
    staged.write_bytes(tmp_path / "a" / "b" / "x.png", b"x")
    staged.commit()
    staged.rollback()  # the folders go with the file they were made for
    assert os.listdir(tmp_path) == []
    staged = StagedFiles()
    staged.write_bytes(tmp_path / "a" / "b" / "x.png", b"x")
    staged.commit()
    staged.release()
    assert (tmp_path / "a" / "b" / "x.png").read_bytes() == b"x"
    atomic_write_bytes(tmp_path / "c" / "r.json", b"{}")
    assert (tmp_path / "c" / "r.json").read_bytes() == b"{}"


@pytest.mark.parametrize("where, reason", [("a/b", None), ("f/b", "'{tmp}/f' is a file, not a folder"),
                                           ("locked/b", "permission denied in '{tmp}/locked'")])
def test_only_a_folder_that_cannot_be_made_is_refused(tmp_path, where, reason):
    (tmp_path / "f").write_bytes(b"")
    (tmp_path / "locked").mkdir(mode=0o500)
    if reason and "permission" in reason and os.access(tmp_path / "locked", os.W_OK):
        pytest.skip("running as root: every folder is writable")
    assert unmakeable_reason(tmp_path / where) == (reason and reason.format(tmp=tmp_path))
    assert not (tmp_path / where).exists()  # checked, not made


@pytest.mark.parametrize("count, text", [(0, "0 bytes"), (1023, "1023 bytes"), (1024, "1.0 KiB"),
                                         (40 * 1024, "40.0 KiB"), (int(2.5 * 2**20), "2.5 MiB"),
                                         (3 * 2**30, "3.0 GiB"), (5 * 2**50, "5120.0 TiB")])
def test_byte_sizes_in_the_largest_unit_that_keeps_them_at_one_or_more(count, text):
    assert byte_size(count) == text


def grid_uvs(n: int) -> np.ndarray:
    """(2 n^2, 3, 2) a regular grid's triangles over 0..1."""
    tris = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = (i / n, j / n), ((i + 1) / n, j / n), (i / n, (j + 1) / n), ((i + 1) / n, (j + 1) / n)
            tris += [(a, b, c), (b, d, c)]
    return np.array(tris, np.float64)


def test_zero_area_uv_triangles_are_warned_about_above_one_percent():
    uvs = grid_uvs(10)  # 200 triangles
    assert uv_layout_warnings(uvs, 64, "m")[1]["uv_triangles_zero_area"] == 0
    collapsed = uvs.copy()
    collapsed[:2] = collapsed[:2, :1]  # 2 of 200: 1 %, not above it
    warnings, counts = uv_layout_warnings(collapsed, 64, "m")
    assert counts["uv_triangles_zero_area"] == 2 and not any("zero area" in w for w in warnings)
    collapsed[:150, :, 1] = 0.5  # most, flattened onto a line
    warnings, counts = uv_layout_warnings(collapsed, 64, "m")
    assert counts["uv_triangles_zero_area"] == 150
    assert "'m': 150 of 200 UV triangles have zero area in the UV map" in " ".join(warnings)


def test_the_largest_extrusion_is_where_float32_resolves_the_meshs_detail():
    """At the bound, float32's spacing at the ray start is EXTRUSION_RESOLUTION of the mesh's
    size; the bound scales with the mesh and shrinks with the object's scale."""
    tri = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]], np.float64)
    size = np.linalg.norm([2, 2, 0])
    limit = max_extrusion(TriangleSoup(tri, None, name="t"), HighToLow([]))
    assert (limit + 2.0) * FLOAT32_SPACING == pytest.approx(size * EXTRUSION_RESOLUTION)
    assert np.spacing(np.float32(limit + 2.0)) <= size * EXTRUSION_RESOLUTION
    assert max_extrusion(TriangleSoup(tri * 10, None, name="t"), HighToLow([])) == pytest.approx(
        (size * 10 * EXTRUSION_RESOLUTION / FLOAT32_SPACING - 20.0))
    scaled = max_extrusion(TriangleSoup(tri, None, name="t"), HighToLow([], low_linear=np.eye(3) * 4.0))
    assert scaled == pytest.approx(limit / 4.0)


def test_a_full_disk_names_the_file_and_leaves_nothing(tmp_path, monkeypatch):
    """The system's own message names no file ('[Errno 28] No space left on device')."""
    import errno

    from hao_addon.core import imageio

    class Full:
        def __init__(self, fd, mode):
            os.close(fd)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(imageio.os, "fdopen", Full)
    target = tmp_path / "sub" / "ao.png"
    with pytest.raises(OSError, match=f"cannot write '{target}': No space left on device"):
        imageio.atomic_write_bytes(target, b"x" * 10)
    staged = imageio.StagedFiles()
    with pytest.raises(OSError, match="cannot write '.*b.png': No space left on device"):
        staged.write_bytes(tmp_path / "b.png", b"x")
    staged.discard()
    assert list(tmp_path.iterdir()) == []
