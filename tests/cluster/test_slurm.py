"""The workflow through a real SLURM (docs/cluster.md): the one-node cluster of
start_slurm.sh, with its accounting database answering sacct, and profiles/slurm with the
account and partition set as docs/cluster.md tells a user to set them. Jobs go through the
SLURM executor plugin: sbatch, the group jobs, sacct, srun in each job.

Two SLURM runs of the small data set, each held to what a local run does:

1. The glass sphere from its raw files to its tables, figures and elastic scene (13 jobs,
   as tests/workflow/test_executor.py runs them from the virtual experiment on; the raw files
   are made beforehand, as a lab's instruments would have) beside two faults: the PS sphere
   with a truncated fluorescence image (its job fails), and glass's penetration-hardness
   scene at a fine preset given 1 min, which it needs about 2 min for (SLURM stops it:
   TIMEOUT). Glass's outputs equal a local run's byte for byte; the run exits non-zero and
   names both, the second with the rule, the sphere and the resource to raise.
2. The file fixed and the runtime raised, the same command again: only the missing jobs run.

A local run of the glass targets, from the virtual experiment on, runs beside the second
SLURM run (the node's second core is idle while SLURM runs only the long scene), to keep the
whole under 6 min on 2 cores.
"""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from ..workflow.same_output import assert_same_output

REPO = Path(__file__).resolve().parents[2]
ACCOUNT, PARTITION = "amontons-test", "amontons"
GLASS = "results/small/glass"
GLASS_TARGETS = [
    f"{GLASS}/load_area.csv",
    f"{GLASS}/amontons.csv",
    f"{GLASS}/glass/measure/hertz_check.csv",
    f"{GLASS}/glass/measure/intensity_pressure_fit.json",
    f"{GLASS}/glass/measure/psf.json",
    f"{GLASS}/glass/measure/edge_gap.json",
    f"{GLASS}/glass/measure/grafting_density.json",
    f"{GLASS}/glass/measure/topography.json",
    f"{GLASS}/glass/scenes/elastic/fields.h5",
]
PS = "results/small/PS"
PS_TARGETS = [f"{PS}/load_area.csv", f"{PS}/amontons.csv", f"{PS}/PS/scenes/elastic/fields.h5"]
PS_DATA = "resources/synthetic/small/PS"
GLASS_DATA = "resources/synthetic/small/glass/truth.json"
BROKEN = f"{PS_DATA}/fluorescence/100.tif"
# Glass's penetration-hardness scene at a pixel of 45 nm to 1e-5: 112 s alone on the 2-core
# Intel Xeon machine (load 0.9). SLURM checks time limits every 30 s, so a job given 1 min
# ends between 60 and 95 s (with KillWait): the scene runs past it on any machine as fast.
LONG_SCENE = f"{GLASS}/glass/scenes/penetration_hardness/fields.h5"
FINE_PRESET = """\
solver_presets:
  fine: {pixel_nm: 45.0, max_side_px: 2048, window_factor: 1.5, tol: 1.0e-5}
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
    folder = root / "profile"
    folder.mkdir()
    edited = text.replace("YOUR_ACCOUNT", ACCOUNT).replace("YOUR_PARTITION", PARTITION)
    (folder / "config.yaml").write_text(edited)
    return folder


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
    log of it (a group job's jobs are listed indented)."""
    out, rule = {}, None
    for line in log.splitlines():
        started = re.match(r"^\s*(?:local)?rule (\w+):$", line)
        if started:
            rule = started[1]
        elif rule and line.strip().startswith("output: "):
            out.update(dict.fromkeys(line.strip()[len("output: ") :].split(", "), rule))
            rule = None
    return out


@pytest.fixture(scope="module")
def runs(slurm, tmp_path_factory):
    """The first SLURM run (with its faults), what it left, the second SLURM run with the
    local run beside it, and their folders."""
    local = project(tmp_path_factory.mktemp("local"))
    cluster = project(tmp_path_factory.mktemp("slurm"))
    profile = user_profile(cluster)
    # The spheres' raw files, made here as a lab's instruments would have: one of PS's can
    # then be broken before the cluster reads it, and the long scene's chain starts at once.
    raw = [f"{PS_DATA}/truth.json", GLASS_DATA]
    made = run(snakemake(cluster, raw, "--cores", "2"), cluster)
    assert made.returncode == 0, made.stderr[-3000:]
    image = cluster / BROKEN
    intact = image.read_bytes()
    image.write_bytes(intact[:2000])

    # the long scene's chain first, so that SLURM's queue holds nothing before it
    on_slurm = ("--profile", str(profile), *QUICK_STATUS, "--prioritize", LONG_SCENE)
    targets = [*GLASS_TARGETS, *PS_TARGETS, LONG_SCENE]
    faulty = run(
        snakemake(cluster, targets, *on_slurm, "--set-resources", "simulate_scene:runtime=1"),
        cluster,
    )
    record = cluster / "results" / "small" / "failed_jobs.csv"
    left = {
        "failed": pd.read_csv(record, keep_default_na=False) if record.is_file() else None,
        "long_scene_made": (cluster / LONG_SCENE).exists(),
        "glass_made": [target for target in GLASS_TARGETS if (cluster / target).is_file()],
    }

    image.write_bytes(intact)
    beside = subprocess.Popen(
        snakemake(local, GLASS_TARGETS, "--cores", "2"),
        cwd=local,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    again = run(
        snakemake(cluster, targets, *on_slurm, "--set-resources", "simulate_scene:runtime=10"),
        cluster,
    )
    _, stderr = beside.communicate(timeout=900)
    assert beside.returncode == 0, stderr[-3000:]
    return {"local": local, "cluster": cluster, "faulty": faulty, "again": again, **left}


def test_glass_through_slurm_gives_the_local_run_byte_for_byte(runs):
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
    record = runs["failed"]
    assert record is not None, "the run left no results/small/failed_jobs.csv"
    assert ("PS", "measure_contact_area", "") in set(
        zip(record["sphere"], record["rule"], record["limit"], strict=True)
    )
    assert "FAILED" in slurm_states()


def test_a_job_past_its_runtime_is_named_with_the_resource_to_raise(runs):
    """SLURM stops the scene at its 1 min (state TIMEOUT); its log holds no error, and the
    run names the rule, the sphere, the resource and the option that raises it."""
    faulty = runs["faulty"]
    assert (
        "sphere glass (glass): simulate_scene failed: stopped by SLURM (TIMEOUT) at its "
        "runtime of 1 min: raise it, e.g. --set-resources simulate_scene:runtime=2"
    ) in faulty.stderr
    assert "SLURM status is: 'TIMEOUT'" in faulty.stderr
    assert "raise simulate_scene's runtime and run again" in faulty.stderr
    assert not runs["long_scene_made"]
    record = runs["failed"]
    assert ("glass", "simulate_scene", "runtime") in set(
        zip(record["sphere"], record["rule"], record["limit"], strict=True)
    )
    assert "TIMEOUT" in slurm_states()


def test_the_run_again_completes_only_what_is_missing(runs):
    again, cluster = runs["again"], runs["cluster"]
    assert again.returncode == 0, again.stderr[-3000:]
    now = started_outputs(again.stdout + again.stderr)
    assert LONG_SCENE in now and f"{PS}/load_area.csv" in now
    assert all(path.startswith((PS, LONG_SCENE.rsplit("/", 1)[0])) for path in now), now
    assert not any(path in now for path in GLASS_TARGETS)
    assert all((cluster / target).is_file() for target in [*PS_TARGETS, LONG_SCENE])
    assert not (cluster / "results" / "small" / "failed_jobs.csv").exists()
