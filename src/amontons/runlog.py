"""Logging for workflow scripts: everything, including a failure's traceback, goes to the rule's
log file as well as to stderr."""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable
from typing import Any


def run_logged(main: Callable[..., Any], log_path: str, **kwargs: Any) -> Any:
    """Call ``main(**kwargs)`` with logging to ``log_path``; log and re-raise any exception."""
    handlers = [logging.FileHandler(log_path, mode="w"), logging.StreamHandler(sys.stderr)]
    logging.basicConfig(
        level=logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        handlers=handlers,
        force=True,
    )
    try:
        return main(**kwargs)
    except Exception:
        logging.getLogger(main.__module__).exception("failed")
        raise
