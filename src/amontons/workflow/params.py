"""Slices of the config as rules' params: each rule gets only what it uses, so that a changed
value re-runs exactly the jobs that use it (DESIGN: scripts never read the whole config)."""

from __future__ import annotations

from collections.abc import Mapping


def sorted_keys(mapping: Mapping) -> dict:
    """``mapping`` with its keys (and those of nested mappings) in sorted order. Snakemake
    compares a job's params as written, key order included: sorted, a config overlay that
    lists its keys in another order re-runs nothing."""
    return {
        key: sorted_keys(value) if isinstance(value, dict) else value
        for key, value in sorted(mapping.items())
    }


def config_slice(config: Mapping, *keys: str) -> dict:
    """The config section at ``keys`` (e.g. "optics", "psf")."""
    section = config
    for key in keys:
        section = section[key]
    return sorted_keys(section)


def otsu_settings(config: Mapping) -> dict:
    """The optics keys that decide where a contact is and whether there is one."""
    optics = config["optics"]
    keys = ("otsu_bins", "min_separation", "min_contrast", "min_patch_px")
    return sorted_keys({key: optics[key] for key in keys})


def ring_optics(config: Mapping) -> dict:
    """The light and the medium of the reflection image: the measurement and the virtual
    experiment read the same two keys."""
    rings = config["optics"]["newton_rings"]
    return sorted_keys({key: rings[key] for key in ("wavelength_nm", "refractive_index")})


def afm_reading(config: Mapping) -> dict:
    """How the AFM maps are read: the surface keys the topography step uses too."""
    surface = config["surface"]
    return sorted_keys(
        {
            "nan_policy": surface["afm_nan_policy"],
            "channel": surface["afm_channel"],
            "line_levelling": surface["line_levelling"],
        }
    )


def image_choice(config: Mapping, reflection: bool = False) -> dict:
    """Which plane of a confocal file is the image (config optics.images), as the keyword
    arguments of amontons.io.confocal.ImageChoice: the fluorescence and bead channel, or with
    ``reflection`` the reflection image's (its own where given, else the same)."""
    images = config["optics"]["images"]
    channel = images["channel"]
    if reflection and images["reflection_channel"] is not None:
        channel = images["reflection_channel"]
    return sorted_keys({"channel": channel, "series": images["series"], "frames": images["frames"]})
