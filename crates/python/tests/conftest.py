"""Shared fixtures of the Python tests: the repository's test data."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"


@pytest.fixture
def data():
    return DATA
