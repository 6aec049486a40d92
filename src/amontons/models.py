"""The contact models: one record each (docs/models.md §2; how to add one:
docs/contributing.md).

A record holds everything the pipeline knows of a model: its name (the config's, the tables'
and the figures'), how a reader names it, the solver's law and route, the scene it needs,
the parameter a scan varies (config key, symbol, unit, sheet column, prior-free range,
chain order) and the timing model's ratio. Every other module asks the records (the scenes
and their checks, the scans, the tables, the verdict, the figures, the accuracy study, the
config schema's allowed values); an architecture test holds model and parameter names to
this module, the configs and the docs.

Pure Python: the workflow reads it while it builds the DAG, without the numerical stack.
"""

from __future__ import annotations

from dataclasses import dataclass

# A scene's kinds (config/scenes): a field solved on a grid (the sphere's map or a periodic
# surface; it can be rendered and compared), or asperity statistics (no field, no optics).
FIELD = "field"
ASPERITY_STATISTICS = "asperity_statistics"


@dataclass(frozen=True)
class Parameter:
    """The model parameter a scene takes and a scan varies.

    ``key``: its name in the config (scene and scan keys), in best.json and in the tables,
    unit in the name; ``symbol`` and ``unit``: how figures and tables write it; ``to_si``:
    the factor from the config unit to SI (a :class:`amontons.simulate.scene.Scene` holds
    it in SI, as ``parameter_si``); ``law_field``: the solver law's
    attribute that holds it (SI, the law's first argument); ``sheet_column``: the sample
    sheet's column of its prior (config/materials.tsv); ``stem``: verdict.csv's column stem;
    ``prior_free_scale``: the dimensionless group a scan without a prior runs over
    (docs/study.md §2), E*/Δx^``prior_free_pixel_power`` in the parameter's unit, Δx the
    solver pixel; ``chain_order``: +1 where a scan solves its values from the smallest
    up, -1 from the largest down (each value warm-starts the next, from the elastic end's
    side: docs/study.md §1); ``description``: the config schema's words for the key."""

    key: str
    symbol: str
    unit: str
    to_si: float
    law_field: str
    sheet_column: str
    stem: str
    prior_free_scale: str
    prior_free_pixel_power: int
    chain_order: int
    description: str

    @property
    def from_si(self) -> float:
        """The factor from SI to the config unit (the inverse of ``to_si``, as a product)."""
        return 1.0 / self.to_si

    @property
    def label(self) -> str:
        """The parameter with its unit, as an axis says it: ``k (MPa/nm)``."""
        return f"{self.symbol} ({self.unit})"


@dataclass(frozen=True)
class ContactModel:
    """One contact model (docs/models.md §2).

    ``name``: the config's and the tables' name; ``label``: a reader's name for it;
    ``law``: the solver's plasticity law (a class of :mod:`amontons.contact`; None: no
    plastic loop); ``route``: the solver route it takes with local increments (the
    volume-conserving increments take the appendix's route; :mod:`amontons.contact.routes`);
    ``kind``: the scene it needs (:data:`FIELD` or :data:`ASPERITY_STATISTICS`);
    ``parameter``: the parameter it takes from the scene or the sheet, None for none;
    ``timing_ratio``: the dimensionless ratio its convolution count follows in the timing
    model (amontons.accuracy.timing; None: the elastic count); ``verdict_rank``: where the
    study's verdict lists it (docs/study.md §4)."""

    name: str
    label: str
    law: str | None
    route: str
    kind: str
    parameter: Parameter | None
    timing_ratio: str | None
    verdict_rank: int


GREENWOOD_TRIPP = ContactModel(
    name="greenwood_tripp",
    label="Greenwood–Tripp",
    law=None,
    route="greenwood_tripp",
    kind=ASPERITY_STATISTICS,
    parameter=None,
    timing_ratio=None,
    verdict_rank=3,
)
ELASTIC = ContactModel(
    name="elastic",
    label="elastic",
    law=None,
    route="elastic",
    kind=FIELD,
    parameter=None,
    timing_ratio=None,
    verdict_rank=1,
)
PENETRATION_HARDNESS = ContactModel(
    name="penetration_hardness",
    label="penetration hardness",
    law="PenetrationHardness",
    route="bounded",
    kind=FIELD,
    parameter=Parameter(
        key="p_y_mpa",
        symbol="p_Y",
        unit="MPa",
        to_si=1e6,
        law_field="p_y",
        sheet_column="hardness_mpa",
        stem="p_y",
        prior_free_scale="p_Y/E*",
        prior_free_pixel_power=0,
        chain_order=-1,
        description="Penetration hardness p_Y, MPa",
    ),
    timing_ratio="yield_ratio",
    verdict_rank=2,
)
CONTACT_HARDENING = ContactModel(
    name="hardening",
    label="contact hardening",
    law="ContactHardening",
    route="winkler",
    kind=FIELD,
    parameter=Parameter(
        key="k_mpa_per_nm",
        symbol="k",
        unit="MPa/nm",
        to_si=1e15,
        law_field="k",
        sheet_column="hardening_k_mpa_per_nm",
        stem="k",
        prior_free_scale="k·Δx/E*",
        prior_free_pixel_power=1,
        chain_order=+1,
        description="Hardening coefficient k (p_Y = k |h_pl|), MPa/nm",
    ),
    timing_ratio="stiffness_ratio",
    verdict_rank=0,
)

# Every model, simplest first (docs/models.md §2).
MODELS = (GREENWOOD_TRIPP, ELASTIC, PENETRATION_HARDNESS, CONTACT_HARDENING)


class UnknownModelError(ValueError):
    """A model or parameter name no record holds (names it and the known ones)."""


def model_names() -> tuple[str, ...]:
    """Every model's name, simplest first."""
    return tuple(m.name for m in MODELS)


def model_named(name: str) -> ContactModel:
    """The record of the model ``name``."""
    for model in MODELS:
        if model.name == name:
            return model
    raise UnknownModelError(f"model {name!r}; expected one of {', '.join(model_names())}")


def field_model_names() -> tuple[str, ...]:
    """The names of the models solved on a grid (:data:`FIELD`): those a truth can be made
    with, by the virtual experiment or the validation study."""
    return tuple(m.name for m in MODELS if m.kind == FIELD)


def with_parameter() -> tuple[ContactModel, ...]:
    """The models that take a parameter (the ones a scan can vary), simplest first."""
    return tuple(m for m in MODELS if m.parameter is not None)


def parameter_keys() -> tuple[str, ...]:
    """The parameters' config keys, in :func:`with_parameter`'s order."""
    return tuple(m.parameter.key for m in with_parameter())


def model_of_parameter(key: str) -> ContactModel:
    """The model whose parameter's config key is ``key``."""
    for model in with_parameter():
        if model.parameter.key == key:
            return model
    raise UnknownModelError(f"parameter {key!r}; expected one of {', '.join(parameter_keys())}")


def parameter_named(key: str) -> Parameter:
    """The parameter whose config key is ``key``."""
    return model_of_parameter(key).parameter


def in_verdict_order() -> tuple[ContactModel, ...]:
    """The models in the order the study's verdict lists them (docs/study.md §4)."""
    return tuple(sorted(MODELS, key=lambda m: m.verdict_rank))


def timed() -> tuple[ContactModel, ...]:
    """The models the timing model counts apart from the elastic solve, by name (the
    accuracy study's timing points and their fit are in this order)."""
    return tuple(sorted((m for m in MODELS if m.timing_ratio), key=lambda m: m.name))
