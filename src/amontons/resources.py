"""What a job of the workflow needs on a cluster, from measured runs (README, "On a cluster").

`benchmarks/fit_job_resources.py` reads the benchmark files Snakemake writes for every job of
a run (`logs/<run>/**/*.benchmark.tsv`: wall time and peak resident memory) and writes
`workflow/resources.json`:

* for most rules, the largest wall time and peak memory any of their jobs took;
* for the rules that solve a contact problem (simulate_scene, simulate_synthetic_scene,
  scan_scene), a model in the size of the FFT grid the solver works on (N points: n² for a
  periodic window, (2n)² for a non-periodic one, Hockney padding) and in the number of loads
  L, per contact model:

      wall time ≈ c_t · L · N            memory ≈ m_0 + m_1 · N

  with c_t the largest measured time per load and grid point, and (m_0, m_1) the line under
  which no measured job's memory lies above by more than its own measurement (the largest
  m_1 · N excess over the baseline m_0 of the process).

The workflow asks for ``SAFETY`` × these (a cluster kills a job at its limit; the machine the
figures were taken on may be faster than the cluster's nodes), rounded up, with floors. This
module is pure Python: the DAG is built without the numerical stack.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path

SAFETY = 2.0
MIN_RUNTIME_MIN = 2
MIN_MEM_MB = 500
GRID_RULES = ("simulate_scene", "simulate_synthetic_scene", "scan_scene")


class ResourceError(KeyError):
    """A rule or model the measured resources do not cover."""


def fft_points(side_px: int, periodic: bool) -> int:
    """Points of the FFT grid a solve on an n × n window works on."""
    return side_px**2 if periodic else (2 * side_px) ** 2


def _minutes(seconds: float) -> int:
    return max(MIN_RUNTIME_MIN, math.ceil(SAFETY * seconds / 60))


def _megabytes(mb: float) -> int:
    return max(MIN_MEM_MB, math.ceil(SAFETY * mb / 100) * 100)


class JobResources:
    """The measured resources of `workflow/resources.json` (see the module docstring)."""

    def __init__(self, record: Mapping, source: str = "workflow/resources.json"):
        self.record = record
        self.source = source

    @classmethod
    def from_file(cls, path: str | Path) -> JobResources:
        with open(path, encoding="utf-8") as stream:
            return cls(json.load(stream), str(path))

    def _rule(self, rule: str) -> Mapping:
        try:
            return self.record["rules"][rule]
        except KeyError:
            raise ResourceError(
                f"{self.source}: no measured resources of rule {rule}; re-run "
                "benchmarks/fit_job_resources.py on a run that has its jobs"
            ) from None

    def _grid(self, rule: str, model: str) -> Mapping:
        try:
            return self.record["grid_rules"][rule][model]
        except KeyError:
            raise ResourceError(
                f"{self.source}: no measured grid model of rule {rule} for contact model "
                f"{model}; re-run benchmarks/fit_job_resources.py on a run that has such jobs"
            ) from None

    def runtime_min(self, rule: str) -> int:
        """Minutes to ask for a job of ``rule``."""
        return _minutes(self._rule(rule)["max_s"])

    def mem_mb(self, rule: str) -> int:
        """Megabytes to ask for a job of ``rule``."""
        return _megabytes(self._rule(rule)["max_rss_mb"])

    def grid_runtime_min(self, rule: str, model: str, points: int, loads: int) -> int:
        """Minutes for a solve of ``loads`` loads on an FFT grid of ``points`` points."""
        return _minutes(self._grid(rule, model)["s_per_load_point"] * loads * points)

    def grid_mem_mb(self, rule: str, model: str, points: int) -> int:
        """Megabytes for a solve on an FFT grid of ``points`` points."""
        grid = self._grid(rule, model)
        return _megabytes(grid["base_mb"] + grid["mb_per_point"] * points)
