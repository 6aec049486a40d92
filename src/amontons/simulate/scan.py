"""Parameter scans of a contact model against the measured contact (docs/study.md).

A scan presses one sphere's AFM map under one model (its *base scene*) at a grid of values of
the model's single material parameter, the penetration hardness p_Y or the hardening
coefficient k (appendix Fig. B.8). Each value's contact is rendered like the microscope sees
it and thresholded by Otsu, load by load.

Criterion: the best value minimises the root-mean-square distance between the logarithms of
the rendered and the measured Otsu areas over every load where the measured image shows a
contact,

    D(v) = sqrt( mean_i [ ln A_sim,i(v) - ln A_meas,i ]² ),

so that a 10 % miss weighs the same at 25 and at 300 mN and the exponent and the prefactor of
the load-area law are fitted together. Two values within ``TIE`` of the same D (a model whose
areas no longer depend on its parameter) are told apart by the IoU of the masks at the
largest load.

A sphere's scan is one job that solves its values one after another (docs/study.md §1;
:mod:`amontons.simulate.scan_job`): this module holds what one value needs, the base scene's
config at the value and the criterion D. Judging the scan from its values is
:mod:`amontons.simulate.scan_best`; reading and wording its best.json,
:mod:`amontons.simulate.scan_record`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from amontons.models import UnknownModelError, model_of_parameter, parameter_keys
from amontons.simulate.scan_grid import ScanError

__all__ = ["ScanError", "log_area_distance", "scene_config_at"]


def scene_config_at(base: Mapping, parameter: str, value: float) -> dict:
    """The base scene's config with the scanned parameter (its config key, amontons.models)
    set to ``value``."""
    try:
        model = model_of_parameter(parameter).name
    except UnknownModelError as exc:
        raise ScanError(
            f"parameter = {parameter!r}; expected one of {list(parameter_keys())}"
        ) from exc
    if base["model"] != model:
        raise ScanError(
            f"parameter {parameter} belongs to model {model!r}, but the base "
            f"scene's model is {base['model']!r}"
        )
    return {**base, parameter: float(value)}


def log_area_distance(simulated_m2: Sequence[float], measured_m2: Sequence[float]) -> float:
    """D: root-mean-square difference of ln(simulated) and ln(measured) areas."""
    sim = np.asarray(simulated_m2, dtype=float)
    meas = np.asarray(measured_m2, dtype=float)
    if sim.shape != meas.shape or sim.size == 0:
        raise ScanError(f"{sim.size} simulated against {meas.size} measured areas")
    if np.any(sim <= 0) or np.any(meas <= 0):
        return float("inf")  # a load with no simulated contact matches nothing
    return float(np.sqrt(np.mean((np.log(sim) - np.log(meas)) ** 2)))
