"""The solver backend switch (config solver_backend, config/README.md): with ``cupy`` every
job of a rule that runs the contact solver on a scene asks for a GPU and passes the backend
to its script; with ``cpu`` (the default) none does, and the DAG stays the recorded one
(tests/workflow/test_dag_unchanged.py). Here without Snakemake: the run's helper and the
rules that use it; tests/workflow/test_dag_unchanged.py checks the jobs themselves."""

import re
from pathlib import Path

import pytest

from amontons.simulate.solve import SOLVER_BACKENDS

RULES = Path(__file__).resolve().parents[2] / "workflow" / "rules"
# The scripts that run the contact solver on a scene's load series (amontons.simulate.solve)
SOLVE_SCRIPTS = ("simulate_scene.py", "scan_scene.py")


def _rules() -> dict[str, str]:
    """Rule name -> its text, over every .smk file."""
    rules = {}
    for path in sorted(RULES.glob("*.smk")):
        parts = re.split(r"^rule (\w+):\n", path.read_text(), flags=re.M)
        rules.update(zip(parts[1::2], parts[2::2], strict=True))
    return rules


def _section(text: str, name: str) -> str:
    match = re.search(rf"^    {name}:\n((?:        .*\n)+)", text, flags=re.M)
    return match.group(1) if match else ""


def _set_backend(name):
    def edit(config):
        config["solver_backend"] = name

    return edit


@pytest.mark.parametrize(("backend", "resources"), [("cpu", {}), ("cupy", {"gpu": 1})])
def test_the_backend_sets_the_gpu_resource_and_param(make_run, backend, resources):
    run = make_run(edit=_set_backend(backend))
    assert run.resources.backend.name == backend
    assert run.resources.backend.resources == resources
    assert run.resources.backend.params == ({"solver_backend": "cupy"} if resources else {})


def test_the_shipped_configs_solve_on_the_cpu(make_run):
    for name in ("config.yaml", "test.yaml"):
        backend = make_run(name).resources.backend
        assert (backend.name, backend.resources, backend.params) == ("cpu", {}, {})


def test_an_unknown_backend_is_refused(make_run):
    with pytest.raises(Exception, match="solver_backend"):
        make_run(edit=_set_backend("cuda"))


def test_every_solve_rule_and_no_other_takes_the_switch():
    rules = _rules()
    solving = {
        name
        for name, text in rules.items()
        if any(f"scripts/{script}" in text for script in SOLVE_SCRIPTS)
    }
    assert solving == {"simulate_scene", "simulate_synthetic_scene", "scan_scene"}
    for name, text in rules.items():
        takes_gpu = "**SOLVE_GPU" in _section(text, "resources")
        takes_backend = "**SOLVE_BACKEND" in _section(text, "params")
        assert takes_gpu == takes_backend == (name in solving), name


def test_every_config_backend_names_a_solver_backend():
    assert set(SOLVER_BACKENDS) == {"cpu", "cupy"}
    assert SOLVER_BACKENDS["cpu"] is None  # the CPU solver's own default
