"""The one TOML writer reads back through tomllib to the values written."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from workbench.base.toml_text import toml_key, toml_value

SCALARS = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(allow_nan=False, allow_infinity=False),
    st.text(),
)
VALUES = st.recursive(
    SCALARS, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(), inner, max_size=4)
)


@given(st.text(), VALUES)
def test_any_key_and_value_reads_back(key: str, value: object) -> None:
    assert tomllib.loads(f"{toml_key(key)} = {toml_value(value)}\n") == {key: value}


def test_numpy_numbers_paths_and_none_are_written_as_python_would() -> None:
    assert toml_value(np.float64(0.1)) == "0.1" and toml_value(np.int32(3)) == "3"
    assert toml_value(Path("a b/lead.json")) == '"a b/lead.json"'
    assert toml_value(None) == '"none"'
    assert toml_value("\x7f") == '"\\u007f"'
    assert math.isclose(tomllib.loads(f"x = {toml_value(np.float32(0.1))}")["x"], 0.1, rel_tol=1e-7)
    assert toml_key("max_lookahead_m") == "max_lookahead_m" and toml_key("a.b") == '"a.b"'
