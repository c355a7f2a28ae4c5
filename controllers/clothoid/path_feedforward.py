"""The path's own clothoid as the reference of the clothoid controller's feedback, and its curvature rate as
feed-forward: a two-degree-of-freedom form of Eq. 3 that makes tracking independent of the lookahead.

Why. Eq. 3 fits one clothoid from the vehicle's (predicted) pose to a target point at the lookahead L on the path.
Even with the vehicle exactly on the path its curvature rate is not the path's: for a path whose curvature varies
within L the fit through one point gives kappa' = kappa_p' + kappa_p'' L / 4 + ..., so the vehicle turns in ahead
of the path by about L / 4 and cuts every transition; the feedback then fights that error with a gain that falls
as L^-3 (docs/clothoid.md: the dlc's max |CTE| against a fixed lookahead). Tracking therefore asked for short
lookaheads, and short lookaheads are where the loop loses its margins (`loop_analysis.py`) and falls into limit cycles.

What. The same hyper-clothoid is fitted twice to the same target: from the vehicle's predicted pose (as Eq. 3)
and from the reference pose, where a vehicle exactly on the path would be predicted to (the path's pose ahead by
the reference lead, then moved on the path's curvature there like the vehicle's prediction). Their difference is
zero on the path and is the feedback; the path's curvature rate, at the point the steering now commanded will be
realised (the vehicle's lag ahead), averaged over a window, is the feed-forward:

    kappa' = kappa'(vehicle pose -> target) - kappa'(reference pose -> target) + kappa_p'(s + V tau_ff) / K

Linearised, the reference term depends on the path only, so the loop and its margins are those of Eq. 3 alone
(`loop_analysis.py`); what changes is that the loop need not produce the path's curvature by error. K is
the vehicle's steady-state gain (understeer) from its identified lag. The timings come from the identified lags:
tau_ff is the low-frequency delay of lead filter and path lag (Eq. 6 and Eq. 5), and the reference lead is how much
the path curvature lags the yaw-rate curvature that the controller measures as kappa(0) (a truck's tandem and
trailer make it much longer than a car's).

The lag inverted (`lag_inverse_curvature`, `ClothoidConfig.feedforward_inversion`, the default). The feed-forward
above is a first-order model of the lag (its low-frequency delay) and, integrated with the feedback, passes through
the lead filter, whose high-frequency gain amplifies any sharpening of it. Instead, the
steering that makes Eq. 5's output the path's curvature is computed from the path ahead (the curvature its dead time
ahead, plus its time derivatives weighted by the second-order part) and added to the steering after the lead
filter; the integrator then holds only the feedback's curvature, and the feedback's two-degree-of-freedom form
(vehicle fit less reference fit) is unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from controllers.clothoid.clothoid_fit import fit_kernel
from controllers.clothoid.pose_prediction import along_arc
from workbench.base.errors import require_in_range
from workbench.base.path_search import PATH_CURVATURE, PATH_HEADING, PATH_X, PATH_Y, value_at

#: Saturation of the reference fit's kappa' (1/m^2): far above any path's, so the fit is never clipped.
REFERENCE_KDOT_MAX = 1e6


@dataclass(frozen=True)
class FeedforwardTiming:
    """feedforward_time_s: where along the path (speed x time ahead of the vehicle's foot point) the feed-forward
    reads the curvature rate (s, >= 0); reference_lead_s: how far ahead of the foot point the reference pose starts
    (s, >= 0; at most the prediction time); steady_state_gain: K of Eq. 5 (> 0)."""

    feedforward_time_s: float
    reference_lead_s: float
    steady_state_gain: float = 1.0

    def __post_init__(self) -> None:
        require_in_range("feedforward_time_s", self.feedforward_time_s, 0.0, 5.0, "s")
        require_in_range("reference_lead_s", self.reference_lead_s, 0.0, 5.0, "s")
        require_in_range("steady_state_gain", self.steady_state_gain, 0.05, 20.0)


@njit(cache=True)
def two_degree_of_freedom_rate(
    vehicle_kdot: float,
    table: np.ndarray,
    record: np.ndarray,
    here: np.ndarray,
    target_x: float,
    target_y: float,
    speed_mps: float,
    prediction_time_s: float,
    feedforward_time_s: float,
    reference_lead_s: float,
    steady_state_gain: float,
    window_m: float,
    path_time_s: float = 0.0,
    reference_curvature: float = math.nan,
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """(kappa' to integrate, the reference's kappa', the feed-forward kappa') (1/m^2), module docstring, on the
    compiled path (`path_search.CompiledPath`'s table and record). here: the foot point of the vehicle's measured
    position (`path_search.track`'s output: s, progress, x, y, heading, curvature, ...); the timings of
    `FeedforwardTiming`.

    The reference pose: the path's pose path_time_s + reference_lead_s ahead of the foot point, moved over the rest
    of the prediction time on the path's curvature there, by the chord of that arc (as the vehicle's own
    prediction; path_time_s: the known delay when the vehicle's pose is predicted over it with the lags' model,
    which follows the path's own curvature, `delay_predictor.py`; else 0); reference_curvature: the curvature the
    reference pose moves on (NaN: the path's there).
    The feed-forward: dkappa/ds of the path speed x feedforward_time_s ahead of the foot point, averaged over
    window_m, over K."""
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    path_curvature = table[PATH_CURVATURE]
    lead = min(reference_lead_s, prediction_time_s)
    if path_time_s + lead > 0.0:
        s_ref = here[0] + speed_mps * (path_time_s + lead)
        rx = value_at(table[PATH_X], s_ref, spacing, length, closed)
        ry = value_at(table[PATH_Y], s_ref, spacing, length, closed)
        rh = value_at(table[PATH_HEADING], s_ref, spacing, length, closed)
        rk = value_at(path_curvature, s_ref, spacing, length, closed)
    else:
        rx, ry, rh, rk = here[2], here[3], here[4], here[5]
    if not math.isnan(reference_curvature):
        rk = reference_curvature
    rx, ry, rh = along_arc(rx, ry, rh, rk, speed_mps * (prediction_time_s - lead))
    reference_kdot = fit_kernel(rx, ry, rh, rk, target_x, target_y, REFERENCE_KDOT_MAX)[0]
    s_ff, half = here[0] + speed_mps * feedforward_time_s, 0.5 * window_m
    feedforward = (
        value_at(path_curvature, s_ff + half, spacing, length, closed)
        - value_at(path_curvature, s_ff - half, spacing, length, closed)
    ) / window_m
    feedforward /= steady_state_gain
    return vehicle_kdot - reference_kdot + feedforward, reference_kdot, feedforward


@njit(cache=True)
def previewed_curvature(
    table: np.ndarray,
    record: np.ndarray,
    s_m: float,
    speed_mps: float,
    preview_s: float,
    first_s: float,
    second_s2: float,
    window_m: float,
) -> tuple[float, float]:  # pragma: no cover - compiled
    """(kappa + first_s dkappa/dt + second_s2 d2kappa/dt2 1/m, dkappa/ds 1/m^2) of the path speed x preview_s ahead
    of s_m, with d/dt = V d/ds at the speed V now (the speed's own change is left out); the derivatives are central
    differences over window_m (dkappa/ds the mean slope over the window, d2kappa/ds2 the second difference over half
    of it), so a clothoid's corner in curvature rate is spread over the window, not a one-step impulse. The path:
    `path_search.CompiledPath`'s table and record."""
    path_curvature = table[PATH_CURVATURE]
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    s, half = s_m + speed_mps * preview_s, 0.5 * window_m
    ahead = value_at(path_curvature, s + half, spacing, length, closed)
    middle = value_at(path_curvature, s, spacing, length, closed)
    behind = value_at(path_curvature, s - half, spacing, length, closed)
    slope = (ahead - behind) / window_m
    second = (ahead - 2.0 * middle + behind) / (half * half)
    return middle + first_s * speed_mps * slope + second_s2 * speed_mps * speed_mps * second, slope


@njit(cache=True)
def lag_inverse_curvature(
    table: np.ndarray,
    record: np.ndarray,
    s_m: float,
    speed_mps: float,
    dead_time_s: float,
    omega_n_rad_s: float,
    zeta: float,
    steady_state_gain: float,
    window_m: float,
) -> tuple[float, float]:  # pragma: no cover - compiled
    """(kinematic curvature to steer 1/m, its path curvature rate dkappa/ds 1/m^2): the identified
    steering-to-path-curvature lag of Eq. 5 inverted along the path (`ClothoidConfig.feedforward_inversion`).

    Eq. 5 makes the path curvature K wn^2 / (s^2 + 2 zeta wn s + wn^2) e^(-T s) times the kinematic curvature
    steered, so the steering that makes the vehicle follow the path's curvature kappa_p exactly is

        u(t) = (kappa_p + 2 zeta / wn dkappa_p/dt + 1 / wn^2 d2kappa_p/dt^2)(t + T) / K,

    read along the path from the foot point s_m by `previewed_curvature` (T: dead_time_s, the lag's delay plus any
    known delay; the path: `path_search.CompiledPath`'s table and record). omega_n_rad_s NaN (no identified lag):
    the path's curvature there, over K."""
    first = second = 0.0
    if not math.isnan(omega_n_rad_s):
        first, second = 2.0 * zeta / omega_n_rad_s, 1.0 / (omega_n_rad_s * omega_n_rad_s)
    curvature, slope = previewed_curvature(table, record, s_m, speed_mps, dead_time_s, first, second, window_m)
    return curvature / steady_state_gain, slope / steady_state_gain
