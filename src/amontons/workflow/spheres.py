"""The selected spheres of the sample sheet, as the DAG asks after them (config/README.md,
"Your own data"): one part per concern, composed here.

- their sheet rows and raw folders (:mod:`~amontons.workflow.sheet_rows`),
- a load series held in one file (:mod:`~amontons.workflow.load_series`),
- the raw files each rule reads (:mod:`~amontons.workflow.raw_files`),
- where their images' pixel comes from (:mod:`~amontons.workflow.pixel_sizes`),
- the optional inputs they lack and what that allows
  (:mod:`~amontons.workflow.optional_inputs`),
- those an earlier run's failure holds out (:mod:`~amontons.workflow.hold_outs`).

The library and the rule files (workflow/rules/*.smk) ask the parts (``SPHERES.files``,
``SPHERES.rows``, ...); this class holds them and the selection the parts share.
"""

from __future__ import annotations

from collections.abc import Mapping

from amontons.workflow.failures import FailedJob
from amontons.workflow.hold_outs import HoldOuts
from amontons.workflow.load_series import LoadSeries
from amontons.workflow.optional_inputs import OptionalInputs
from amontons.workflow.paths import RunPaths
from amontons.workflow.pixel_sizes import PixelSizes
from amontons.workflow.raw_files import RawFiles
from amontons.workflow.sheet_rows import SheetRows


class Spheres:
    """The selected materials' spheres, in the sheet's order, with their parts: ``rows``
    (:class:`SheetRows`), ``series`` (:class:`LoadSeries`), ``files`` (:class:`RawFiles`),
    ``pixels`` (:class:`PixelSizes`), ``inputs`` (:class:`OptionalInputs`) and
    ``hold_outs`` (:class:`HoldOuts`); and which of them the run makes results for
    (:meth:`of`)."""

    def __init__(
        self,
        records: Mapping[str, dict],
        paths: RunPaths,
        psf_stand_in: bool = False,
        synthetic_flim: str = "tif",
        synthetic_images: str = ".tif",
        load_series: Mapping | None = None,
    ):
        """``records``: sphere id → sheet record (amontons.config.sheet); ``psf_stand_in``:
        whether the config gives a PSF (optics.psf.stand_in) for the spheres with no bead
        image; ``synthetic_flim``: the format of the virtual experiment's FLIM file ('tif' or
        'ptu', config virtual_experiment.formats.flim); ``synthetic_images``: the suffix of
        its confocal images ('.tif', '.ome.tif', '.czi'; amontons.io.layout.IMAGE_FORMATS of
        virtual_experiment.formats.images); ``load_series``: how a file holding a sphere's
        whole load series maps its planes to the loads (config optics.images.load_series:
        {axis, planes}; None: no such file is accepted)."""
        self.rows = SheetRows(records, paths)
        self.series = LoadSeries(self.rows, load_series)
        self.files = RawFiles(self.rows, self.series, synthetic_images, synthetic_flim)
        self.pixels = PixelSizes(self.rows, self.files, paths)
        self.inputs = OptionalInputs(self.rows, self.files, psf_stand_in)
        self.hold_outs = HoldOuts(self.rows)

    def __iter__(self):
        return iter(self.rows)

    @property
    def held_out(self) -> dict[str, list[FailedJob]]:
        """The held-out spheres, each with the failed jobs that hold it out
        (:class:`HoldOuts`)."""
        return self.hold_outs.jobs

    def of(self, material: str, having: str | None = None) -> list[str]:
        """The spheres of ``material`` whose results the run makes and its tables read, in
        sheet order: not those held out by an earlier run's failure (:class:`HoldOuts`), and
        only those with the optional input ``having`` where it is given."""
        return [
            s
            for s, row in self.rows.records.items()
            if row["material"] == material
            and s not in self.held_out
            and (having is None or self.inputs.has(s, having))
        ]

    def materials_with(self, materials, kind: str) -> list[str]:
        """Those of ``materials`` with at least one sphere that has the optional input
        ``kind``."""
        return [m for m in materials if self.of(m, having=kind)]
