"""Rule scan_scene: one sphere's parameter scan (amontons.simulate.scan_job, docs/study.md),
its values solved in a chain in one job, then judged and refined."""

import os

if "snakemake" in globals():
    # The contact solve's BLAS calls spin OpenBLAS threads beyond the rule's (benchmarks/README)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from amontons.runlog import run_logged
from amontons.simulate.scan_job import run

if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        run,
        sm.log[0],
        levelled_path=sm.input.levelled,
        psf_path=sm.input.psf,
        registration_path=sm.input.registration,
        fluorescence=sm.input.fluorescence,
        chain=sm.params.chain,
        seed=list(sm.input.seed),
        judgement=sm.params.judgement,
        refinement_path=sm.output.refinement,
        scan=sm.params.scan,
        base_config=sm.params.base,
        sphere=sm.wildcards.sphere,
        sphere_record=sm.params.sphere_record,
        pixel_nm=sm.params.pixel_nm,
        pixel_table=list(sm.input.pixel_table),
        images=sm.params.images,
        otsu=sm.params.otsu,
        threads=sm.threads,
        solver_backend=sm.params.get("solver_backend", "cpu"),
    )
