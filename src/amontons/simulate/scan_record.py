"""A scan's best.json read back and put in words (docs/study.md §1, §6): whether it is decided,
its estimate as model-table columns, and the sentences figures and tables state it in. Pure
Python: a figure or a table that only reads the record imports no statistics."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.models import parameter_named

# best.json's key that holds why a scan was not decided (amontons.simulate.scan_best), and
# how the model table's source names such a scan.
NOT_DECIDED = "not_decided"
NOT_DECIDED_SOURCE = "not decided"


def symbol_and_unit(best: Mapping) -> tuple[str, str]:
    """How figures and tables write a best.json record's parameter: symbol and unit."""
    parameter = parameter_named(best["parameter"])
    return parameter.symbol, parameter.unit


def is_decided(best: Mapping) -> bool:
    """Whether a best.json record holds a judgement (else :data:`NOT_DECIDED` says why)."""
    return NOT_DECIDED not in best


def held_no_load(best: Mapping) -> bool:
    """Whether a scan not decided solved nothing (its AFM scan held no load's window), as
    against one that solved its values but holds too few loads to judge them."""
    return not is_decided(best) and "largest_window_in_scan_um" in best


def not_decided_note(best: Mapping) -> str:
    """Why a scan is not decided, in a few words for a figure."""
    return "no load in the scan" if held_no_load(best) else "too few loads to judge"


# best.json's numbers the verdict judges the models by (docs/study.md §6), as model-table
# columns of a scan's row: χ² under the measured scatter at the best value, at the scan's
# elastic end and of the elastic model itself with its own error, the quantile's rise and
# the loads it counts.
JUDGEMENT_COLUMNS = {
    "chi2_min_measured_sd": "chi2_best",
    "chi2_elastic_end_measured_sd": "chi2_elastic_end",
    "chi2_elastic_measured_sd": "chi2_elastic",
    "chi2_rise": "chi2_rise",
    "n_loads": "n_loads",
}


def estimate_columns(best: Mapping | None) -> dict:
    """A scan's estimate and the interval that belongs to it, and the χ² the verdict judges
    by (:data:`JUDGEMENT_COLUMNS`), as model-table columns, from its best.json record
    (``None``, for a scene's row, or a scan not decided: empty columns). The interval's ends
    are ``None`` where it is open at the scan's end."""
    if best is None or not is_decided(best):
        empty = ("estimate", "estimate_low", "estimate_high", *JUDGEMENT_COLUMNS.values())
        return dict.fromkeys(empty)
    low, high = best["interval"]
    return {
        "estimate": best["estimate"],
        "estimate_low": low,
        "estimate_high": high,
        **{column: best.get(key) for key, column in JUDGEMENT_COLUMNS.items()},
    }


def significant(value: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant digits, in plain notation where it is short
    (4.47, 0.447, 2170, 40000)."""
    return f"{float(f'{value:.{digits}g}'):g}"


def interval_text(low: float | None, high: float | None) -> str:
    """A scan's interval as '4.61–6.13'; with an end the scan does not bound, '≥ 2170' or
    '≤ 214' (a bound), and with neither, 'not bounded by the scan'."""
    if low is None and high is None:
        return "not bounded by the scan"
    if high is None:
        return f"≥ {significant(low)}"
    if low is None:
        return f"≤ {significant(high)}"
    return f"{significant(low)}–{significant(high)}"


def is_bound(low: float | None, high: float | None) -> bool:
    """Whether an interval reaches a scan's end on one side or both: then it is stated as
    the bound it is, not as an interval."""
    return low is None or high is None


def estimate_text(best: Mapping) -> str:
    """A best.json record as figures and tables state it: the parameter's estimate with its
    interval at its confidence, or, where the interval reaches the scan's end, the bound the
    data set; and the grid's best named as such ('k = 5.31 MPa/nm (95% interval 4.61–6.13;
    grid's best 4.47)', 'k ≥ 2170 MPa/nm (95% bound, open at the scan's end; grid's best
    40000)')."""
    symbol, unit = symbol_and_unit(best)
    low, high = best["interval"]
    grid = f"grid's best {significant(best['grid_best'])}"
    if is_bound(low, high):
        return (
            f"{symbol} {interval_text(low, high)} {unit} ({best['confidence']:.0%} bound, open "
            f"at the scan's end; {grid})"
        )
    return (
        f"{symbol} = {significant(best['estimate'])} {unit} ({best['confidence']:.0%} interval "
        f"{interval_text(low, high)}; {grid})"
    )


def grid_best_text(best: Mapping) -> str:
    """The grid's best value of a best.json record, for a figure that shows the model there,
    with the estimate and its interval, or the bound, beside it ("the grid's best k = 4.47
    MPa/nm (estimate 5.31, 95% interval 4.61–6.13)")."""
    symbol, unit = symbol_and_unit(best)
    low, high = best["interval"]
    grid = f"the grid's best {symbol} = {significant(best['grid_best'])} {unit}"
    if is_bound(low, high):
        return f"{grid} ({best['confidence']:.0%} bound {symbol} {interval_text(low, high)})"
    return (
        f"{grid} (estimate {significant(best['estimate'])}, {best['confidence']:.0%} interval "
        f"{interval_text(low, high)})"
    )


def grid_best_label(best: Mapping) -> str:
    """The grid's best value of a best.json record, short, for a legend or a panel
    ("grid's best k = 4.47 MPa/nm")."""
    symbol, unit = symbol_and_unit(best)
    return f"grid's best {symbol} = {significant(best['grid_best'])} {unit}"
