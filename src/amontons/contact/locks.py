"""An exclusive lock on a file across the processes of one machine (POSIX ``flock``): the
solver's shared caches (FFTW wisdom, :mod:`.wisdom`; numba's warm-up, :mod:`.jit`) are
written by one process at a time. Without fcntl (Windows) the lock is a no-op."""

from __future__ import annotations

import contextlib
import os

try:  # POSIX: serialise writers between processes
    import fcntl
except ImportError:  # pragma: no cover - Windows: no lock, the files are still shared
    fcntl = None


@contextlib.contextmanager
def exclusive_lock(path: str | os.PathLike):
    """Hold an exclusive lock on the file ``path`` (created empty if absent, and left for
    the next holder) for the block; the lock ends with the block or the process."""
    with open(path, "a") as handle:
        if fcntl is not None:
            fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            if fcntl is not None:
                fcntl.flock(handle, fcntl.LOCK_UN)
