"""Settings of the virtual experiment in SI units, converted once from the config's
``virtual_experiment`` slice (units in the key names; config/README.md describes each)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from amontons.io.layout import IMAGE_FORMATS
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.virtual.afm import AfmSettings
from amontons.virtual.flim import TcspcSettings
from amontons.virtual.rough_contact import SolverSettings

FLIM_FORMATS = ("tif", "ptu")
RHEOMETER_FORMATS = ("csv", *EXPORT_SHAPES)
IMAGE_FORMAT_NAMES = tuple(IMAGE_FORMATS)


@dataclass(frozen=True)
class InstrumentSettings:
    """The virtual instruments, in SI units (see config/README.md for each key)."""

    psf_fwhm_m: float
    background_counts: float
    contact_counts: float
    confinement_floor_pa: float
    field_of_view_factor: float
    reflection_counts: float
    reflection_contrast: float
    reflection_rings: int
    bead_field_m: float
    bead_peak_counts: float
    absorbance_peak: float
    absorbance_band_fwhm_nm: float
    absorbance_noise_sd: float
    rotation_radius_m: float
    sliding_speed_m_s: float
    dynamic_fraction: float
    flim_field_px: int
    flim_contact_ns: float
    flim_outside_ns: float
    flim_noise_ns: float
    wavelength_m: float
    refractive_index: float

    @classmethod
    def from_config(cls, settings: Mapping, newton_rings: Mapping) -> InstrumentSettings:
        """Convert the ``virtual_experiment`` config slice (units in key names) to SI; the
        light and the medium of the reflection image come from ``newton_rings`` (the
        ``optics.newton_rings`` slice the measurement reads them from)."""
        return cls(
            psf_fwhm_m=settings["psf_fwhm_nm"] * 1e-9,
            background_counts=settings["background_counts"],
            contact_counts=settings["contact_counts"],
            confinement_floor_pa=settings["confinement_floor_mpa"] * 1e6,
            field_of_view_factor=settings["field_of_view_factor"],
            reflection_counts=settings["reflection_counts"],
            reflection_contrast=settings["reflection_contrast"],
            reflection_rings=settings["reflection_rings"],
            bead_field_m=settings["bead_field_um"] * 1e-6,
            bead_peak_counts=settings["bead_peak_counts"],
            absorbance_peak=settings["absorbance_peak"],
            absorbance_band_fwhm_nm=settings["absorbance_band_fwhm_nm"],
            absorbance_noise_sd=settings["absorbance_noise_sd"],
            rotation_radius_m=settings["rotation_radius_mm"] * 1e-3,
            sliding_speed_m_s=settings["sliding_speed_um_s"] * 1e-6,
            dynamic_fraction=settings["dynamic_fraction"],
            flim_field_px=settings["flim_field_px"],
            flim_contact_ns=settings["flim_contact_ns"],
            flim_outside_ns=settings["flim_outside_ns"],
            flim_noise_ns=settings["flim_noise_ns"],
            wavelength_m=newton_rings["wavelength_nm"] * 1e-9,
            refractive_index=newton_rings["refractive_index"],
        )


@dataclass(frozen=True)
class SurfaceSettings:
    """The rough sphere and the grids it is seen on (SI units; config/README.md)."""

    hurst: float
    rolloff_m: float
    solver: SolverSettings
    afm: AfmSettings

    @classmethod
    def from_config(cls, settings: Mapping) -> SurfaceSettings:
        """Convert the ``virtual_experiment`` config slice (units in key names) to SI."""
        return cls(
            hurst=settings["roughness_hurst"],
            rolloff_m=settings["roughness_rolloff_um"] * 1e-6,
            solver=SolverSettings(
                pixel_m=settings["solver_pixel_nm"] * 1e-9,
                max_grid_px=settings["solver_max_grid_px"],
                window_factor=settings["solver_window_factor"],
            ),
            afm=AfmSettings(
                pixel_m=settings["afm_pixel_nm"] * 1e-9,
                side_px=settings["afm_side_px"],
                noise_m=settings["afm_noise_nm"] * 1e-9,
                line_offsets=settings["afm_line_offsets"],
                line_offset_m=settings["afm_line_offset_nm"] * 1e-9,
                field_factor=settings["afm_field_factor"],
                rotation_deg=settings["afm_rotation_deg"],
                mirrored=settings["afm_mirrored"],
            ),
        )


@dataclass(frozen=True)
class OutputFormats:
    """The formats the virtual instruments write (config ``virtual_experiment.formats``).

    ``flim``: 'tif' (the mean arrival time map) or 'ptu' (the time-tagged photons, which need
    ``tcspc``); ``rheometer``: 'csv' (our own) or one of the export shapes of
    amontons.io.rheometer_export_shapes.EXPORT_SHAPES; ``images``: the confocal images'
    format, a key of amontons.io.layout.IMAGE_FORMATS ('tif', 'ome_tiff', 'czi'). The
    default is the TIFF and CSV route.
    """

    flim: str = "tif"
    rheometer: str = "csv"
    tcspc: TcspcSettings | None = None
    images: str = "tif"

    def __post_init__(self):
        if self.flim not in FLIM_FORMATS:
            raise ValueError(
                f"virtual_experiment.formats.flim = {self.flim!r}; expected one of {FLIM_FORMATS}"
            )
        if self.rheometer not in RHEOMETER_FORMATS:
            raise ValueError(
                f"virtual_experiment.formats.rheometer = {self.rheometer!r}; expected one of "
                f"{RHEOMETER_FORMATS}"
            )
        if self.images not in IMAGE_FORMAT_NAMES:
            raise ValueError(
                f"virtual_experiment.formats.images = {self.images!r}; expected one of "
                f"{IMAGE_FORMAT_NAMES}"
            )
        if self.flim == "ptu" and self.tcspc is None:
            raise ValueError("a PTU FLIM file needs the photon-counting settings (tcspc)")

    @classmethod
    def from_config(cls, settings: Mapping) -> OutputFormats:
        """From the ``virtual_experiment`` config slice: its ``formats`` (flim, rheometer,
        images) and, for a PTU, the photon-counting keys (amontons.virtual.flim.TcspcSettings)."""
        formats = settings["formats"]
        flim = formats["flim"]
        return cls(
            flim=flim,
            rheometer=formats["rheometer"],
            tcspc=TcspcSettings.from_config(settings) if flim == "ptu" else None,
            images=formats["images"],
        )

    @property
    def image_suffix(self) -> str:
        """The suffix of the confocal images ('.tif', '.ome.tif', '.czi')."""
        return IMAGE_FORMATS[self.images]


# The formats of the small-data run and of every test that does not choose one.
TIFF_AND_CSV = OutputFormats()
