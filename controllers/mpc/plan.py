"""A solved MPC plan, stamped with its time: shifted to warm-start the next solve, and replayed as the fallback.

The prediction step h (default 50 ms) need not equal the controller's sample time (20 ms at 50 Hz), so "shifted"
means re-sampled at the current time: node k of the shifted plan is the old plan at t - t_0 + k h, interpolated
linearly between its nodes and held at its last node beyond the horizon. The commanded road-wheel angle is a
state whose rate is the (piecewise-constant) input, so the plan's command at any time is exact: piecewise linear.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit


def interp_rows(rows: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """rows (n, m) at fractional row indices `positions` (clipped to [0, n-1]), linearly interpolated."""
    n = rows.shape[0]
    pos = np.clip(positions, 0.0, n - 1)
    lo = np.minimum(pos.astype(int), n - 1)
    hi = np.minimum(lo + 1, n - 1)
    frac = (pos - lo)[:, None]
    return rows[lo] * (1.0 - frac) + rows[hi] * frac


@njit(cache=True)
def shift_rows(rows: np.ndarray, offset: float, count: int) -> np.ndarray:  # pragma: no cover - compiled
    """`count` rows starting at fractional row `offset` >= 0, one row apart, the last row held beyond the end:
    the uniform case of `interp_rows` (every node moves by the same elapsed time). Compiled: it runs on every
    MPC step, where a dozen small numpy calls doing the same work cost 15-20 us."""
    n, m = rows.shape
    whole = int(offset)
    frac = offset - whole
    out = np.empty((count, m))
    for k in range(count):
        lo = min(whole + k, n - 1)
        hi = min(lo + 1, n - 1)
        for j in range(m):
            out[k, j] = rows[lo, j] * (1.0 - frac) + rows[hi, j] * frac
    return out


@njit(cache=True)
def _shifted(
    states: np.ndarray, inputs: np.ndarray, progress_m: np.ndarray, offset: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """`Plan.shifted` for a node offset in [0, N]: states and progress by `shift_rows`, the progress counted from
    the new start, the inputs of the intervals the new ones start in (the last one held)."""
    n = inputs.shape[0]
    new_states = shift_rows(states, offset, n + 1)
    new_progress = shift_rows(progress_m.reshape(-1, 1), offset, n + 1)[:, 0]
    new_progress -= new_progress[0]
    whole = min(int(offset), n - 1)
    new_inputs = np.empty_like(inputs)
    for k in range(n):
        new_inputs[k] = inputs[min(whole + k, n - 1)]
    return new_states, new_inputs, new_progress


@dataclass
class Plan:
    """t_s: time of the measurement the plan starts from; step_s: prediction step h; states (N+1, nx);
    inputs (N, nu); progress_m (N+1,): predicted arc length travelled from the start; i_cmd: index of the
    commanded road-wheel angle in the state; dual: the solver's multipliers (for warm starts)."""

    t_s: float
    step_s: float
    states: np.ndarray
    inputs: np.ndarray
    progress_m: np.ndarray
    i_cmd: int
    dual: tuple[np.ndarray, ...] = ()

    @property
    def horizon_steps(self) -> int:
        return self.inputs.shape[0]

    def positions(self, t_s: float) -> np.ndarray:
        """Fractional node indices of the old plan that the N+1 nodes of a plan starting at t_s fall on."""
        return (t_s - self.t_s) / self.step_s + np.arange(self.horizon_steps + 1)

    def shifted(self, t_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(states, inputs, progress from t_s) re-sampled for a plan starting at t_s (not before the plan)."""
        offset = min(max((t_s - self.t_s) / self.step_s, 0.0), float(self.horizon_steps))
        return _shifted(self.states, self.inputs, self.progress_m, offset)

    def command_at(self, t_s: float) -> float:
        """The planned command (road-wheel angle, rad) at time t_s: exact, the rate is piecewise constant."""
        tau = t_s - self.t_s
        n = self.horizon_steps
        if tau >= n * self.step_s:
            return float(self.states[n, self.i_cmd])
        k = min(max(int(tau // self.step_s), 0), n - 1)
        return float(self.states[k, self.i_cmd] + self.inputs[k, 0] * (max(tau, 0.0) - k * self.step_s))

    def rate_at(self, t_s: float) -> float:
        """The planned command rate (rad/s) at t_s (0 beyond the horizon)."""
        k = int((t_s - self.t_s) // self.step_s)
        return float(self.inputs[k, 0]) if 0 <= k < self.horizon_steps else 0.0
