"""Shared test configuration.

``tests/`` mirrors the package (``tests/kernels`` for ``vimpact/kernels`` and
so on); ``tests/oracles`` holds what the code is checked against that is not
a test itself: the slow NumPy reference and the catalogue of hard cases.
"""

from pathlib import Path

import pytest

#: The repository root (sweep specs, scene files and shipped tables live below it).
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def repo_root() -> Path:
    return ROOT
