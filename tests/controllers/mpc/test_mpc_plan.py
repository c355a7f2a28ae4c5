"""A plan shifted to a later time: states and progress re-sampled by linear interpolation in time, held at the
last node beyond the horizon; the command is exact between nodes (piecewise-constant rate)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.mpc.plan import Plan, shift_rows

STEP_S = 0.05


def _plan(seed: int, n: int = 12, nx: int = 3) -> Plan:
    rng = np.random.default_rng(seed)
    inputs = rng.normal(0.0, 0.5, (n, 1))
    states = rng.normal(0.0, 1.0, (n + 1, nx))
    states[:, -1] = np.concatenate(([0.1], 0.1 + np.cumsum(inputs[:, 0]) * STEP_S))  # the command integrates u
    progress = np.concatenate(([0.0], np.cumsum(rng.uniform(0.1, 1.0, n))))
    return Plan(2.0, STEP_S, states, inputs, progress, nx - 1)


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 10_000), elapsed=st.floats(0.0, 1.0))
def test_shift_matches_interpolation_in_time(seed: int, elapsed: float):
    plan = _plan(seed)
    n = plan.horizon_steps
    t = plan.t_s + elapsed
    elapsed = t - plan.t_s  # as the plan sees it, rounding included
    states, inputs, progress = plan.shifted(t)
    t_old = np.arange(n + 1) * STEP_S
    t_new = np.minimum(elapsed + np.arange(n + 1) * STEP_S, n * STEP_S)  # np.interp holds the ends too
    for j in range(plan.states.shape[1]):
        np.testing.assert_allclose(states[:, j], np.interp(t_new, t_old, plan.states[:, j]), atol=1e-12)
    expected_progress = np.interp(t_new, t_old, plan.progress_m)
    np.testing.assert_allclose(progress, expected_progress - expected_progress[0], atol=1e-12)
    whole = min(int(elapsed / STEP_S), n - 1)
    np.testing.assert_array_equal(inputs[:, 0], plan.inputs[np.minimum(np.arange(whole, whole + n), n - 1), 0])


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), elapsed=st.floats(0.0, 1.0))
def test_the_command_is_exact_between_nodes(seed: int, elapsed: float):
    """The command state integrates the piecewise-constant rate, so it is the linear interpolation of the nodes."""
    plan = _plan(seed)
    t_old = np.arange(plan.horizon_steps + 1) * STEP_S
    expected = np.interp(elapsed, t_old, plan.states[:, -1])
    assert abs(plan.command_at(plan.t_s + elapsed) - expected) < 1e-12


def test_shift_rows_holds_the_last_row():
    rows = np.arange(8.0).reshape(4, 2)
    np.testing.assert_allclose(shift_rows(rows, 2.5, 3), [[5.0, 6.0], [6.0, 7.0], [6.0, 7.0]])
