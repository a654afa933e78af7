# SPDX-License-Identifier: GPL-3.0-or-later
"""8-bit PNG output and its dither (issue 30 item 5): no banding in a smooth gradient, levels
stay exact, the same bytes on every run; the command line writes it."""
from __future__ import annotations

import zlib

import numpy as np
import pytest

from hao_addon.core.imageio import png16_bytes, quantized

STEP = 1.0 / 255.0


def gradient() -> np.ndarray:
    """(128, 1024) a shallow ramp, 0.30 to 0.34: about ten 8-bit steps over 1024 columns."""
    return np.tile(np.linspace(0.30, 0.34, 1024), (128, 1))


def column_error(levels: np.ndarray, image: np.ndarray) -> np.ndarray:
    """(columns,) the mean of each column's 8-bit values against the ramp, in steps."""
    return levels.astype(np.float64).mean(axis=0) - image.mean(axis=0) * 255.0


def test_rounding_bands_and_the_dither_does_not():
    """Rounded, a column's mean is off by up to half a step (the bands); dithered, by its
    noise alone: 128 samples of a uniform, sd 0.29 / sqrt(128) = 0.026 step, so 0.15 is about
    six of those."""
    image = gradient()
    banded = np.abs(column_error(quantized(image, 8), image))
    smooth = np.abs(column_error(quantized(image, 8, dither=True), image))
    assert banded.max() > 0.45 and smooth.max() < 0.15, (banded.max(), smooth.max())
    assert abs(column_error(quantized(image, 8, dither=True), image).mean()) < 0.01  # no bias overall


def test_levels_stay_exact_and_the_noise_stays_below_a_step():
    levels = np.array([0.0, 1.0, 128 / 255, 17 / 255, 254 / 255])
    image = np.tile(levels, (64, 1))
    assert (quantized(image, 8, dither=True) == np.round(levels * 255)).all()
    ramp = gradient()
    diff = quantized(ramp, 8, dither=True).astype(np.float64) - ramp * 255.0
    assert diff.min() > -1.0 and diff.max() < 1.0  # floor(v + u): one of the two levels around v


def test_the_same_bytes_on_every_run():
    image = gradient()
    first = png16_bytes(image, bits=8, dither=True)
    assert first == png16_bytes(image, bits=8, dither=True)
    assert first[24] == 8  # IHDR bit depth
    raw = zlib.decompress(first[first.index(b"IDAT") + 4:])
    assert len(raw) == 128 * (1 + 1024)  # a filter byte and one byte a sample per row


def test_cli_writes_a_dithered_8_bit_map_of_the_bake(tmp_path):
    """--png-bits 8 --dither: Blender reads the file back within one 8-bit step of the 16-bit
    map of the same bake, its mean within a tenth of a step."""
    from test_cli_runs import SPOT, run

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    bake = ["bake", SPOT, "--size", "128", "--directions", "32", "--margin", "2", "--quiet"]
    assert run([*bake, "--out", tmp_path / "a16.png"], tmp).returncode == 0
    done = run([*bake, "--out", tmp_path / "a8.png", "--png-bits", "8", "--dither"], tmp)
    assert done.returncode == 0, done.stderr

    def red(path) -> np.ndarray:
        from bake_helpers import load_image_rgba
        return load_image_rgba(path)[..., 0].ravel().astype(np.float64)

    deep, shallow = red(tmp_path / "a16.png"), red(tmp_path / "a8.png")
    assert np.abs(shallow - deep).max() < STEP + 1e-6
    assert abs((shallow - deep).mean()) < 0.1 * STEP
    refused = run([*bake, "--out", tmp_path / "b.png", "--dither"], tmp)
    assert refused.returncode == 2 and "add --png-bits 8" in refused.stderr


@pytest.mark.parametrize("bits", [8, 16])
def test_gray_and_rgba_pngs_of_both_depths_have_their_sizes(bits):
    for image in (np.zeros((4, 5)), np.zeros((4, 5, 4))):
        data = png16_bytes(image, bits=bits)
        channels = 1 if image.ndim == 2 else 4
        raw = zlib.decompress(data[data.index(b"IDAT") + 4:])
        assert len(raw) == 4 * (1 + 5 * channels * bits // 8)
