"""The raw-data layout a sphere's folder follows, whether real or virtual.

<folder>/fluorescence/<load in mN>.tif   one confocal image per load (e.g. 25.tif)
<folder>/truth.json                      virtual experiment only; the analysis never reads it
"""

from __future__ import annotations

from pathlib import Path


class RawDataError(ValueError):
    """A raw-data folder does not match what the sample sheet promises."""


def fluorescence_name(load_mn: float) -> str:
    """File name of the fluorescence image at ``load_mn`` (e.g. 25 → '25.tif')."""
    return f"{load_mn:g}.tif"


def _load_of(path: Path) -> float | None:
    stem = path.stem.removesuffix("mN").removesuffix("mn")
    try:
        return float(stem)
    except ValueError:
        return None


def fluorescence_images(folder: str | Path, loads_mn: list[float]) -> list[Path]:
    """Paths of the fluorescence images, in the order of ``loads_mn``.

    Files are named by their load in mN (``25.tif`` or ``25mN.tif``). Raises RawDataError naming
    the folder when a load has no image, or an image's load is not in the list.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise RawDataError(f"{folder}: no fluorescence folder")
    found = {}
    for path in sorted(folder.glob("*.tif*")):
        load = _load_of(path)
        if load is None:
            raise RawDataError(f"{path}: file name is not a load in mN (expected e.g. 25.tif)")
        found[load] = path
    missing = [load for load in loads_mn if not any(abs(load - f) < 1e-9 for f in found)]
    extra = [f for f in found if not any(abs(load - f) < 1e-9 for load in loads_mn)]
    if missing or extra:
        raise RawDataError(
            f"{folder}: the load list {loads_mn} mN does not match the images "
            f"(no image for {missing or 'none'}; images not in the list: {extra or 'none'})"
        )
    return [next(found[f] for f in found if abs(load - f) < 1e-9) for load in loads_mn]
