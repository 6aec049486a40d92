"""Same bits as a base commit, on this machine: the check a rebuild must pass.

Solves the golden cases (record.py) twice in this place, on this machine: once with the
solver of ``--base`` (its ``src/`` exported from git into a temporary folder and put first on
PYTHONPATH) and once with the working tree's, and compares every array to the last bit.
Exits 1 naming the arrays that differ, with the largest difference of each as a fraction of
its peak; 0 when all are identical. Run from the repository root:

    python tests/contact/golden/same_bits.py --base HEAD      # uncommitted changes
    make golden-bits BASE=<the commit before the change>

Both sides run the working tree's record.py, so both solve the same cases. ``--keep`` also
writes the base's solves as the record (golden.npz and golden.machine.json): how the record
is re-made on a new kind of machine from the code it was first recorded on.

Unlike tests/contact/test_golden.py, this holds only on one machine: another CPU rounds
differently (compare.py).
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

import numpy as np
from compare import exact_failures  # beside this script, which runs as a script

HERE = Path(__file__).resolve().parent
RECORD = HERE / "record.py"
REPO = HERE.parents[2]


def export_source(rev: str, into: Path) -> Path:
    """``rev``'s ``src/`` written below ``into`` (git archive); returns that ``src``."""
    archive = subprocess.run(
        ["git", "-C", str(REPO), "archive", "--format=tar", rev, "src"],
        capture_output=True,
        check=True,
    )
    with tarfile.open(fileobj=io.BytesIO(archive.stdout), mode="r|") as tar:
        tar.extractall(into, filter="data")
    return into / "src"


def solve_cases(source: Path | None, out: Path) -> dict[str, np.ndarray]:
    """The golden cases solved by the solver below ``source`` (None: the working tree's
    installed package), written to ``out`` and returned."""
    env = dict(os.environ)
    if source is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(source), env.get("PYTHONPATH")]))
    subprocess.run([sys.executable, str(RECORD), "--out", str(out)], env=env, check=True)
    with np.load(out) as data:
        return {key: data[key] for key in data.files}


def describe(key: str, got: np.ndarray, want: np.ndarray) -> str:
    """One differing array: its key and largest difference over its peak."""
    if got.shape != want.shape:
        return f"{key}: shape {got.shape} != {want.shape}"
    scale = float(np.abs(want).max()) or 1.0
    return f"{key}: max |diff| {float(np.abs(got - want).max()) / scale:.2e} of its peak"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", required=True, help="the commit whose bits must be kept")
    parser.add_argument("--keep", action="store_true", help="write the base's as the record")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="same_bits-") as tmp:
        tmp = Path(tmp)
        base = solve_cases(export_source(args.base, tmp / "base"), tmp / "base.npz")
        work = solve_cases(None, tmp / "work.npz")
        if args.keep:
            for name in ("base.npz", "base.machine.json"):
                shutil.copyfile(tmp / name, HERE / name.replace("base", "golden"))
    differ = exact_failures(work, base)
    for key in differ:
        print(describe(key, work[key], base[key]) if key in base else key)
    print(f"{len(base) - len(differ)} of {len(base)} arrays identical to {args.base}'s")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
