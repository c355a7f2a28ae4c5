"""The blend from the dynamic (tyre-force) model to the kinematic (no-slip) one at low speed.

Tyre-force models are singular at standstill: slip angles atan2(vy, vx) are undefined at vx = 0 and the yaw
dynamics stiffen as 1/vx. Below a speed band [v_low, v_high] the lateral accelerations are therefore taken from the
kinematic vehicle (every axle rolling without lateral slip), with a smoothstep weight (Ebert et al., "Texturing and
Modeling", the cubic Hermite 3w^2 - 2w^3, continuous in value and slope at both ends of the band):
    w = smoothstep((u - v_low) / (v_high - v_low)),   x'' = w x''_dynamic + (1 - w) x''_kinematic,
as CommonRoad's single-track model switches to its kinematic model below 0.1 m/s (Althoff & Wuersching,
"CommonRoad: Vehicle Models", 2020), here blended instead of switched. The kinematic branch adds a first-order pull
(x_kinematic - x) / KINEMATIC_PULL_S so that the lateral states converge onto the no-slip values instead of merely
following their rates.
"""

from __future__ import annotations

from numba import njit

from workbench.base.errors import WorkbenchInputError

#: Time constant (s) with which the blended kinematic branch pulls the lateral states onto the no-slip values.
KINEMATIC_PULL_S = 0.02


@njit(cache=True)
def blend_weight(u, v_low, v_high):  # pragma: no cover - compiled
    """Weight of the dynamic branch: 0 at or below v_low, 1 at or above v_high, smoothstep between."""
    w = min(max((u - v_low) / (v_high - v_low), 0.0), 1.0)
    return w * w * (3.0 - 2.0 * w)


@njit(cache=True)
def blend(w, dynamic, kinematic):  # pragma: no cover - compiled
    """w x dynamic + (1 - w) x kinematic."""
    return w * dynamic + (1.0 - w) * kinematic


@njit(cache=True)
def pull(kinematic_value, value):  # pragma: no cover - compiled
    """The kinematic branch's pull of a lateral state onto its no-slip value, (target - value) / KINEMATIC_PULL_S."""
    return (kinematic_value - value) / KINEMATIC_PULL_S


def check_blend_speeds(low_mps: float, high_mps: float) -> None:
    """The blend band must be a band: kinematic_blend_low_mps < kinematic_blend_high_mps."""
    if low_mps >= high_mps:
        raise WorkbenchInputError(
            f"kinematic_blend_low_mps must be < kinematic_blend_high_mps = {high_mps}; got {low_mps!r}"
        )
