"""The accuracy study's problems and the grid of solver settings it solves them at
(docs/accuracy.md). Pure Python: the workflow builds its jobs from these names without the
numerical stack.

A setting is a solver pixel (a multiple of the finest pixel: the AFM map's own for the
rough spheres), a CG tolerance, a window factor (window side / Hertz contact diameter at the
largest load; a periodic problem has no window to choose) and coarse-to-fine on or off
(elastic problems only: the solver ignores it with plasticity). The config gives the grid as
blocks, each the Cartesian product of its lists; the settings are their union.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from amontons.config.errors import ConfigError
from amontons.models import CONTACT_HARDENING, ELASTIC, timed

# problem -> (contact model, geometry)
PROBLEMS = {
    "elastic_sphere": (ELASTIC.name, "sphere"),
    "hardening_sphere": (CONTACT_HARDENING.name, "sphere"),
    "periodic": (ELASTIC.name, "flat_periodic"),
}
REFERENCE = "reference"


class AccuracyConfigError(ConfigError):
    """An accuracy study the config cannot run (names the key)."""


@dataclass(frozen=True, order=True)
class Setting:
    """One point of the grid: pixel factor (× the finest pixel), tolerance, window factor
    (None for a periodic problem), coarse-to-fine."""

    pixel_factor: int
    tol: float
    window_factor: float | None
    coarse_to_fine: bool

    @property
    def name(self) -> str:
        """A file-name-safe label, e.g. ``px4_tol1e-06_w1.5_c2f0``."""
        window = "" if self.window_factor is None else f"_w{self.window_factor:g}"
        return f"px{self.pixel_factor}_tol{self.tol:.0e}{window}_c2f{int(self.coarse_to_fine)}"

    def to_record(self) -> dict:
        return {
            "pixel_factor": self.pixel_factor,
            "tol": self.tol,
            "window_factor": self.window_factor,
            "coarse_to_fine": self.coarse_to_fine,
        }


def problem_kind(problem: str) -> tuple[str, str]:
    """(contact model, geometry) of a problem; AccuracyConfigError for an unknown one."""
    try:
        return PROBLEMS[problem]
    except KeyError:
        raise AccuracyConfigError(
            f"accuracy.problems: {problem!r} is not a problem; expected one of {list(PROBLEMS)}"
        ) from None


def _setting(problem: str, pixel_factor, tol, window_factor, coarse_to_fine) -> Setting | None:
    """The setting as the problem sees it, None where it means nothing there: coarse-to-fine
    with plasticity (the solver ignores it), a window factor on a periodic surface."""
    model, geometry = problem_kind(problem)
    if coarse_to_fine and model != ELASTIC.name:
        return None
    window = None if geometry == "flat_periodic" else float(window_factor)
    return Setting(int(pixel_factor), float(tol), window, bool(coarse_to_fine))


def problem_settings(problem: str, blocks: Sequence[Mapping]) -> list[Setting]:
    """The settings of ``problem``: the union of every block's Cartesian product, sorted."""
    out = set()
    for block in blocks:
        for combo in itertools.product(
            block["pixel_factor"], block["tol"], block["window_factor"], block["coarse_to_fine"]
        ):
            setting = _setting(problem, *combo)
            if setting is not None:
                out.add(setting)
    return sorted(out)


def reference_setting(problem: str, reference: Mapping) -> Setting:
    """The converged reference: the finest pixel, the tightest tolerance, the widest window."""
    return _setting(
        problem,
        reference["pixel_factor"],
        reference["tol"],
        reference["window_factor"],
        False,
    )


def settings_by_name(problem: str, config: Mapping) -> dict[str, Setting]:
    """Every setting of ``problem`` by name, the reference under ``REFERENCE``."""
    named = {s.name: s for s in problem_settings(problem, config["grid"])}
    named[REFERENCE] = reference_setting(problem, config["reference"])
    return named


def timing_points(config: Mapping) -> dict[str, tuple[str, float]]:
    """The timing points by name (e.g. ``penetration_hardness_y0.6``): (contact model, its
    dimensionless ratio)."""
    spec = config["timing_points"]
    points = {}
    for model in timed():
        key = model.timing_ratio
        for value in spec.get(key, ()):
            points[f"{model.name}_{key[0]}{value:g}"] = (model.name, float(value))
    return points


def timing_point_pattern() -> str:
    """The regular expression of a timing point's name (:func:`timing_points`)."""
    names = "|".join(model.name for model in timed())
    letters = "".join(sorted({model.timing_ratio[0] for model in timed()}))
    return rf"({names})_[{letters}][0-9.e+-]+"


def timing_setting(config: Mapping) -> Setting:
    """The one setting every timing point is solved at."""
    spec = config["timing_points"]["setting"]
    return Setting(
        int(spec["pixel_factor"]), float(spec["tol"]), float(spec["window_factor"]), False
    )


def common_pixel_factor(config: Mapping) -> int:
    """Pixel factor of the grid every pressure field is compared on: the coarsest setting's."""
    return max(max(block["pixel_factor"]) for block in config["grid"])


def common_window_factor(config: Mapping) -> float:
    """Window factor of that grid: the narrowest window any setting has (every setting's
    contact lies inside it)."""
    return min(min(block["window_factor"]) for block in config["grid"])


def check_accuracy(config: Mapping, source: str) -> None:
    """Stop before any job on an accuracy study that cannot run, naming the key."""
    for problem in config["problems"]:
        problem_kind(problem)
    reference = config["reference"]
    finest = min(min(block["pixel_factor"]) for block in config["grid"])
    tightest = min(min(block["tol"]) for block in config["grid"])
    widest = max(max(block["window_factor"]) for block in config["grid"])
    wanted = (
        ("pixel_factor", reference["pixel_factor"], finest, "the finest pixel factor"),
        ("tol", reference["tol"], tightest, "the tightest tolerance"),
        ("window_factor", -reference["window_factor"], -widest, "the widest window factor"),
    )
    for key, value, bound, what in wanted:
        if value > bound:
            raise AccuracyConfigError(
                f"{source}: accuracy.reference.{key} = {abs(value):g} is coarser than "
                f"{what} of the grid ({abs(bound):g}); expected the reference at least as "
                "converged as every setting"
            )
    for block in config["grid"]:
        if min(block["pixel_factor"]) < 1:
            raise AccuracyConfigError(
                f"{source}: accuracy.grid pixel_factor {block['pixel_factor']}; expected "
                "integers ≥ 1 (multiples of the finest pixel)"
            )


def check_accuracy_study(config: Mapping, sheet: Mapping[str, dict], source: str) -> None:
    """The accuracy study's sphere (null: the first sphere of the first selected material,
    set in place) must be a sphere of a selected material, and its grid and reference must
    make sense (:func:`check_accuracy`). ``config``: the whole config; ``sheet``: every
    sphere's record (amontons.config.sheet)."""
    study = config["accuracy"]
    if study["sphere"] is None:
        # the first sphere of the first selected material: the study runs on any data set
        study["sphere"] = next(
            s for m in config["materials"] for s, r in sheet.items() if r["material"] == m
        )
    record = sheet.get(study["sphere"])
    if record is None or record["material"] not in config["materials"]:
        raise ConfigError(
            f"{source}: accuracy.sphere = {study['sphere']!r} is not a sphere of the selected "
            f"materials {list(config['materials'])}; expected one of "
            f"{', '.join(s for s, r in sheet.items() if r['material'] in config['materials'])}"
        )
    check_accuracy(study, source)
