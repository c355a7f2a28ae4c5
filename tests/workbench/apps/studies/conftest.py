"""Fixtures of the studies tests (helpers in study_helpers.py)."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import TINY_SPEC, write_spec


@pytest.fixture
def tiny_spec(tmp_path: Path) -> Path:
    """The tiny study (study_helpers.TINY_SPEC) as a file."""
    return write_spec(tmp_path / "spec", TINY_SPEC)
