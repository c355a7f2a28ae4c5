"""Motion of the reference point (the rear-axle centre) from a body's CG motion, and its path curvature.

For a rigid body with longitudinal speed u, CG lateral velocity v and yaw rate r (body frame), the point a distance
b behind the CG moves at (u, v_ref) with v_ref = v - b r, and accelerates (time derivative in the rotating body
frame plus the transport terms; e.g. Rajamani, "Vehicle Dynamics and Control", 2nd ed., chapter 2):
    a_x = u' - v_ref r,   a_y = v' - b r' + u r.
Its path curvature is that of a planar curve traced at velocity (u, v_ref) with acceleration (a_x, a_y):
    kappa = (u a_y - v_ref a_x) / (u^2 + v_ref^2)^(3/2),
and, standing still, the kinematic tan(delta) / L.

Its velocity in the world frame, for a heading yaw: (u cos(yaw) - v_ref sin(yaw), u sin(yaw) + v_ref cos(yaw)).

`reference_point` and `world_velocity` are compiled for the compiled models; `reference_point_python` is the same
code run by Python (CommonRoad's multi-body model), whose floating-point results it keeps.
"""

from __future__ import annotations

import math

from numba import njit


def _reference_point(u, v, r, du, dv, dr, b, delta, wheelbase):
    """(v_ref, a_x, a_y, kappa) of the point b behind the CG; see the module docstring."""
    vref = v - b * r
    ax_ref, ay_ref = du - vref * r, dv - b * dr + u * r
    speed = math.hypot(u, vref)
    kappa = (u * ay_ref - vref * ax_ref) / speed**3 if speed > 1e-3 else math.tan(delta) / wheelbase
    return vref, ax_ref, ay_ref, kappa


reference_point = njit(cache=True)(_reference_point)
reference_point_python = _reference_point


@njit(cache=True)
def world_velocity(u, vref, yaw):  # pragma: no cover - compiled
    """(dx/dt, dy/dt) of a point moving at (u, vref) in a body frame with heading yaw."""
    cy, sy = math.cos(yaw), math.sin(yaw)
    return u * cy - vref * sy, u * sy + vref * cy
