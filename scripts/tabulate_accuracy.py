"""Rule tabulate_accuracy: every problem at every setting with its cost and its errors against
its reference, the Pareto flags, and the presets the fronts propose (docs/accuracy.md)."""

import logging

from amontons.accuracy.front import accuracy_table, propose_presets
from amontons.io.fields import read_load_series
from amontons.io.files import read_json, write_json, write_table
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    summary_paths: list,
    field_paths: list,
    budgets: dict,
    preset_problems: list,
    table_path: str,
    presets_path: str,
) -> None:
    summaries = [read_json(path) for path in summary_paths]
    pressures = {}
    for path in field_paths:
        fields, _, settings = read_load_series(path)
        pressures[(settings["problem"], settings["setting"])] = [f["pressure"] for f in fields]
    table = accuracy_table(summaries, pressures)
    presets = propose_presets(table, budgets, preset_problems)
    for name, preset in presets.items():
        if preset is None:
            log.warning("preset %s: no setting meets its budget %s", name, budgets[name])
        else:
            log.info("preset %s: %s (%.1f s)", name, preset["setting"], preset["wall_time_s"])
    write_table(table_path, table)
    write_json(
        presets_path,
        {
            "rule": "the cheapest setting (wall time summed over the problems) whose errors "
            "are all within the preset's budget on every problem",
            "problems": preset_problems,
            "presets": presets,
        },
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        summary_paths=list(sm.input.summaries),
        field_paths=list(sm.input.fields),
        budgets=sm.params.budgets,
        preset_problems=sm.params.preset_problems,
        table_path=sm.output.table,
        presets_path=sm.output.presets,
    )
