"""Cluster resources from measured runs (amontons.measured_resources, workflow/resources.json)."""

import json
from pathlib import Path

import pytest

from amontons.measured_resources import (
    MIN_MEM_MB,
    MIN_RUNTIME_MIN,
    SAFETY,
    JobResources,
    ResourceError,
    fft_points,
    mem_mb_of,
    runtime_min,
)

REPO = Path(__file__).resolve().parents[1]
RECORD = {"rules": {"measure_psf": {"max_s": 90.0, "max_rss_mb": 640.0, "jobs": 5}}}


def test_a_non_periodic_solve_works_on_the_padded_grid():
    assert fft_points(512, periodic=True) == 512**2
    assert fft_points(512, periodic=False) == 1024**2


def test_rules_ask_for_twice_their_measured_maximum_rounded_up():
    resources = JobResources(RECORD)
    assert resources.runtime_min("measure_psf") == 3  # 2 × 90 s = 3 min
    assert resources.mem_mb("measure_psf") == 1300  # 2 × 640 MB, to the next 100 MB
    assert SAFETY == 2.0


def test_floors_hold_for_tiny_jobs():
    assert runtime_min(0.1) == MIN_RUNTIME_MIN
    assert mem_mb_of(10.0) == MIN_MEM_MB == 500
    assert runtime_min(181.0) == 7  # 2 × 181 s = 6.03 min, up


def test_an_unmeasured_rule_is_named():
    resources = JobResources(RECORD, "my.json")
    with pytest.raises(ResourceError, match="my.json: no measured resources of rule fit_scene"):
        resources.mem_mb("fit_scene")


def test_the_committed_measurements_cover_every_rule():
    """workflow/resources.json (benchmarks/fit_job_resources.py on the full and small runs)
    holds every rule that runs as a cluster job."""
    record = json.loads((REPO / "workflow" / "resources.json").read_text())
    rules = set()
    for path in (REPO / "workflow" / "rules").glob("*.smk"):
        text = path.read_text()
        for block in text.split("\nrule ")[1:]:
            if "localrule: True" not in block:
                rules.add(block.split(":", 1)[0])
    assert rules <= set(record["rules"])
    assert all(v["max_s"] > 0 and v["max_rss_mb"] > 0 for v in record["rules"].values())
