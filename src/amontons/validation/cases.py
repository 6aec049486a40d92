"""The validation study's truths and cases, from the config's ``validation`` slice
(config/README.md; docs/study.md §7). Pure Python: the workflow names the cases' jobs from it
without loading the numerical stack.

A *truth* is a contact model with its parameter (an elastic truth has none); a *case* is one
truth on one seed's rough sphere, solved ``ratio`` times finer in pixel than the study then
solves it. The cases are on the study's own small sphere (the config's ``validation`` keys),
or on a sphere of the materials sheet (``validation.spheres``: the reproduction's spheres, at
the pixel the run's solver preset solves each at), whose truths are its elastic contact and
each plastic model at the value the config gives that sphere."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import asdict, dataclass

from amontons import models

# each plastic model's scanned parameter (config ``scans``)
PARAMETER_OF = {m.name: m.parameter.key for m in models.with_parameter()}
# the models a truth can be: those solved on a grid (amontons.models.FIELD)
TRUTH_MODELS = models.field_model_names()
# how far a truth's areas lie from the other models' against the study's model error: beyond
# it, below it, or an elastic truth (which every plastic model approaches at its elastic end)
CLEAR = "clear"
BELOW_MODEL_ERROR = "below model error"
NO_PLASTICITY = "none"
SIGNALS = (CLEAR, BELOW_MODEL_ERROR, NO_PLASTICITY)
# who solves a truth: our own solver, or ContactMechanics (amontons.validation.independent),
# which has no contact hardening
AMONTONS = "amontons"
CONTACTMECHANICS = "contactmechanics"
SOLVERS = {
    AMONTONS: TRUTH_MODELS,
    CONTACTMECHANICS: (models.ELASTIC.name, models.PENETRATION_HARDNESS.name),
}


@dataclass(frozen=True)
class Truth:
    """A contact model and its parameter's value (config units: p_y_mpa, k_mpa_per_nm; None
    for the elastic truth), under ``name``; ``signal``: whether its areas differ from the
    other models' by more than the study's model error ('clear'), less ('below model
    error') or not at all ('none': an elastic truth); ``solver``: who solves it
    (:data:`SOLVERS`); ``ratio``: its own truth-to-study pixel ratio where the study's
    default is out of reach for its solver (None: the default)."""

    name: str
    model: str
    value: float | None
    signal: str
    solver: str = AMONTONS
    ratio: float | None = None

    def __post_init__(self):
        if self.model not in TRUTH_MODELS:
            raise ValueError(
                f"validation truth {self.name!r}: model = {self.model!r}; expected one of "
                f"{TRUTH_MODELS}"
            )
        if self.signal not in SIGNALS:
            raise ValueError(
                f"validation truth {self.name!r}: signal = {self.signal!r}; expected one of "
                f"{SIGNALS}"
            )
        if self.model not in SOLVERS.get(self.solver, ()):
            raise ValueError(
                f"validation truth {self.name!r}: solver = {self.solver!r} for a {self.model} "
                f"truth; expected one of {[k for k, v in SOLVERS.items() if self.model in v]}"
            )
        if (self.value is None) != (self.parameter is None):
            raise ValueError(
                f"validation truth {self.name!r}: a {self.model} truth needs "
                f"{self.parameter or 'no value'}"
            )

    @property
    def parameter(self) -> str | None:
        return PARAMETER_OF.get(self.model)

    @classmethod
    def from_config(cls, name: str, entry: Mapping) -> Truth:
        model = entry["model"]
        parameter = PARAMETER_OF.get(model)
        value = None if parameter is None else entry.get(parameter)
        ratio = entry.get("ratio")
        return cls(
            name,
            model,
            None if value is None else float(value),
            entry["signal"],
            entry.get("solver", AMONTONS),
            None if ratio is None else float(ratio),
        )


@dataclass(frozen=True)
class Case:
    """One truth on one seed's sphere, solved ``ratio`` times finer in pixel than the study;
    ``comparison``: one of the comparison ratios' cases (reported, not held to the targets);
    ``sphere``: the materials sheet's sphere it is on (None: the study's own small sphere;
    the truth's name then starts with the sphere's)."""

    truth: Truth
    seed: int
    ratio: float
    comparison: bool = False
    sphere: str | None = None

    @property
    def name(self) -> str:
        return f"{self.truth.name}_r{self.ratio:g}_s{self.seed}"

    def to_record(self) -> dict:
        """JSON-ready (a case job's params), as :meth:`from_record` reads it."""
        return asdict(self)

    @classmethod
    def from_record(cls, record: Mapping) -> Case:
        return cls(**{**record, "truth": Truth(**record["truth"])})


def truths_of(validation: Mapping) -> dict[str, Truth]:
    """The truths ``run_truths`` names, by name, in its order."""
    truths = validation["truths"]
    for name in validation["run_truths"]:
        if name not in truths:
            raise ValueError(
                f"validation.run_truths names {name!r}; expected one of {list(truths)}"
            )
    return {name: Truth.from_config(name, truths[name]) for name in validation["run_truths"]}


def cases_of(validation: Mapping) -> list[Case]:
    """Every case of the study: each truth at its own ratio, or else ``truth_pixel_ratio``,
    over ``seeds`` seeds, and the truths ``comparison_truths`` again at each of
    ``comparison_ratios`` (the default reproduction's truth against its study, now and
    before: what a truth close to the study's grid does)."""
    truths = truths_of(validation)
    first = validation["first_seed"]
    seeds = range(first, first + validation["seeds"])
    default = float(validation["truth_pixel_ratio"])
    cases = [Case(t, s, t.ratio or default) for t in truths.values() for s in seeds]
    for name in validation["comparison_truths"]:
        if name not in truths:
            raise ValueError(
                f"validation.comparison_truths names {name!r}; expected one of run_truths "
                f"{list(truths)}"
            )
        cases += [
            Case(truths[name], s, float(ratio), comparison=True)
            for ratio in validation["comparison_ratios"]
            for s in seeds
        ]
    return cases


def cases_by_name(validation: Mapping) -> dict[str, Case]:
    """Every case of the study, on the small sphere and the sheet's spheres, by name."""
    return {case.name: case for case in [*cases_of(validation), *sphere_cases(validation)]}


def case_named(validation: Mapping, name: str) -> Case:
    """The case of ``name`` (:attr:`Case.name`), on the small sphere or a sheet sphere."""
    case = cases_by_name(validation).get(name)
    if case is None:
        raise ValueError(f"validation case {name!r} is not one of the config's cases")
    return case


def case_names(validation: Mapping) -> list[str]:
    """The names of every case of the study on its small sphere (the jobs' wildcards)."""
    return [case.name for case in cases_of(validation)]


# the truths on a sheet sphere: each model solved on a grid and its signal (each plastic model
# at the value ``validation.spheres`` gives the sphere, clear of the model error by its choice)
SPHERE_TRUTHS = tuple(
    (name, NO_PLASTICITY if name not in PARAMETER_OF else CLEAR) for name in TRUTH_MODELS
)


def sphere_truths(sphere: str, values: Mapping) -> list[Truth]:
    """The truths on sheet sphere ``sphere``: elastic, and each plastic model at its value in
    ``values`` (config units: p_y_mpa, k_mpa_per_nm), named ``<sphere>_<model>``."""
    truths = []
    for model, signal in SPHERE_TRUTHS:
        parameter = PARAMETER_OF.get(model)
        value = None if parameter is None else float(values[parameter])
        truths.append(Truth(f"{sphere}_{model}", model, value, signal))
    return truths


def sphere_cases(validation: Mapping, available: Collection[str] | None = None) -> list[Case]:
    """The cases on the materials sheet's spheres: every truth (:func:`sphere_truths`) of each
    sphere ``validation.spheres.run`` names (of those in ``available``, where given) on
    ``seeds`` seeds from ``first_seed``, at ``ratio``; and the truths of
    ``comparison_models`` again at each of ``comparison_ratios`` (reported, not held to the
    targets: what a truth finer than the default does)."""
    block = validation["spheres"]
    seeds = range(block["first_seed"], block["first_seed"] + block["seeds"])
    ratio = float(block["ratio"])
    cases = []
    for sphere in block["run"]:
        if available is not None and sphere not in available:
            continue
        if sphere not in block["values"]:
            raise ValueError(
                f"validation.spheres.run names {sphere!r}; expected one of its values' spheres "
                f"{list(block['values'])}"
            )
        truths = sphere_truths(sphere, block["values"][sphere])
        cases += [Case(truth, seed, ratio, sphere=sphere) for truth in truths for seed in seeds]
        cases += [
            Case(truth, seed, float(again), comparison=True, sphere=sphere)
            for truth in truths
            if truth.model in block["comparison_models"]
            for again in block["comparison_ratios"]
            for seed in seeds
        ]
    return cases


def sphere_case_names(validation: Mapping, available: Collection[str] | None = None) -> list[str]:
    """The names of the cases on the sheet's spheres (the jobs' wildcards)."""
    return [case.name for case in sphere_cases(validation, available)]


# the keys of ``validation`` (and of its ``spheres``) that only say which cases run: a case
# job's settings leave them out, so that adding a seed or a truth reruns no case
ENUMERATING_KEYS = (
    "seeds",
    "first_seed",
    "run_truths",
    "truths",
    "comparison_ratios",
    "comparison_truths",
)
SPHERE_ENUMERATING_KEYS = (
    "run",
    "values",
    "seeds",
    "first_seed",
    "comparison_ratios",
    "comparison_models",
)


def case_settings(validation: Mapping) -> dict:
    """What a case is judged with: ``validation`` without the keys that only enumerate the
    cases (:data:`ENUMERATING_KEYS`, :data:`SPHERE_ENUMERATING_KEYS`); the case itself is
    its own record (:meth:`Case.to_record`)."""
    settings = {k: v for k, v in validation.items() if k not in ENUMERATING_KEYS}
    spheres = validation["spheres"]
    settings["spheres"] = {k: v for k, v in spheres.items() if k not in SPHERE_ENUMERATING_KEYS}
    return settings
