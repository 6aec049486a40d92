"""The study's answer in one table (docs/study.md §6): per sphere, the measured load-area
exponent, each contact model's exponent and area ratio, the scans' estimates of k and p_Y with
their intervals, and which models give the measured exponent. Read from the model tables
(``models.csv``, amontons.simulate.tables.model_table_rows) and written as ``verdict.csv``; the
report's first page (``report_page``) and ``summary.md`` (``summary_markdown``) show it.

Exponents are dimensionless; k is in MPa/nm and p_Y in MPa; area ratios are simulated over
measured Otsu area at the largest load.
"""

from __future__ import annotations

import base64
import math
import textwrap
import urllib.parse
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from amontons.models import in_verdict_order, model_of_parameter, parameter_named, with_parameter
from amontons.simulate.scan_record import (
    JUDGEMENT_COLUMNS,
    NOT_DECIDED,
    NOT_DECIDED_SOURCE,
    interval_text,
    is_bound,
    is_decided,
    significant,
    symbol_and_unit,
)
from amontons.study.decision import ELASTIC, Decision, decide

# The models of the verdict, in the order the study discusses them (docs/study.md §4), and
# how a reader names them.
MODELS = {model.name: model.label for model in in_verdict_order()}
# The scanned parameter of each plastic model.
MODEL_PARAMETERS = {model.name: model.parameter.key for model in with_parameter()}
# The model-table columns the verdict reads.
MODEL_TABLE_COLUMNS = (
    "sphere",
    "model",
    "source",
    "value",
    "estimate",
    "estimate_low",
    "estimate_high",
    "exponent",
    "exponent_difference",
    "measured_exponent",
    "measured_ci_low",
    "measured_ci_high",
    "area_ratio_largest",
    *JUDGEMENT_COLUMNS.values(),
)
# The section of the summary and the report that names the spheres a failed job holds out.
FAILED_TITLE = "Failed: held out of every table and figure"


class SummaryError(ValueError):
    """A model table that cannot give the verdict (the message names the file)."""


def _present(cell) -> bool:
    return cell is not None and not (isinstance(cell, float) and math.isnan(cell))


def _cell(cell):
    """A table cell as a JSON/CSV value: None for an empty (NaN) cell."""
    return cell if _present(cell) else None


def model_row(rows: pd.DataFrame, model: str) -> pd.Series | None:
    """The row of ``model`` in one sphere's rows of a model table: its scan's best value where
    the model was scanned, else its first scene (None where the table has neither)."""
    own = rows[rows["model"] == model]
    scanned = own[own["source"].str.startswith("scan ")]
    chosen = scanned if len(scanned) else own
    return None if chosen.empty else chosen.iloc[0]


def matching_models(row: Mapping) -> list[str]:
    """The models of a verdict row whose exponent lies inside the measured exponent's
    interval (both ends included)."""
    low, high = row["measured_ci_low"], row["measured_ci_high"]
    return [
        model
        for model in MODELS
        if _present(row.get(f"{model}_exponent")) and low <= row[f"{model}_exponent"] <= high
    ]


def verdict_rows(table: pd.DataFrame, material: str, source: str) -> list[dict]:
    """One verdict row per sphere of a material's model table (``source``: its path, for the
    error). Columns: the measured exponent and its interval; per model, its exponent, the
    difference from the measured one, the area ratio at the largest load and the table row
    it comes from; per scanned parameter, the estimate, its interval (None: open) and the
    grid's best; and ``matching``: the models whose exponent lies inside the measured
    interval, ';'-separated."""
    missing = set(MODEL_TABLE_COLUMNS) - set(table)
    if missing:
        raise SummaryError(
            f"{source}: no column {sorted(missing)}; expected a models.csv of rule "
            "tabulate_models with the scans' estimates (one written before them: rerun it, "
            "snakemake --forcerun best_scan_value)"
        )
    rows = []
    for sphere, own in table.groupby("sphere", sort=False):
        first = own.iloc[0]
        row = {
            "material": material,
            "sphere": sphere,
            "measured_exponent": first["measured_exponent"],
            "measured_ci_low": first["measured_ci_low"],
            "measured_ci_high": first["measured_ci_high"],
        }
        for model in MODELS:
            chosen = model_row(own, model)
            row[f"{model}_exponent"] = None if chosen is None else chosen["exponent"]
            row[f"{model}_exponent_difference"] = (
                None if chosen is None else chosen["exponent_difference"]
            )
            row[f"{model}_area_ratio"] = (
                None if chosen is None else _cell(chosen["area_ratio_largest"])
            )
            row[f"{model}_source"] = None if chosen is None else chosen["source"]
        for model, parameter in MODEL_PARAMETERS.items():
            stem = parameter_named(parameter).stem
            chosen = model_row(own, model)
            scanned = chosen is not None and chosen["source"].startswith("scan ")
            for column, key in (
                ("estimate", "estimate"),
                ("low", "estimate_low"),
                ("high", "estimate_high"),
                ("grid_best", "value"),
                ("chi2_best", "chi2_best"),
                ("chi2_elastic_end", "chi2_elastic_end"),
                ("chi2_elastic", "chi2_elastic"),
            ):
                row[f"{stem}_{column}"] = _cell(chosen[key]) if scanned else None
        row["matching"] = ";".join(matching_models(row))
        decision = model_decision(row, own)
        row["decided"] = ";".join(decision.kept)
        row["decided_why"] = decision.why
        if decision.elastic:
            state_as_bounds(row)
        rows.append(row)
    return rows


def state_as_bounds(row: dict) -> None:
    """Where the answer is elastic, each scanned parameter as the one-sided bound the data
    set: its interval's lower end, no estimate and no upper end (the elastic limit, the
    parameter → ∞, is kept)."""
    for parameter in MODEL_PARAMETERS.values():
        stem = parameter_named(parameter).stem
        row[f"{stem}_estimate"] = None
        row[f"{stem}_high"] = None


def model_decision(row: Mapping, own: pd.DataFrame) -> Decision:
    """The decision between the models a verdict row's scans judged
    (:func:`amontons.study.decision.decide`), from their χ² columns (``own``: the sphere's
    model-table rows, for the quantile and the loads)."""
    best, elastic_end, elastic = {}, {}, {}
    for model, parameter in MODEL_PARAMETERS.items():
        stem = parameter_named(parameter).stem
        if _present(row[f"{stem}_chi2_best"]):
            best[model] = row[f"{stem}_chi2_best"]
            elastic_end[model] = _cell(row[f"{stem}_chi2_elastic_end"])
            elastic[model] = _cell(row[f"{stem}_chi2_elastic"])
    judged = own[own["chi2_rise"].notna()]  # verdict_rows has checked the column is there
    if judged.empty:
        return decide({}, {}, float("nan"), 0)
    # the larger of the scans' quantiles: a model is excluded only where both would exclude it
    return decide(
        best, elastic_end, judged["chi2_rise"].max(), int(judged["n_loads"].min()), elastic
    )


def verdict_table(tables: Mapping[str, str]) -> pd.DataFrame:
    """The verdict of every material: ``tables`` maps a material to its models.csv path."""
    rows = []
    for material, path in tables.items():
        rows += verdict_rows(pd.read_csv(path), material, path)
    return pd.DataFrame(rows)


def _signed(value: float) -> str:
    """``value`` to 3 decimals with its sign, a typographic minus for a reader's table."""
    return f"{value:+.3f}".replace("-", "−")


def _exponent_text(value, difference) -> str:
    return f"{value:.3f} ({_signed(difference)})"


def _not_decided(row: Mapping, model: str) -> bool:
    """Whether a verdict row's ``model`` comes from a scan that was not decided (its AFM
    scan held no load: amontons.simulate.scan_best.not_decided_record)."""
    source = row.get(f"{model}_source")
    return isinstance(source, str) and source.endswith(NOT_DECIDED_SOURCE)


def model_text(row: Mapping, model: str) -> str:
    """A verdict row's cell for ``model``: exponent, its difference from the measured one,
    and the area ratio at the largest load where the model is rendered."""
    value = row.get(f"{model}_exponent")
    if not _present(value):
        return NOT_DECIDED_SOURCE if _not_decided(row, model) else "not run"
    text = _exponent_text(value, row[f"{model}_exponent_difference"])
    ratio = row.get(f"{model}_area_ratio")
    return text if not _present(ratio) else f"{text}, area ×{ratio:.2f}"


def parameter_text(row: Mapping, parameter: str) -> str:
    """A verdict row's cell for a scanned parameter: estimate, interval, grid's best."""
    stem = parameter_named(parameter).stem
    estimate = row.get(f"{stem}_estimate")
    if not _present(row.get(f"{stem}_grid_best")):  # a bound has no estimate, a scan a grid
        return (
            NOT_DECIDED_SOURCE
            if _not_decided(row, model_of_parameter(parameter).name)
            else "not scanned"
        )
    low, high = (_cell(row[f"{stem}_{end}"]) for end in ("low", "high"))
    grid = f"grid's best {significant(row[f'{stem}_grid_best'])}"
    if is_bound(low, high):
        return f"{interval_text(low, high)} (bound); {grid}"
    return f"{significant(estimate)} ({interval_text(low, high)}); {grid}"


def _model_names(cell) -> list[str]:
    """A verdict cell of ';'-separated models as readers name them (an empty cell, which a
    CSV reads back as NaN: none)."""
    return [MODELS[m] for m in cell.split(";") if m] if isinstance(cell, str) else []


def verdict_text(row: Mapping) -> str:
    """Which models give the measured exponent, in words."""
    matching = _model_names(row["matching"])
    if not matching:
        return "no model"
    if len(matching) == 1:
        return f"{matching[0]} only"
    return f"{', '.join(matching)}: not decided"


def bounds_text(row: Mapping) -> str:
    """Each scanned parameter's one-sided bound in a verdict row ('p_Y ≥ 117 MPa'), or that
    its scan does not bound it."""
    parts = []
    for parameter in MODEL_PARAMETERS.values():
        own = parameter_named(parameter)
        if not _present(row.get(f"{own.stem}_chi2_best")):
            continue
        low = _cell(row.get(f"{own.stem}_low"))
        parts.append(
            f"{own.symbol} not bounded by the scan"
            if low is None
            else f"{own.symbol} ≥ {significant(low)} {own.unit}"
        )
    return ", ".join(parts)


def decided_text(row: Mapping) -> str:
    """The decision by the areas at every load, in words: the one model the data name (elastic
    with each plastic parameter's bound), or 'not decided' with the models they cannot tell
    apart (an empty cell: no scan judged)."""
    kept = _model_names(row.get("decided"))
    if not kept:
        return "no scan judged"
    if row.get("decided") == ELASTIC:
        bounds = bounds_text(row)
        return f"{kept[0]}: no flow detected" + (f", {bounds}" if bounds else "")
    if len(kept) == 1:
        return f"{kept[0]} only"
    return f"not decided: {', '.join(kept)}"


def display_rows(verdict: pd.DataFrame, confidence: float) -> list[list[str]]:
    """The verdict as a reader's table: a header of spheres, then one line per quantity
    (measured exponent, each model, each scanned parameter, the verdict)."""
    records = verdict.to_dict("records")
    lines = [
        [
            "sphere (material)",
            *(
                r["sphere"] if r["sphere"] == r["material"] else f"{r['sphere']} ({r['material']})"
                for r in records
            ),
        ],
        [
            f"measured exponent ({confidence:.0%} interval)",
            *(
                f"{r['measured_exponent']:.3f} ({r['measured_ci_low']:.3f}–"
                f"{r['measured_ci_high']:.3f})"
                for r in records
            ),
        ],
    ]
    for model, name in MODELS.items():
        parameter = MODEL_PARAMETERS.get(model)
        at = "" if parameter is None else f" at the grid's best {parameter_named(parameter).symbol}"
        lines.append([f"{name}{at}", *(model_text(r, model) for r in records)])
    for parameter in MODEL_PARAMETERS.values():
        own = parameter_named(parameter)
        symbol, unit = own.symbol, own.unit
        lines.append(
            [
                f"{symbol} (estimate, {unit}; {confidence:.0%} interval)",
                *(parameter_text(r, parameter) for r in records),
            ]
        )
    lines.append(
        [
            f"exponent inside the measured {confidence:.0%} interval",
            *(verdict_text(r) for r in records),
        ]
    )
    lines.append(
        [
            f"decided by the areas at every load ({confidence:.0%}, scatter and model error)",
            *(decided_text(r) for r in records),
        ]
    )
    return lines


def list_table(lines: Sequence[Sequence[str]], title: str) -> str:
    """reStructuredText list-table of ``lines`` (the first is the header)."""
    out = [f".. list-table:: {title}", "   :header-rows: 1", "   :stub-columns: 1", ""]
    for line in lines:
        for i, cell in enumerate(line):
            out.append(f"   {'*' if i == 0 else ' '} - {cell}")
    return "\n".join(out) + "\n"


@dataclass(frozen=True)
class ReportFigure:
    """A figure the report's first page shows: its PNG, the report's path for it (the key
    that opens its entry), and a caption line."""

    png: str
    caption: str


def _image(figure: ReportFigure) -> str:
    """An rst image of ``figure`` embedded as a data URI (the report is one file), linked to
    the figure's own entry in the report; the URI is broken over lines, which docutils joins
    (its line-length limit is 10,000 characters)."""
    data = base64.b64encode(Path(figure.png).read_bytes()).decode("ascii")
    uri = textwrap.wrap(f"data:image/png;base64,{data}", 76)
    target = f"javascript:app.showResultInfo('{urllib.parse.quote(figure.png)}')"
    return "\n".join(
        [
            f".. figure:: {uri[0]}",
            *(f"   {part}" for part in uri[1:]),
            f"   :alt: {figure.caption}",
            "   :width: 100%",
            f"   :target: {target}",
            "",
            f"   {figure.caption}",
            "",
        ]
    )


def report_page(
    verdict: pd.DataFrame,
    figures: Sequence[ReportFigure],
    confidence: float,
    data_label: str,
    sources: Sequence[str],
    verdict_path: str,
    left_out: Sequence[str] = (),
    failed: Sequence[str] = (),
) -> str:
    """The report's first page (reStructuredText, included by workflow/report/workflow.rst):
    the verdict table (``verdict``, read from ``verdict_path``, made from the model tables
    ``sources``), the spheres held out because a job of theirs failed (``failed``) and what
    the spheres' data did not allow (``left_out``; one line each, so that a missing row or
    figure is never a silent gap), then ``figures`` (Fig. B.13 and each sphere's Fig.
    B.12)."""
    title = f"The answer ({data_label})"
    parts = [
        title,
        "=" * len(title),
        "",
        "Which contact model gives the measured load-area law: per sphere, the measured "
        "exponent, each model's exponent with its difference from the measured one and its "
        "simulated/measured area at the largest load, and the scans' estimates of k and p_Y "
        "with their intervals and the grid's best value, at which the models are shown "
        f"(docs/study.md). The table is {verdict_path}, made from {', '.join(sources)}.",
        "",
        list_table(display_rows(verdict, confidence), "Verdict per sphere"),
        "",
    ]
    if failed:
        parts += [f"{FAILED_TITLE}:", ""]
        parts += [f"- {line}" for line in failed] + [""]
    if left_out:
        parts += ["What the data did not allow:", ""]
        parts += [f"- {line}" for line in left_out] + [""]
    parts += [_image(figure) for figure in figures]
    return "\n".join(parts)


def markdown_table(lines: Sequence[Sequence[str]]) -> str:
    """A Markdown (pipe) table of ``lines`` (the first is the header)."""
    header, *body = lines
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(line) + " |" for line in body]
    return "\n".join(out) + "\n"


@dataclass(frozen=True)
class Headline:
    """One number a user would quote: what it is, its value in words, and where it is read
    (a file, and the key, column or row in it)."""

    what: str
    value: str
    source: str


def measured_headline(sphere: str, fit: Mapping, path: str) -> Headline:
    """The measured load-area exponent of a sphere (load_area_fit.json)."""
    exponent = fit["exponent"]
    return Headline(
        f"{sphere}: measured load-area exponent α (A ∝ F^α)",
        f"{exponent['estimate']:.3f} ({exponent['confidence']:.0%} interval "
        f"{exponent['ci_low']:.3f}–{exponent['ci_high']:.3f}; {fit['n']} loads)",
        f"`{path}`: exponent",
    )


def scan_headline(sphere: str, best: Mapping, path: str, elastic: bool = False) -> Headline:
    """A scan's estimate with its interval and the grid's best (best.json); for a scan not
    decided, why. Where the sphere's answer is ``elastic`` (no flow detected), the scan is
    stated as the verdict states it: its interval's lower end as a bound, with no estimate
    and no upper end (:func:`state_as_bounds`)."""
    if not is_decided(best):
        symbol, unit = symbol_and_unit(best)
        return Headline(
            f"{sphere}: {symbol} of {model_of_parameter(best['parameter']).label} ({unit})",
            f"{NOT_DECIDED_SOURCE}: {best[NOT_DECIDED]}",
            f"`{path}`: {NOT_DECIDED}",
        )
    if "estimate" not in best or "grid_best" not in best:
        raise SummaryError(
            f"{path}: no 'estimate' or 'grid_best'; expected a best.json of rule "
            "best_scan_value that states the scan's estimate (rerun it, snakemake "
            "--forcerun best_scan_value)"
        )
    symbol, unit = symbol_and_unit(best)
    low, high = best["interval"]
    edge = "; the grid's best is at the scan's end" if best["at_scan_edge"] else ""
    grid = f"grid's best {significant(best['grid_best'])}{edge}"
    if elastic:
        value = (
            f"{interval_text(low, None)} ({best['confidence']:.0%} bound; no flow detected, "
            f"the answer is elastic; {grid})"
        )
    elif is_bound(low, high):
        value = f"{interval_text(low, high)} ({best['confidence']:.0%} bound; {grid})"
    else:
        value = (
            f"{significant(best['estimate'])} ({best['confidence']:.0%} interval "
            f"{interval_text(low, high)}; {grid})"
        )
    return Headline(
        f"{sphere}: {symbol} of {model_of_parameter(best['parameter']).label} ({unit})",
        value,
        f"`{path}`: {'interval' if elastic else 'estimate, interval'}, grid_best",
    )


def model_headlines(row: Mapping, verdict_path: str, models_path: str) -> list[Headline]:
    """Each model's exponent against the measured one, and its area ratio, from a verdict
    row (verdict.csv), which names the model-table row it copies."""
    out = []
    for model, name in MODELS.items():
        if not _present(row.get(f"{model}_exponent")):
            continue
        out.append(
            Headline(
                f"{row['sphere']}: {name}, exponent (difference from the measured)",
                model_text(row, model),
                f"`{verdict_path}`: sphere {row['sphere']}, columns {model}_exponent, "
                f"{model}_exponent_difference, {model}_area_ratio (from `{models_path}`, row "
                f"{row[f'{model}_source']!r})",
            )
        )
    if isinstance(row.get("decided"), str) and row["decided"]:
        out.append(
            Headline(
                f"{row['sphere']}: decided by the areas at every load",
                f"{decided_text(row)}: {row['decided_why']}",
                f"`{verdict_path}`: sphere {row['sphere']}, columns decided, decided_why",
            )
        )
    return out


def amontons_headline(sphere: str, table: pd.DataFrame, path: str) -> Headline:
    """How far area and static friction grow over the loads against the load itself
    (amontons.csv: both normalised at the reference load; Amontons' law: as the load)."""
    first, last = table.iloc[0], table.iloc[-1]
    return Headline(
        f"{sphere}: from {first['load_mn']:g} to {last['load_mn']:g} mN",
        f"load ×{last['normal_force_mn'] / first['normal_force_mn']:.2f}, contact area "
        f"×{last['area_over_area_ref'] / first['area_over_area_ref']:.2f}, static friction "
        f"×{last['friction_over_friction_ref'] / first['friction_over_friction_ref']:.2f}",
        f"`{path}`: rows of sphere {sphere}, columns normal_force_mn, area_over_area_ref, "
        "friction_over_friction_ref",
    )


def curvature_headlines(table: pd.DataFrame, path: str) -> list[Headline]:
    """Curved minus flat load-area exponent per model (B10_curvature.csv)."""
    out = []
    for model, rows in table.groupby("model", sort=False):
        exponents = rows.groupby("geometry")["exponent"].first()
        out.append(
            Headline(
                f"synthetic surface, {model}: curved − flat load-area exponent",
                f"{exponents['curved'] - exponents['flat periodic']:+.3f} (curved "
                f"{exponents['curved']:.3f}, flat {exponents['flat periodic']:.3f})",
                f"`{path}`: column exponent, rows of model {model}",
            )
        )
    return out


def summary_markdown(
    run: str,
    data_label: str,
    verdict_lines: Sequence[Sequence[str]] | None,
    verdict_path: str | None,
    headlines: Sequence[Headline],
    left_out: Sequence[str] = (),
    failed: Sequence[str] = (),
) -> str:
    """results/<run>/summary.md: the verdict table (None: the run has no scans, so no
    verdict), the headline numbers, each with the file (and key) it is read from, the spheres
    held out because a job of theirs failed (``failed``, one line per job), and what the
    spheres' data did not allow (``left_out``, one line each), so that no gap is silent."""
    lines = [f"# amontons: run `{run}` ({data_label})", ""]
    if verdict_lines is None:
        lines += ["No scans ran (`run_scans: []`), so no model is judged.", ""]
    else:
        lines += [
            "Which contact model gives the measured load-area law (docs/study.md); the "
            f"table is `{verdict_path}`.",
            "",
            markdown_table(verdict_lines),
        ]
    lines += ["## Headline numbers", "", "Each number names the file it is read from.", ""]
    lines += [f"- **{h.what}**: {h.value}. Source: {h.source}." for h in headlines]
    if failed:
        lines += ["", f"## {FAILED_TITLE}", ""]
        lines += [f"- {line}" for line in failed]
    if left_out:
        lines += ["", "## What the data did not allow", ""]
        lines += [f"- {line}" for line in left_out]
    return "\n".join(lines) + "\n"
