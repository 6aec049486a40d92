"""Spheres held out of a run's results and tables by an earlier run's failed jobs
(amontons.workflow.ledger), until their files, their sheet row or the config change, or
the job succeeds."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.workflow.failures import FailedJob
from amontons.workflow.sheet_rows import SheetRows


class HoldOuts:
    """The held-out spheres of the run: ``jobs`` maps each to the failed jobs of an earlier
    run that hold it out (none held out until :meth:`hold_out`)."""

    def __init__(self, rows: SheetRows):
        self.rows = rows
        self.jobs: dict[str, list[FailedJob]] = {}

    def hold_out(self, failed: Mapping[str, list[FailedJob]]) -> None:
        """Hold spheres out of the run's results and tables, each with the failed jobs of an
        earlier run that hold it out (amontons.workflow.ledger)."""
        unknown = set(failed) - set(self.rows.records)
        if unknown:
            raise ValueError(f"cannot hold out spheres not in the run: {sorted(unknown)}")
        self.jobs = {sphere: list(jobs) for sphere, jobs in failed.items()}

    def failed_lines(self, sphere: str) -> list[str]:
        """Why a held-out sphere is out of its material's tables: one line per failed job,
        with its error and log (none for a sphere not held out)."""
        material = self.rows.material_of(sphere)
        return [
            f"failed in an earlier run: {job.rule}: {job.error or 'see its log'} [{job.log}]; "
            f"held out of {material}'s tables, figures, summary and report until its files, "
            "its sheet row or the config change, or the job succeeds"
            for job in self.jobs.get(sphere, [])
        ]
