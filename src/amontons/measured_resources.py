"""What a job of the workflow needs on a cluster, from measured runs (docs/cluster.md).

`benchmarks/fit_job_resources.py` reads the benchmark files Snakemake writes for every job of
a run (`logs/<run>/**/*.benchmark.tsv`: wall time and peak resident memory) and writes
`workflow/resources.json`:

for every rule, the largest wall time and peak memory any of its jobs took. The rules that
solve a contact problem (simulate_scene, simulate_synthetic_scene, scan_scene) are sized by
the accuracy study's timing model instead, from their grid, loads and tolerance
(amontons.accuracy.timing, docs/accuracy.md).

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


class ResourceError(KeyError):
    """A rule the measured resources do not cover."""


def fft_points(side_px: int, periodic: bool) -> int:
    """Points of the FFT grid a solve on an n × n window works on (Hockney padding: (2n)²)."""
    return side_px**2 if periodic else (2 * side_px) ** 2


def runtime_min(seconds: float) -> int:
    """Minutes to ask for a job measured or predicted to take ``seconds``."""
    return max(MIN_RUNTIME_MIN, math.ceil(SAFETY * seconds / 60))


def mem_mb_of(mb: float) -> int:
    """Megabytes to ask for a job measured or predicted to peak at ``mb``."""
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

    def runtime_min(self, rule: str) -> int:
        """Minutes to ask for a job of ``rule``."""
        return runtime_min(self._rule(rule)["max_s"])

    def mem_mb(self, rule: str) -> int:
        """Megabytes to ask for a job of ``rule``."""
        return mem_mb_of(self._rule(rule)["max_rss_mb"])
