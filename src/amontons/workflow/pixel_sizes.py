"""Where the fluorescence pixel of a sphere's images comes from: the sheet
(fluorescence_pixel_nm), else each image's own metadata, probed at DAG time
(amontons.io.pixel_probe), so that an image stating none stops the run before any job."""

from __future__ import annotations

import os

from amontons.io.layout import RawDataError
from amontons.io.pixel_probe import states_pixel_size
from amontons.workflow.paths import CONTACT_AREA, RunPaths
from amontons.workflow.raw_files import RawFiles
from amontons.workflow.sheet_rows import SheetRows


class PixelSizes:
    """The selected spheres' fluorescence pixel sizes: which inputs a rule reads the pixel
    from, and which images state none while the sheet gives none."""

    def __init__(self, rows: SheetRows, files: RawFiles, paths: RunPaths):
        self.rows = rows
        self.files = files
        self.paths = paths

    def image_pixel_inputs(self, sphere: str) -> list[str]:
        """What a rule that renders a contact at the fluorescence pixel reads that pixel from:
        nothing where the sheet gives it (fluorescence_pixel_nm), else the sphere's measured
        contact-area table, which records the pixel each image's file gave
        (amontons.measure.area.image_pixel_m)."""
        if self.rows.pixel_nm(sphere) is not None:
            return []
        return [self.paths.measured(CONTACT_AREA, self.rows.material_of(sphere), sphere)]

    def images_without_pixel(self, sphere: str) -> list[str]:
        """The images of a measured sphere whose sheet row gives no fluorescence_pixel_nm
        that state no pixel size in their metadata either (amontons.io.pixel_probe): the
        confocal images (fluorescence, reflection, bead) and the FLIM file (map or photons);
        none where the sheet gives one. Images that do not match the loads, or whose header
        cannot be read, are left to the errors that name them."""
        if self.rows.is_synthetic(sphere) or self.rows.pixel_nm(sphere) is not None:
            return []
        try:
            images = self.files.per_load_inputs(sphere, "fluorescence")
        except RawDataError:
            images = []
        singles = (
            self.files.reflection_image(sphere),
            self.files.bead_image(sphere),
            self.files.flim_path(sphere),
        )
        images += [path for path in singles if path is not None and os.path.isfile(path)]
        return [path for path in images if not _states_pixel(path)]

    def check(self) -> None:
        """Stop the run before any job where an image has no pixel size: RawDataError naming
        each sphere and its images that state none while the sheet gives none."""
        lacking = {sphere: self.images_without_pixel(sphere) for sphere in self.rows}
        lines = [f"sphere {s}: {', '.join(paths)}" for s, paths in lacking.items() if paths]
        if lines:
            raise RawDataError(
                "images without a pixel size in their metadata, and no fluorescence_pixel_nm "
                f"in the sheet: {'; '.join(lines)}; expected the sheet's fluorescence_pixel_nm "
                "for these spheres, or images that state their pixel (OME-TIFF PhysicalSizeX, "
                "CZI Scaling, TIFF resolution tags, PTU ImgHdr_PixResol)"
            )


def _states_pixel(path: str) -> bool:
    """Whether the image ``path`` states its pixel size; an unreadable header counts as yes
    here, since the job that reads it stops naming the file."""
    try:
        return states_pixel_size(path)
    except RawDataError:
        return True
