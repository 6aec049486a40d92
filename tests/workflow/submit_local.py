#!/usr/bin/env python3
"""Submit command for Snakemake's cluster-generic executor that runs each job as its own
process on this machine: ``submit_local.py <jobscript>`` starts ``sh <jobscript>`` in a new
session (detached, as a batch system would), logs its output to ``<jobscript name>.log`` in
``$SUBMIT_LOCAL_LOGDIR`` (default: beside the jobscript, which Snakemake deletes after the
run) and prints the process id as the job id. The executor learns of the job's end from
the marker files the jobscript touches, as on a cluster without a status command.
"""

import os
import subprocess
import sys
from pathlib import Path


def main() -> None:
    jobscript = Path(sys.argv[1])
    logdir = Path(os.environ.get("SUBMIT_LOCAL_LOGDIR", jobscript.parent))
    with open(logdir / f"{jobscript.name}.log", "wb") as log:
        process = subprocess.Popen(
            ["sh", str(jobscript)],
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    print(process.pid)


if __name__ == "__main__":
    main()
