"""A measured sphere's load series in one file (config/README.md, "A load series in one
file"): in place of one fluorescence image per load, one file holds every load; it is then
every fluorescence job's input, and the jobs' ``images`` param says which plane is which
load (config optics.images.load_series: {axis, planes})."""

from __future__ import annotations

import os
from collections.abc import Mapping

from amontons.io.layout import (
    FLUORESCENCE_DIR,
    LOAD_SERIES_STEM,
    RawDataError,
    confocal_file,
    load_count_mismatch,
    plane_loads,
)
from amontons.io.pixel_probe import load_plane_count
from amontons.workflow.params import sorted_keys
from amontons.workflow.sheet_rows import SheetRows


class LoadSeries:
    """Which selected spheres hold their loads in one file, and how its planes map to the
    loads: ``config`` is the config's optics.images.load_series ({axis, planes}; None: no
    such file is accepted). Each sphere's folder is looked at once, when the DAG asks
    first."""

    def __init__(self, rows: SheetRows, config: Mapping | None = None):
        self.rows = rows
        self.config = None if config is None else dict(config)
        self._files: dict[str, str | None] = {}

    def file(self, sphere: str) -> str | None:
        """A measured sphere's one file holding every load's fluorescence image
        (``<folder>/fluorescence.<suffix>``, amontons.io.layout.LOAD_SERIES_STEM); None where
        it has none (the virtual experiment writes one image per load).

        Raises RawDataError naming both where the folder also has the per-load
        ``fluorescence/``, and naming the file where the config does not say how its planes
        map to the loads (optics.images.load_series): neither is guessed. The folder is
        looked at once, when the DAG asks first."""
        if sphere not in self._files:
            self._files[sphere] = self._find_file(sphere)
        return self._files[sphere]

    def _find_file(self, sphere: str) -> str | None:
        if self.rows.is_synthetic(sphere):
            return None
        folder = self.rows.raw_dir(sphere)
        found = confocal_file(folder, LOAD_SERIES_STEM)
        if found is None:
            return None
        if os.path.isdir(f"{folder}/{FLUORESCENCE_DIR}"):
            raise RawDataError(
                f"sphere {sphere}: both {folder}/{FLUORESCENCE_DIR}/ (one image per load) and "
                f"{found} (every load in one file); expected one of the two"
            )
        if self.config is None:
            raise RawDataError(
                f"sphere {sphere}: {found} holds every load, but optics.images.load_series is "
                "null; expected it to say which axis (series or frames) carries the loads and "
                "which plane is which load (config/README.md, 'A load series in one file')"
            )
        return str(found)

    def plane_loads(self, sphere: str) -> list[float] | None:
        """The load (mN) of each plane of a sphere's load-series file, in plane order; None
        where it has per-load images. A planes list that does not fit the sheet's loads stops
        the run, naming the sphere (amontons.io.layout.plane_loads)."""
        if self.file(sphere) is None:
            return None
        return plane_loads(self.rows.loads_mn(sphere), self.config["planes"], f"sphere {sphere}")

    def fluorescence_choice(self, sphere: str, images: Mapping) -> dict:
        """The ``images`` param of a rule that reads a sphere's fluorescence images: the
        config's choice (amontons.workflow.params.image_choice), plus for a load-series file
        ``load_series`` {axis, plane_loads_mn} (amontons.io.rawdata.fluorescence_planes).
        Spheres with per-load images get ``images`` as it is, so their jobs' params, and
        what they make, stay those of a run without load-series files."""
        planes = self.plane_loads(sphere)
        if planes is None:
            return dict(images)
        series = {"axis": self.config["axis"], "plane_loads_mn": planes}
        return sorted_keys({**images, "load_series": series})

    def check(self, series: int = 0) -> None:
        """Stop the run before any job where a sphere's load-series file does not hold one
        plane per load along the load axis, as its header says (amontons.io.pixel_probe;
        ``series``: optics.images.series, the series whose frames carry the loads):
        RawDataError naming the sphere, the file, what it holds and the loads. A header that
        does not say is left to the jobs' reader, which counts the planes again; a folder that
        cannot be mapped at all, to the rules' input functions, which name it."""
        for sphere in self.rows:
            try:
                path, planes = self.file(sphere), self.plane_loads(sphere)
            except RawDataError:
                continue
            if path is None:
                continue
            axis = self.config["axis"]
            count = load_plane_count(path, axis, series)
            if count is not None and count != len(planes):
                described = f"it holds {count} {axis} (its header says)"
                raise RawDataError(
                    f"sphere {sphere}: {load_count_mismatch(path, described, axis, planes)}"
                )
