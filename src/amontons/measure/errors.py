"""Outcomes of a measurement that are not a number: well-formed data that hold nothing to
measure. The result says so (a flagged null with the reason), never a made-up value."""

from __future__ import annotations

from amontons.io.layout import RawDataError


class NotMeasurable(RawDataError):
    """Well-formed data that hold nothing to measure: the result says so (a flagged null)
    instead of giving a number."""


class RingsUnreadable(NotMeasurable):
    """A reflection image whose Newton rings cannot be numbered (e.g. a rough sphere's)."""


class NoContact(NotMeasurable):
    """An image in which no contact stands out from the background (Otsu classes overlap)."""
