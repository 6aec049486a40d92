"""Wildcard constraints: a regex that matches exactly the names a rule may take (spheres,
scenes, scans, validation cases, accuracy problems)."""

from __future__ import annotations

import re


def names_pattern(names) -> str:
    """Regex matching exactly ``names``; never empty-match."""
    return "|".join(map(re.escape, names)) or "(?!)"
