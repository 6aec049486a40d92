"""FFTW wisdom kept on disk, so that every process on a machine uses the same plans.

FFTW_MEASURE chooses each plan by timing candidate algorithms, and two fresh processes can
choose differently (seen here at 1024²: two different outputs in four fresh processes),
which changes the last bits of every result. FFTW's *wisdom* records the choice: a process
that imports it gets the same plan without timing anything. :func:`shared_wisdom` wraps the
building of a plan: under an exclusive file lock it imports the wisdom file, lets the plan
be built (measured only if no wisdom covers it), and writes the process's wisdom back when
it differs from the file's. The first process to plan a transform on a machine sets it for
all the others, also those running at the same time (they wait for the lock), so results
are the same bytes from run to run, as they are with FFTW_ESTIMATE, and the planning time is
paid once.

The file is ``$AMONTONS_FFTW_WISDOM`` if set (an empty value keeps wisdom in the process
only), else ``fftw-wisdom-<key>.json`` in ``$XDG_CACHE_HOME/amontons`` (``~/.cache``),
where the key hashes the CPU model and flags, the machine type, the pyfftw version and
:data:`TIMED_UNDER` (how plans were timed): a cache directory shared by different machines
(a cluster's home) keeps one file per kind of node. docs/models.md §2.1 ("FFT plans")
says what this means for reproducibility.
"""

from __future__ import annotations

import contextlib
import functools
import glob
import hashlib
import json
import os
import platform
import tempfile
import warnings
from pathlib import Path

from .locks import exclusive_lock

WISDOM_ENV = "AMONTONS_FFTW_WISDOM"
# How the plans in a file were timed; a change sets the files of before aside. Until
# 2026-11-26 a solve held OpenMP to one thread while it planned, so its two-thread MEASURE
# plans were timed on one core (benchmarks/README.md, "A second core").
TIMED_UNDER = "openmp-at-the-plan's-threads"


class WisdomFileError(RuntimeError):
    """The wisdom file exists but cannot be read as FFTW wisdom."""


def _cpu_description() -> str:
    """CPU model name and feature flags of the first processor (Linux), else the platform's
    processor string: FFTW's codelets depend on the SIMD features."""
    try:
        text = Path("/proc/cpuinfo").read_text(errors="replace")
    except OSError:
        return platform.processor()
    wanted = ("model name", "flags", "Features", "CPU part")
    lines = [ln.strip() for ln in text.split("\n\n")[0].splitlines()]
    return "\n".join(ln for ln in lines if ln.split(":")[0].strip() in wanted)


@functools.cache
def machine_key() -> str:
    """12 hex digits naming this kind of machine and FFTW build."""
    import pyfftw

    text = "\n".join((platform.machine(), _cpu_description(), pyfftw.__version__, TIMED_UNDER))
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def wisdom_path() -> Path | None:
    """The wisdom file of this machine, or None when ``$AMONTONS_FFTW_WISDOM`` is empty."""
    value = os.environ.get(WISDOM_ENV)
    if value is not None:
        return Path(value).expanduser() if value.strip() else None
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "amontons" / f"fftw-wisdom-{machine_key()}.json"


def _read(path: Path):
    """The three wisdom strings (double, single, long double) of ``path``, or None if the
    file does not exist yet or is empty (a writer that died before its first write)."""
    try:
        text = path.read_text()
    except FileNotFoundError:
        return None
    if not text.strip():
        return None
    try:
        strings = json.loads(text)
        if not (isinstance(strings, list) and len(strings) == 3):
            raise ValueError(f"a list of 3 strings expected, got {type(strings).__name__}")
        return tuple(s.encode("ascii") for s in strings)
    except (ValueError, AttributeError, UnicodeEncodeError) as exc:
        raise WisdomFileError(
            f"FFTW wisdom file {path} is not a JSON list of three FFTW wisdom strings "
            f"({exc}); delete it and the plans will be measured again"
        ) from exc


def _import(path: Path):
    """Import the wisdom of ``path`` into this process; return it as read (None if none)."""
    import pyfftw

    wisdom = _read(path)
    if wisdom is None:
        return None
    imported = pyfftw.import_wisdom(wisdom)
    if not imported[0]:  # the double-precision wisdom is the one the solver uses
        raise WisdomFileError(
            f"FFTW rejected the double-precision wisdom in {path}; delete the file and "
            "the plans will be measured again"
        )
    return wisdom


def _entries(wisdom):
    """The wisdom's entries, one set per precision: FFTW exports them in hash-table order,
    which differs between processes that know the same plans."""
    if wisdom is None:
        return None
    return tuple(frozenset(w.splitlines()) for w in wisdom)


def _write_atomically(path: Path, wisdom) -> None:
    """Replace ``path`` by the wisdom in one rename: a reader never sees half a file. Called
    under the file's lock, so a temporary of an earlier writer is one it left when it was
    killed: removed first."""
    for stale in path.parent.glob(f"{glob.escape(path.name)}*.tmp"):
        with contextlib.suppress(OSError):
            stale.unlink()
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            json.dump([w.decode("ascii") for w in wisdom], fh)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _locked(path: Path):
    """An exclusive lock on ``path``'s lock file for the duration (no-op without fcntl)."""
    return exclusive_lock(path.with_name(path.name + ".lock"))


@contextlib.contextmanager
def shared_wisdom():
    """Build FFTW plans inside this block with the machine's shared wisdom (module doc).

    Raises
    ------
    WisdomFileError
        The wisdom file exists but is not FFTW wisdom (names the file).

    Warns
    -----
    RuntimeWarning
        The cache directory cannot be created or written: plans are then measured per
        process and results may differ in their last bits between processes.
    """
    import pyfftw

    path = wisdom_path()
    with contextlib.ExitStack() as stack:
        shared = path is not None
        if shared:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                stack.enter_context(_locked(path))
            except OSError as exc:
                _warn_unshared(path, exc)
                shared = False
        if shared:
            on_disk = _import(path)
        yield
        if not shared:
            return
        known = pyfftw.export_wisdom()
        # the process may know plans the file lacks (planned before, or with another file)
        if _entries(known) != _entries(on_disk):
            try:
                _write_atomically(path, known)
            except OSError as exc:
                _warn_unshared(path, exc)


def _warn_unshared(path: Path, exc: OSError) -> None:
    warnings.warn(
        f"cannot keep FFTW wisdom in {path} ({exc}): FFT plans are measured per process, "
        f"so results may differ in their last bits between processes; set {WISDOM_ENV} "
        "to a writable file, or pass planner_effort='FFTW_ESTIMATE'",
        RuntimeWarning,
        stacklevel=4,
    )
