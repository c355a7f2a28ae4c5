"""The path preview: curvature and speed per interval at the predicted progress, against the path's own
(np.interp) curvature and speed, on an open path (clipped at its ends) and a closed loop (wrapped)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.mpc.preview import PathPreview
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path import ReferencePath

OPEN = ClothoidChain().straight(10.0).clothoid_to(1 / 25, 12.0).arc(20.0).clothoid_to(0.0, 12.0).to_path("open")
OPEN = OPEN.with_speed(np.linspace(4.0, 12.0, OPEN.curvature_1pm.size))
_theta = np.linspace(0.0, 2 * np.pi, 200, endpoint=False)
LOOP = ReferencePath.from_xy(30.0 * np.cos(_theta), 20.0 * np.sin(_theta), closed=True, name="ellipse")


def _reference(path: ReferencePath, s0: float, progress: np.ndarray, v0: float, v_min: float) -> np.ndarray:
    s_mid = s0 + 0.5 * (progress[1:] + progress[:-1])
    kappa = path.curvature(s_mid)
    if path.speed_mps is None:
        speed = np.full(s_mid.size, v0)
    else:
        speed = v0 + path.speed(s_mid) - path.speed(s0)
    return np.column_stack((kappa, np.maximum(speed, v_min)))


@settings(max_examples=60, deadline=None)
@given(
    closed=st.booleans(),
    s0=st.floats(-20.0, 400.0),
    step=st.floats(0.0, 2.0),
    v0=st.floats(0.0, 20.0),
    v_min=st.floats(0.5, 5.0),
)
def test_preview_matches_the_paths_interpolation(closed: bool, s0: float, step: float, v0: float, v_min: float):
    path = LOOP if closed else OPEN
    progress = step * np.arange(31) * (1.0 + 0.1 * np.sin(np.arange(31)))  # uneven, non-decreasing
    got = PathPreview(path).along(s0, progress, v0, v_min)
    expected = _reference(path, s0, progress, v0, v_min)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)


def test_without_a_speed_profile_the_measured_speed_is_used():
    got = PathPreview(LOOP).along(5.0, np.linspace(0.0, 12.0, 11), 7.5, 3.0)
    np.testing.assert_array_equal(got[:, 1], 7.5)
    assert got.shape == (10, 2)
