"""The workflow through a real SLURM (docs/cluster.md): the one-node cluster of
start_slurm.sh, with its accounting database answering sacct, and profiles/slurm with the
account and partition set as docs/cluster.md tells a user to set them. Jobs go through the
SLURM executor plugin: sbatch, the group jobs, sacct, srun in each job.

One project, run twice through SLURM:

1. The glass sphere from its virtual experiment to its tables, figures and elastic scene
   (14 jobs, as tests/workflow/test_executor.py runs them), beside two faults of the PS
   sphere: a truncated fluorescence image (its job fails) and its penetration-hardness
   scene at a fine preset given 1 min where it needs about 2 (SLURM stops it: TIMEOUT).
   Glass's outputs equal a local run's byte for byte; the run exits non-zero and names both
   faults, the first as a local run does, the second with the rule, the sphere and the
   resource to raise.
2. The file fixed and the runtime raised, the same command again: only PS's missing jobs
   run, and it exits 0.

PS's raw files and levelled AFM map are made beforehand, locally (the first can then be
broken before the cluster reads it): the long scene is among the first jobs SLURM starts,
so that it holds one of the node's two cores from the start while the others queue for the
second. The local run runs beside the second SLURM run. Measured: docs/cluster.md.
"""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from amontons.workflow.failures import started_resources

from ..workflow.same_output import GLASS_TARGETS, assert_same_output

REPO = Path(__file__).resolve().parents[2]
ACCOUNT, PARTITION = "amontons-test", "amontons"
PS = "results/small/PS"
# PS's tables: its measurements, fits and figures (its scenes are left out: the long one
# below is enough of them)
PS_TARGETS = [f"{PS}/load_area.csv", f"{PS}/amontons.csv"]
PS_DATA = "resources/synthetic/small/PS"
BROKEN = f"{PS_DATA}/fluorescence/100.tif"
# PS's penetration-hardness scene at a pixel of 40 nm to 1e-5: 120 s alone on the 2-core
# Intel Xeon machine (load 0.8). SLURM checks time limits every 30 s, so a job given 1 min
# ends between 60 and 95 s (with KillWait): the scene runs past it on any machine as fast.
# Its chain starts from PS's levelled AFM map, made with the raw files.
LONG_SCENE = f"{PS}/PS/scenes/penetration_hardness/fields.h5"
LEVELLED = f"{PS}/PS/measure/afm_before_levelled.h5"
FINE_PRESET = """\
solver_presets:
  fine: {pixel_nm: 40.0, max_side_px: 2048, window_factor: 1.5, tol: 1.0e-5}
scenes:
  penetration_hardness:
    preset: fine
"""
CONFIG = ("--configfile", "config/test.yaml", "config/fine.yaml")
# The plugin's first status query after 2 s, not 40: its queries back off by 10 s each
# round in which no job finished, so the default would add minutes to a run of short jobs.
QUICK_STATUS = ("--slurm-init-seconds-before-status-checks", "2")


def project(root: Path) -> Path:
    """A project folder with the repository's config and the fine preset's overlay."""
    shutil.copytree(REPO / "config", root / "config")
    (root / "config" / "fine.yaml").write_text(FINE_PRESET)
    return root


def user_profile(root: Path) -> Path:
    """profiles/slurm with this cluster's account and partition in place of the
    placeholders, as docs/cluster.md tells a user to edit it."""
    text = (REPO / "profiles" / "slurm" / "config.yaml").read_text()
    assert "YOUR_ACCOUNT" in text and "YOUR_PARTITION" in text
    root.mkdir()
    edited = text.replace("YOUR_ACCOUNT", ACCOUNT).replace("YOUR_PARTITION", PARTITION)
    (root / "config.yaml").write_text(edited)
    return root


def snakemake(root: Path, targets, *args) -> list[str]:
    """The command line of Snakemake on ``targets`` in ``root`` (targets before
    --configfile, which takes every word after it)."""
    return [
        *(sys.executable, "-m", "snakemake", *targets),
        *("-s", str(REPO / "Snakefile"), "-d", str(root), *args, *CONFIG),
    ]


def run(command, root: Path) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=root, capture_output=True, text=True, timeout=900)


def started_outputs(log: str) -> dict[str, str]:
    """The output files of every job a run started, each with its rule, from Snakemake's
    log of it (amontons.workflow.failures.started_resources reads the start blocks)."""
    return {path: rule for rule, outputs in started_resources(log) for path in outputs.split(", ")}


def make_raw_files(root: Path, targets) -> None:
    """Raw files (and what else ``targets`` name) made locally, as a lab's instruments
    would have made the raw files."""
    made = run(snakemake(root, targets, "--cores", "2"), root)
    assert made.returncode == 0, made.stderr[-3000:]


def failed_record(root: Path) -> pd.DataFrame | None:
    """The run's record of its failed jobs (None where it left none)."""
    record = root / "results" / "small" / "failed_jobs.csv"
    return pd.read_csv(record, keep_default_na=False) if record.is_file() else None


def recorded(record: pd.DataFrame | None) -> set[tuple[str, str, str]]:
    """(sphere, rule, limit) of every job in a run's record of its failed jobs."""
    assert record is not None, "the run left no results/small/failed_jobs.csv"
    return set(zip(record["sphere"], record["rule"], record["limit"], strict=True))


@pytest.fixture(scope="module")
def runs(slurm, tmp_path_factory):
    """The first SLURM run and what it left, the second SLURM run, and the local run beside
    it (and their folders)."""
    out = {"local": project(tmp_path_factory.mktemp("local"))}
    cluster = out["cluster"] = project(tmp_path_factory.mktemp("slurm"))
    on_slurm = ("--profile", str(user_profile(tmp_path_factory.mktemp("user") / "profile")))
    on_slurm += (*QUICK_STATUS, "--set-resources")
    make_raw_files(cluster, [f"{PS_DATA}/truth.json", LEVELLED])
    image = cluster / BROKEN
    intact = image.read_bytes()
    image.write_bytes(intact[:2000])

    targets = [*GLASS_TARGETS, *PS_TARGETS, LONG_SCENE]
    faulty = run(snakemake(cluster, targets, *on_slurm, "simulate_scene:runtime=1"), cluster)
    out["faulty"] = faulty
    out["failed"] = failed_record(cluster)
    out["glass_made"] = [target for target in GLASS_TARGETS if (cluster / target).is_file()]
    out["long_scene_made"] = (cluster / LONG_SCENE).exists()

    image.write_bytes(intact)
    beside = subprocess.Popen(
        snakemake(out["local"], GLASS_TARGETS, "--cores", "2"),
        cwd=out["local"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    out["again"] = run(snakemake(cluster, targets, *on_slurm, "simulate_scene:runtime=10"), cluster)
    _, stderr = beside.communicate(timeout=900)
    assert beside.returncode == 0, stderr[-3000:]
    return out


def test_glass_through_slurm_gives_the_local_run_byte_for_byte(runs):
    """Every file of the local run of glass's targets, virtual experiment included, equals
    the SLURM run's (compared after the run again, which runs none of glass's jobs)."""
    local, cluster, faulty = runs["local"], runs["cluster"], runs["faulty"]
    log = faulty.stdout + faulty.stderr
    # every job went through sbatch, each with its own SLURM job id, some as group jobs
    submitted = re.findall(r"submitted with SLURM jobid (\d+)", log)
    assert len(submitted) == len(set(submitted)) >= 8
    assert re.search(r"group job", log, re.I), log[-3000:]
    assert (cluster / ".snakemake" / "slurm_logs").is_dir()
    produced = sorted(
        p.relative_to(local)
        for top in ("results", "resources")
        for p in (local / top).rglob("*")
        if p.is_file()
    )
    assert len(produced) >= 30
    for path in produced:
        assert_same_output(cluster / path, local / path)


def slurm_states() -> list[str]:
    """The state of every job the cluster's accounting database holds."""
    out = subprocess.run(
        ["sacct", "-X", "-n", "-P", "-o", "State"], capture_output=True, text=True, check=True
    )
    return out.stdout.split()


def test_a_failed_job_is_named_once_and_the_other_sphere_runs(runs):
    """PS's job fails on the broken file: the run exits non-zero and names it with its
    sphere and error as a local run does (tests/workflow/test_corrupt_file.py), once, though
    the failed cluster job's own log repeats it; every glass target was made in that run."""
    faulty = runs["faulty"]
    assert faulty.returncode != 0
    named = re.findall(
        rf"^sphere PS \(PS\): measure_contact_area failed: .*{re.escape(BROKEN)}.*$",
        faulty.stderr,
        re.M,
    )
    assert len(named) == 1, faulty.stderr[-3000:]
    assert "not a readable TIFF" in named[0]
    assert "run again to make PS's tables, figures, summary and report without PS" in (
        faulty.stderr
    )
    assert runs["glass_made"] == GLASS_TARGETS
    assert ("PS", "measure_contact_area", "") in recorded(runs["failed"])
    assert "FAILED" in slurm_states()


def test_a_job_past_its_runtime_is_named_with_the_resource_to_raise(runs):
    """SLURM stops the scene at its 1 min (state TIMEOUT); its log holds no error, and the
    run names the rule, the sphere, the resource and the option that raises it."""
    faulty = runs["faulty"]
    assert (
        "sphere PS (PS): simulate_scene failed: stopped by SLURM (TIMEOUT) at its "
        "runtime of 1 min: raise it, e.g. --set-resources simulate_scene:runtime=2"
    ) in faulty.stderr, faulty.stderr[-3000:]
    assert "SLURM status is: 'TIMEOUT'" in faulty.stderr
    assert "raise simulate_scene's runtime and run again" in faulty.stderr
    assert not runs["long_scene_made"]
    assert ("PS", "simulate_scene", "runtime") in recorded(runs["failed"])
    assert "TIMEOUT" in slurm_states()


def test_the_run_again_completes_only_what_is_missing(runs):
    """The file fixed and the runtime raised: only PS's jobs run, the scene among them, none
    of glass's; the run exits 0 and leaves no record of failed jobs."""
    again, cluster = runs["again"], runs["cluster"]
    assert again.returncode == 0, again.stderr[-3000:]
    now = started_outputs(again.stdout + again.stderr)
    assert {LONG_SCENE, f"{PS}/load_area.csv", f"{PS}/PS/measure/contact_area.csv"} <= set(now)
    assert all(path.startswith(f"{PS}/") for path in now), now
    made = [*GLASS_TARGETS, *PS_TARGETS, LONG_SCENE]
    assert all((cluster / target).is_file() for target in made)
    assert failed_record(cluster) is None
