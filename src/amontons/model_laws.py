"""A model record's plasticity law at a value: the one place that joins the records
(amontons.models, pure Python, read while the workflow builds its DAG) to the solver's law
classes (amontons.contact.laws). The scenes, the virtual experiment and the validation
study's truths build their laws here."""

from __future__ import annotations

from amontons.contact import laws
from amontons.models import model_named


def law_of(model: str, value: float | None, **options):
    """The plasticity law of ``model`` at ``value`` in the record's config unit (p_y_mpa,
    k_mpa_per_nm), SI, with the law's ``options`` (increment, alpha); None for a model
    without a law (elastic)."""
    record = model_named(model)
    if record.law is None:
        return None
    return law_si(model, value * record.parameter.to_si, **options)


def law_si(model: str, value_si: float | None, **options):
    """The plasticity law of ``model`` at ``value_si``, its parameter in SI (Pa, Pa/m); None
    for a model without a law (elastic, Greenwood–Tripp)."""
    law = model_named(model).law
    return None if law is None else getattr(laws, law)(value_si, **options)
