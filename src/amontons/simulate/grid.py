"""Fields on the solver grid seen on another grid (positions in m about both grids' centres).

Two ways, one per need: :func:`resample` interpolates a field at given positions (AFM scans,
the gap at image pixel centres); :class:`PixelAverager` averages a field over each image pixel
from the nearest solver pixel of each sub-sample, so a contact patch's edge counts by the
fraction of the image pixel it covers. :func:`block_mean` averages whole blocks of an image (the
registration's coarse search; maps drawn at a figure's resolution).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, sparse


def block_mean(image: np.ndarray, factor: int) -> np.ndarray:
    """Mean over ``factor`` × ``factor`` blocks, the rows and columns that fill no whole block
    (at the end of each axis, fewer than ``factor``) dropped."""
    rows, cols = (n // factor * factor for n in image.shape)
    blocks = np.asarray(image, dtype=float)[:rows, :cols]
    return blocks.reshape(rows // factor, factor, cols // factor, factor).mean(axis=(1, 3))


def resample(
    field: np.ndarray,
    spacing_m: float,
    rows_m: np.ndarray,
    cols_m: np.ndarray,
    order: int,
    mode: str = "nearest",
) -> np.ndarray:
    """``field`` (on a grid of ``spacing_m`` about its centre) at the positions (m) given by
    the outer product of ``rows_m`` and ``cols_m``; spline ``order`` 0, 1 or 3; ``mode`` as in
    scipy.ndimage.map_coordinates ('constant' is 0 outside)."""
    rows = np.asarray(rows_m)[:, None]
    cols = np.asarray(cols_m)[None, :]
    return resample_points(field, spacing_m, rows, cols, order, mode)


def resample_points(
    field: np.ndarray,
    spacing_m: float,
    rows_m: np.ndarray,
    cols_m: np.ndarray,
    order: int,
    mode: str = "nearest",
) -> np.ndarray:
    """``field`` (on a grid of ``spacing_m`` about its centre) at the positions (m) of the
    arrays ``rows_m`` and ``cols_m`` (broadcast together): a rotated scan's pixels."""
    n0, n1 = field.shape
    rows, cols = np.broadcast_arrays(np.asarray(rows_m), np.asarray(cols_m))
    r = (n0 - 1) / 2 + rows / spacing_m
    c = (n1 - 1) / 2 + cols / spacing_m
    return ndimage.map_coordinates(field, [r, c], order=order, mode=mode, cval=0.0)


class PixelAverager:
    """Average solver-grid fields over the pixels of an image grid.

    Each image pixel is sampled on a ``supersample``² sub-grid and each sub-sample takes the
    nearest solver pixel (0 outside the solver window). The sub-grid is separable, so the
    average is R·F·Cᵀ with sparse row and column weights built once and reused for every
    field and load (a 1500² image at 4×4 sub-samples is 36 M look-ups otherwise).
    """

    def __init__(self, field_shape, spacing_m, image_shape, pixel_m, supersample: int = 4):
        self.rows = _weights(field_shape[0], spacing_m, image_shape[0], pixel_m, supersample)
        self.cols = _weights(field_shape[1], spacing_m, image_shape[1], pixel_m, supersample)

    def __call__(self, field: np.ndarray) -> np.ndarray:
        return np.asarray(self.rows @ (self.cols @ np.asarray(field, dtype=float).T).T)


def _weights(n_field, spacing_m, n_image, pixel_m, supersample):
    """(n_image × n_field) sparse matrix: the share of each image pixel's sub-samples (along
    one axis) whose nearest solver pixel is each field pixel."""
    sub = pixel_m / supersample
    positions = (np.arange(n_image * supersample) - (n_image * supersample - 1) / 2) * sub
    nearest = np.floor((n_field - 1) / 2 + positions / spacing_m + 0.5).astype(int)
    inside = (nearest >= 0) & (nearest < n_field)
    pixel = np.arange(n_image * supersample) // supersample
    return sparse.csr_matrix(
        (np.full(inside.sum(), 1.0 / supersample), (pixel[inside], nearest[inside])),
        shape=(n_image, n_field),
    )
