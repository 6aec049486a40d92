"""Scan-line levelling only where the lines are offset, on maps built here: a 25.6 µm scan
(256 × 256 px of 100 nm) of a smooth sphere of 1.25 mm radius, 65-130 nm of sag, with white
height noise of 1 nm; not the virtual experiment's 32 nm pixels and 0.3 nm noise."""

import numpy as np
import pytest

from amontons.io.heightmap import TopographyError
from amontons.measure.scan_lines import (
    LINE_LEVELLING_MODES,
    ScanLineError,
    level_lines,
    line_levelling_mode,
)
from amontons.measure.topography import level_sphere, sphere_cap

N, PIXEL, RADIUS, NOISE = 256, 100e-9, 1.25e-3, 1e-9


def _sphere(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    cap = sphere_cap((N, N), PIXEL, RADIUS, (0.7e-6, -0.4e-6), 2e-6)
    return cap + rng.normal(0, NOISE, (N, N))


def _offsets(rng: np.random.Generator) -> np.ndarray:
    """Per-row offsets (m): eight single lines shifted by 2-5 nm of either sign, and a block
    of 40 rows shifted by 3 nm (a tip change and back)."""
    offsets = np.zeros(N)
    lines = rng.choice(np.r_[10:100, 160:250], size=8, replace=False)
    offsets[lines] = rng.choice([-1, 1], size=8) * rng.uniform(2e-9, 5e-9, size=8)
    offsets[110:150] += 3e-9
    return offsets


def test_auto_removes_the_offsets_it_finds():
    """With offsets present, ``auto`` levels: every row's removed offset matches the true one
    (up to a constant) within 0.3 nm, and the radius is right to 0.1 %. A step's size is a
    difference of two row medians of 256 noisy pixels (sd 1.25·√2·1 nm/16 = 0.11 nm) less
    the local slope: 0.3 nm is ~2.5 sd of that. Without levelling the same map's rows keep
    up to 5 nm of offset."""
    rng = np.random.default_rng(21)
    offsets = _offsets(rng)
    fit = level_sphere(_sphere(21) + offsets[:, None], PIXEL, line_levelling="auto")
    assert fit.line_levelling.applied and fit.line_levelling.stepped_rows == 2 * 8 + 2
    assert not fit.line_levelling.every_row
    removed = fit.line_offsets - np.median(fit.line_offsets - offsets)
    np.testing.assert_allclose(removed, offsets, rtol=0, atol=0.3e-9)
    assert fit.radius_m == pytest.approx(RADIUS, rel=1e-3)
    # what is left in the rows: the roughness map's row medians are the noise's
    row_medians = np.median(fit.roughness, axis=1)
    assert np.abs(row_medians - np.median(row_medians)).max() < 0.3e-9
    unlevelled = level_sphere(_sphere(21) + offsets[:, None], PIXEL, line_levelling="off")
    assert np.abs(np.median(unlevelled.roughness, axis=1)).max() > 2e-9


def test_auto_leaves_unshifted_lines_alone_and_keeps_the_radius_scatter():
    """Twelve noise draws without offsets: ``auto`` finds no offset in any, so the radius
    scatters exactly as without levelling (measured 0.014 %). Aligning every row (``on``,
    the old behaviour) adds a random walk of the row medians along y that bends the sphere:
    its scatter is 17× larger here (0.23 %); 3× is the bound."""
    errors = {mode: [] for mode in LINE_LEVELLING_MODES}
    for seed in range(12):
        heights = _sphere(seed)
        for mode in LINE_LEVELLING_MODES:
            fit = level_sphere(heights, PIXEL, line_levelling=mode)
            errors[mode].append(fit.radius_m / RADIUS - 1)
            if mode == "auto":
                assert not fit.line_levelling.applied
                assert not fit.line_offsets.any()
    scatter = {mode: np.std(values) for mode, values in errors.items()}
    assert scatter["auto"] <= scatter["off"] * (1 + 1e-9)
    assert scatter["on"] > 3 * scatter["off"]
    assert abs(np.mean(errors["auto"])) < 3 * scatter["off"] / np.sqrt(12) + 1e-4


def test_auto_aligns_every_row_when_every_row_is_offset():
    """An offset of 2 nm rms on every row (a drifting feedback): the small offsets hide
    among the ordinary steps, so ``auto`` aligns every row as ``on`` does. Leaving the
    unflagged quarter of the steps alone instead bent the radius by 7-18 %; aligned, it is
    within 0.5 % (the random walk of the row medians, as under ``on``)."""
    rng = np.random.default_rng(8)
    heights = _sphere(8) + rng.normal(0, 2e-9, N)[:, None]
    fit = level_sphere(heights, PIXEL, line_levelling="auto")
    assert fit.line_levelling.every_row and fit.line_levelling.stepped_rows == N - 1
    assert fit.radius_m == pytest.approx(RADIUS, rel=5e-3)
    aligned = level_sphere(heights, PIXEL, line_levelling="on")
    np.testing.assert_array_equal(fit.line_offsets, aligned.line_offsets)


def test_modes_and_records():
    heights = _sphere(3)
    record = level_lines(heights - sphere_cap((N, N), PIXEL, RADIUS, (0.7e-6, -0.4e-6), 2e-6))
    assert record.to_record()["mode"] == "auto" and record.to_record()["applied"] is False
    assert record.to_record()["row_offset_rms_nm"] == 0.0
    assert level_lines(heights, "off").to_record()["step_threshold_nm"] is None
    # YAML reads an unquoted on/off as true/false
    assert line_levelling_mode(True) == "on" and line_levelling_mode(False) == "off"
    with pytest.raises(ScanLineError, match="line levelling 'always'; expected one of auto"):
        line_levelling_mode("always")
    with pytest.raises(TopographyError, match=r"\(12, 40\) px; line levelling needs at least"):
        level_sphere(_sphere(4)[:12, :40], PIXEL)
