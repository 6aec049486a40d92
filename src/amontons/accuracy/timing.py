"""The timing model (docs/accuracy.md, "Timing model"): a solve's wall time and peak memory
from its FFT grid, its contact model and its tolerance, fitted to the accuracy study's
measured points. :func:`predict` is pure Python (the workflow sizes jobs with it while it
builds the DAG); amontons.accuracy.timing_fit fits it, with numpy.

Per load series of L loads on an FFT grid of N points (n² periodic, the padded (2n)²-ish
grid of a window otherwise):

    convolutions per load  C_el = exp(b0 + b_p·[periodic] + b1·log10(1/tol) + b2·ln P)
                                                                          (elastic)
                           C    = C_el · exp(a) · (z / (1 + z))^γ            (plastic models)
    wall time              t = c_0 + c_conv·L·C·N·log2 N
    peak memory            m = m0 + m1·N

P is the number of pixels the contact can cover: the whole grid n² of a periodic surface,
(D/Δx)² on a sphere, D its Hertz contact diameter at the largest load and Δx the pixel (CG
iterations grow with the contact's extent in pixels, not with the empty window around it).
A convolution (one FFT pair) is the unit of work: a CG iteration costs one or two of them
depending on the route, and each load adds a few of its own (the approach search), so
counting convolutions rather than iterations keeps one cost per unit across models.

z is the dimensionless number that decides how far a plastic solve departs from the elastic
one (docs/accuracy.md §6):

- contact hardening, the stiffness ratio s = 2kΔx/(πE*): the Winkler layer of stiffness k
  against the half-space's stiffness at the pixel scale. The operator K + 1/k is better
  conditioned the softer the layer (small s: few iterations); s ≫ 1 is the elastic limit.
- penetration hardness, the yield ratio y = p_Y/(E*·h'_rms/2): the yield pressure against a
  rough surface's elastic mean contact pressure. At small y most contact points sit at the
  bound and the CG works on the few free ones; y ≫ 1 is the elastic limit.

Where z is not known (None: a dry run before the AFM map's slope is measured) the model
takes z/(1+z) = 1, the elastic limit, which over-predicts soft layers and low yield ratios.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from amontons.measured_resources import fft_points
from amontons.models import ELASTIC, model_named


def stiffness_ratio(k_pa_per_m: float, pixel_m: float, e_star_pa: float) -> float:
    """s = 2kΔx/(πE*): a hardening layer's stiffness k (Pa/m) over the half-space's at the
    pixel Δx (m), E* (Pa)."""
    return 2.0 * k_pa_per_m * pixel_m / (math.pi * e_star_pa)


def yield_ratio(p_y_pa: float, e_star_pa: float, slope_rms: float) -> float:
    """y = p_Y/(E*·h'_rms/2): the yield pressure (Pa) over a rough surface's elastic mean
    contact pressure, from E* (Pa) and the rms slope at the solver pixel."""
    return p_y_pa / (0.5 * e_star_pa * slope_rms)


def _stiffness_ratio_at(value: float, *, pixel_m: float, e_star_pa: float, slope_rms):
    return stiffness_ratio(value, pixel_m, e_star_pa)


def _yield_ratio_at(value: float, *, pixel_m: float, e_star_pa: float, slope_rms):
    return yield_ratio(value, e_star_pa, slope_rms) if slope_rms else None


# A model's timing ratio (amontons.models: ContactModel.timing_ratio) as a function of its
# parameter's SI value, the pixel (m), E* (Pa) and the rms slope (None where unknown).
RATIOS = {"stiffness_ratio": _stiffness_ratio_at, "yield_ratio": _yield_ratio_at}


def plastic_ratio(
    model: str,
    *,
    pixel_m: float,
    e_star_pa: float,
    slope_rms: float | None = None,
    parameter_si: float | None = None,
) -> float | None:
    """The dimensionless ratio z of a solve under ``model`` (its record's timing ratio,
    amontons.models), its parameter in SI (hardening k Pa/m, penetration hardness p_Y Pa);
    None for a model without one, or where the parameter or the slope is not known (the
    elastic limit)."""
    record = model_named(model)
    if record.timing_ratio is None or not parameter_si:
        return None
    at = RATIOS[record.timing_ratio]
    return at(parameter_si, pixel_m=pixel_m, e_star_pa=e_star_pa, slope_rms=slope_rms)


def parameter_at_ratio(
    model: str, ratio: float, *, pixel_m: float, e_star_pa: float, slope_rms: float
) -> float:
    """The parameter (SI) of the plastic law whose ratio is ``ratio``: hardening k =
    s·πE*/(2Δx) (Pa/m), penetration hardness p_Y = y·E*·h'_rms/2 (Pa)."""
    record = model_named(model)
    if record.timing_ratio is None:
        raise ValueError(f"no plastic ratio for model {model!r}")
    unit = RATIOS[record.timing_ratio](
        1.0, pixel_m=pixel_m, e_star_pa=e_star_pa, slope_rms=slope_rms
    )
    return ratio / unit


def convolutions_per_load(
    record: Mapping,
    model: str,
    *,
    tol: float,
    periodic: bool,
    contact_px: float,
    ratio: float | None = None,
) -> float:
    """Predicted convolutions per load of ``model`` at ``tol``, the contact ``contact_px``
    pixels across (a periodic surface: its side), its dimensionless ``ratio`` z (None: the
    elastic limit). A model the study did not measure takes the elastic count."""
    coef = record["convolutions"][ELASTIC.name]["coef"]
    features = _elastic_features(tol, periodic, contact_px)
    count = math.exp(sum(c * f for c, f in zip(coef, features, strict=True)))
    plastic = record["convolutions"].get(model)
    if model_named(model).timing_ratio is None or plastic is None:
        return count
    share = 1.0 if ratio is None else ratio / (1.0 + ratio)
    return count * math.exp(plastic["offset"]) * share ** plastic["gamma"]


def predict(
    record: Mapping,
    model: str,
    *,
    side_px: int,
    periodic: bool,
    loads: int,
    tol: float,
    contact_px: float | None = None,
    ratio: float | None = None,
) -> tuple[float, float]:
    """(wall time s, peak memory MB) of a load series of ``loads`` loads of ``model`` on a
    ``side_px`` grid at ``tol``: ``contact_px`` the Hertz contact diameter at the largest load
    in pixels (None or periodic: the grid's side), ``ratio`` its z (:func:`plastic_ratio`;
    None: the elastic limit). ``record``: the JSON that
    amontons.accuracy.timing_fit.fit_timing_model writes."""
    points = fft_points(side_px, periodic)
    extent = side_px if periodic or contact_px is None else contact_px
    count = loads * convolutions_per_load(
        record, model, tol=tol, periodic=periodic, contact_px=extent, ratio=ratio
    )
    time = record["time"]
    seconds = time["c_0"] + time["c_conv"] * count * points * math.log2(points)
    memory = record["memory"]
    return seconds, memory["m0"] + memory["m1"] * points


def _elastic_features(tol: float, periodic: bool, contact_px: float) -> list[float]:
    return [1.0, float(periodic), math.log10(1.0 / tol), 2.0 * math.log(contact_px)]


def point_features(point: Mapping) -> list[float]:
    """The elastic count's features of a measured point (amontons.accuracy.timing_fit)."""
    return _elastic_features(point["tol"], point["periodic"], point["contact_px"])
