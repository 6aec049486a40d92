"""Cluster resources from measured runs (amontons.resources, workflow/resources.json)."""

import json
from pathlib import Path

import pytest

from amontons.resources import (
    MIN_MEM_MB,
    MIN_RUNTIME_MIN,
    SAFETY,
    JobResources,
    ResourceError,
    fft_points,
)

REPO = Path(__file__).resolve().parents[1]
RECORD = {
    "rules": {"measure_psf": {"max_s": 90.0, "max_rss_mb": 640.0, "jobs": 5}},
    "grid_rules": {
        "simulate_scene": {
            "hardening": {"s_per_load_point": 4e-6, "base_mb": 300.0, "mb_per_point": 1e-4}
        }
    },
}


def test_a_non_periodic_solve_works_on_the_padded_grid():
    assert fft_points(512, periodic=True) == 512**2
    assert fft_points(512, periodic=False) == 1024**2


def test_rules_ask_for_twice_their_measured_maximum_rounded_up():
    resources = JobResources(RECORD)
    assert resources.runtime_min("measure_psf") == 3  # 2 × 90 s = 3 min
    assert resources.mem_mb("measure_psf") == 1300  # 2 × 640 MB, to the next 100 MB
    assert SAFETY == 2.0


def test_a_solve_asks_for_more_on_a_larger_grid_and_for_floors_on_a_small_one():
    resources = JobResources(RECORD)
    big = fft_points(1024, periodic=False)  # 4.19 Mpoints
    # 2 × 5 loads × 4e-6 s × 4.19e6 = 168 s: 3 min; 2 × (300 + 419) MB = 1438: 1500 MB
    assert resources.grid_runtime_min("simulate_scene", "hardening", big, 5) == 3
    assert resources.grid_mem_mb("simulate_scene", "hardening", big) == 1500
    tiny = fft_points(32, periodic=True)
    assert resources.grid_runtime_min("simulate_scene", "hardening", tiny, 5) == MIN_RUNTIME_MIN
    assert resources.grid_mem_mb("simulate_scene", "hardening", tiny) == 700  # 600.2 MB up
    assert MIN_MEM_MB == 500


def test_an_unmeasured_rule_or_model_is_named():
    resources = JobResources(RECORD, "my.json")
    with pytest.raises(ResourceError, match="my.json: no measured resources of rule fit_scene"):
        resources.mem_mb("fit_scene")
    with pytest.raises(ResourceError, match="contact model elastic"):
        resources.grid_mem_mb("simulate_scene", "elastic", 100)


def test_the_committed_measurements_cover_every_rule_and_solve_model():
    """workflow/resources.json (benchmarks/fit_job_resources.py on the full and small runs)
    holds every rule that runs as a cluster job and every contact model a solve rule uses."""
    record = json.loads((REPO / "workflow" / "resources.json").read_text())
    rules = set()
    for path in (REPO / "workflow" / "rules").glob("*.smk"):
        text = path.read_text()
        for block in text.split("\nrule ")[1:]:
            if "localrule: True" not in block:
                rules.add(block.split(":", 1)[0])
    assert rules <= set(record["rules"])
    plastic = {"penetration_hardness", "hardening"}
    assert plastic | {"elastic"} <= set(record["grid_rules"]["simulate_scene"])
    assert plastic <= set(record["grid_rules"]["scan_scene"])
    assert all(v["max_s"] > 0 and v["max_rss_mb"] > 0 for v in record["rules"].values())
