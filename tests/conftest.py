"""Shared fixtures: repository paths and the schemas."""

from pathlib import Path

import pytest

from amontons.config import load_schema

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def config_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "config.schema.yaml")


@pytest.fixture(scope="session")
def sheet_schema() -> dict:
    return load_schema(REPO / "workflow" / "schemas" / "materials.schema.yaml")
