"""Fixed-step classical Runge-Kutta (RK4), the one integrator of every plant.

Each step of size h evaluates the derivative f four times (Hairer, Norsett & Wanner, "Solving Ordinary
Differential Equations I", section II.1, the classical fourth-order method):
    k1 = f(s), k2 = f(s + h/2 k1), k3 = f(s + h/2 k2), k4 = f(s + h k3),   s <- s + h/6 (k1 + 2 k2 + 2 k3 + k4).
A fixed step at the plant rate keeps a run's cost per controller step constant and its result independent of an
error controller's choices; the models' fastest modes (tyre relaxation, the steering actuator, the kinematic pull)
are resolved at 1 kHz.

`rk4` is compiled with numba and takes the derivative as a first-class compiled function with the signature
f(state, params, delta_cmd, accel, out) writing ds/dt into `out`. It is inlined into its caller at numba's IR level
(`inline="always"`): a dispatcher passed as a runtime argument would stop numba caching the caller (its address is
a "dynamic global"), so each model wraps it in its own cached function with its derivative as a global:

    @njit(cache=True)
    def _advance(state, p, delta_cmd, accel, h, n):
        return rk4(_rhs, state, p, delta_cmd, accel, h, n)

Numba's cache is keyed on the caller's source file only: after editing this module (or `tyres`, `blend`,
`actuator`, `reference_point`), clear the models' caches (`__pycache__/*.nbi`, `*.nbc`) or set NUMBA_CACHE_DIR.

`rk4_python` is the same step for a derivative written in Python (CommonRoad's multi-body model).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import njit

#: Index of the longitudinal speed in every compiled model's state; it never goes below zero (no reversing).
SPEED_INDEX = 3


@njit(inline="always")
def rk4(rhs, state, p, delta_cmd, accel, h, n):  # pragma: no cover - compiled
    """`n` RK4 steps of size `h` of ds/dt = rhs(s, p, delta_cmd, accel) with the inputs held; a new array.

    The speed (state SPEED_INDEX) is clipped at zero after each step: braking stops the vehicle, it does not
    reverse it.
    """
    m = state.size
    s = state.copy()
    k1, k2, k3, k4, t = np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    for _ in range(n):
        rhs(s, p, delta_cmd, accel, k1)
        for i in range(m):
            t[i] = s[i] + 0.5 * h * k1[i]
        rhs(t, p, delta_cmd, accel, k2)
        for i in range(m):
            t[i] = s[i] + 0.5 * h * k2[i]
        rhs(t, p, delta_cmd, accel, k3)
        for i in range(m):
            t[i] = s[i] + h * k3[i]
        rhs(t, p, delta_cmd, accel, k4)
        for i in range(m):
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if s[SPEED_INDEX] < 0.0:
            s[SPEED_INDEX] = 0.0
    return s


def rk4_python(rhs: Callable[[np.ndarray], np.ndarray], state: np.ndarray, h: float) -> np.ndarray:
    """One RK4 step of size `h` of ds/dt = rhs(s) (a Python derivative returning a new array); a new array."""
    k1 = rhs(state)
    k2 = rhs(state + 0.5 * h * k1)
    k3 = rhs(state + 0.5 * h * k2)
    k4 = rhs(state + h * k3)
    return state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
