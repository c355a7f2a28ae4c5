"""Tyre lateral force: slip angle, Pacejka's magic formula, and the relaxation-length lag.

Slip angle of a contact moving at (vx, vy) in the wheel frame: alpha = atan2(vy, vx) (Pacejka, "Tyre and Vehicle
Dynamics", 3rd ed., chapter 1; a positive alpha gives a negative force). For a steered wheel
at angle delta, the axle-centre velocity (u, vy) in the body frame is rotated into the wheel frame first.

Steady-state force, magic formula (Pacejka, chapter 4, without shifts):
    Fy = -D sin(C atan(B alpha - E (B alpha - atan(B alpha)))),
with D the peak force (friction x load), C the shape factor, E the curvature factor and B = k / (C mu) so that the
cornering stiffness dFy/dalpha at zero slip, B C D, is k x load. E = 0 gives -D sin(C atan(B alpha)).

Relaxation length sigma (Pacejka, chapter 7, the single-contact-point
transient model): the force lags its steady value as a first-order system
over the distance rolled, dFy/dt = (u / sigma)(Fy_ss - Fy); u is held at least at the kinematic blend's lower
speed so that the lag stays finite at standstill.
"""

from __future__ import annotations

import math

from numba import njit

#: Gravitational acceleration (m/s^2) the vehicle models' axle loads are computed with: CommonRoad's rounded
#: g = 9.81 (commonroad-vehicle-models, `vehicle_dynamics_st.py` and `vehicle_dynamics_mb.py`; Althoff &
#: Wuersching, "CommonRoad: Vehicle Models", 2020), not standard gravity (9.80665, `scipy.constants.g`, which the
#: speed profile, limits and tuning use): the cars take CommonRoad's parameters and match its models, and every
#: plant computes its loads with the same g.
COMMONROAD_G_MPS2 = 9.81


@njit(cache=True)
def slip_angle(vy, vx):  # pragma: no cover - compiled
    """Slip angle (rad) of a contact moving at (vx, vy) in the wheel frame; zero for a wheel standing still."""
    return math.atan2(vy, vx) if abs(vx) + abs(vy) > 1e-9 else 0.0


@njit(cache=True)
def steered_slip_angle(vy, u, sin_delta, cos_delta):  # pragma: no cover - compiled
    """Slip angle (rad) of a wheel steered by delta whose axle centre moves at (u, vy) in the body frame."""
    return slip_angle(vy * cos_delta - u * sin_delta, u * cos_delta + vy * sin_delta)


@njit(cache=True)
def magic_formula(alpha, peak, stiffness_factor, shape, curvature):  # pragma: no cover - compiled
    """Steady lateral force (N) at slip angle alpha (rad): -D sin(C atan(B alpha - E (B alpha - atan(B alpha))))."""
    x = stiffness_factor * alpha
    if curvature != 0.0:  # E = 0 leaves x as it is; skip the extra arctangent
        x = x - curvature * (x - math.atan(x))
    return -peak * math.sin(shape * math.atan(x))


@njit(cache=True)
def relaxation_rate(u, min_speed, relaxation_length):  # pragma: no cover - compiled
    """u / sigma (1/s), the rate at which a force approaches its steady value, with u held at least min_speed."""
    return max(u, min_speed) / relaxation_length
