"""Identification of the vehicle's preview responses (`PreviewResponse`) from the same open-loop logs as the lag of
Eq. 5: how the steering, and the measured curvature (yaw rate / speed), of a vehicle that drives a path depend on
that path's curvature before and after where the vehicle is.

Why. The clothoid controller's feed-forward inverts the identified lag (the steering that makes the vehicle drive the
path's curvature) and its reference pose starts on the curvature such a vehicle would measure
(`controllers/clothoid/path_feedforward.py`). Both are exact only as far as Eq. 5 describes the vehicle. A car's
second-order lag explains its logs to a few hundredths of a percent (NRMSE); the loaded tractor-semitrailer's to
about 1-2 %, with zeta at its bound: its trailer and tandems add slow responses (the tractor's path still creeps
seconds after the steering settles) that no second-order lag holds, and the two lag-derived signals are off by
several times the car's (`benchmarks/cte_breakdown.py`).

What. Two finite impulse responses on the path curvature kappa_p the rear axle drives, at times tau_k from
past_s before to future_s after the present, tap_spacing_s apart, fitted by least squares over all logs:

    steering kinematic curvature u(t)  ~ sum_k h_k kappa_p(t + tau_k)
    measured curvature r(t) / V        ~ sum_k g_k kappa_p(t + tau_k)

regularised by ridge x (the regressors' mean energy) x (|h|^2 + smoothness |D2 h|^2) (D2: the second difference),
so that the taps the logs do not determine go to zero smoothly instead of fitting noise. The measured taps are
scaled to sum to one: in a steady turn the yaw rate over speed is the path's curvature (rigid-body kinematics), and
a reference that differs from it by the fit's error would leave the feedback holding that error as an offset in
every arc. The steering taps' sum is the vehicle's steady-state steering over curvature (its understeer), as the
logs give it. Before each log starts the vehicle drove straight (the maneuvers start from rest in steering), so the
path curvature there is zero; samples whose future window passes the log's end are left out.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from controllers.clothoid.preview_model import PreviewResponse
from tuning.lag_fit import SteeringGeometry, kinematic_curvature, path_curvature, yaw_rate_curvature
from tuning.log_file import VehicleLog
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.geometry import VehicleGeometry

#: s: the ranges of how far before (past_s) and after (future_s) the present the taps may reach; the CLI's
#: --preview-past-s / --preview-future-s and the preset options check the same.
PAST_RANGE_S = (0.0, 30.0)
FUTURE_RANGE_S = (0.0, 10.0)


@dataclass(frozen=True)
class PreviewFitOptions:
    """How `fit_preview` fits the preview responses (module docstring)."""

    tap_spacing_s: float = 0.05  # time between taps (s), in [0.005, 0.5]; a whole number of log samples
    past_s: float = 8.0  # how far before the present the taps reach (s), in [0, 30]: the slow responses' settling
    future_s: float = 2.0  # how far after the present the taps reach (s), in [0, 10]: the lag's preview
    ridge: float = 1e-3  # the regularisation's weight relative to the regressors' mean energy (-), in [0, 1e3]
    smoothness: float = 10.0  # the second difference's weight in the regularisation (-), in [0, 1e6]
    smooth_s: float = 0.3  # the Savitzky-Golay window of the path's derivatives (s), in [0, 10] (`path_curvature`)
    lat_accel_g: float = 0.2  # the kinematic lateral acceleration (g), in [0.001, 1], of the logs tuning.schedule
    # makes for them (fit_preview fits the logs it is given): the middle of the range the feed-forward serves
    # (corners planned up to 0.3 g, the handling gain's grid to 0.4 g), so that the taps' dynamics, not only their
    # gain, are the tyres' in the corners; the lags of Eq. 5, a linearisation for the loop, stay at the schedule's 0.1 g

    def __post_init__(self) -> None:
        require_in_range("tap_spacing_s", self.tap_spacing_s, 0.005, 0.5, "s")
        require_in_range("past_s", self.past_s, *PAST_RANGE_S, "s")
        require_in_range("future_s", self.future_s, *FUTURE_RANGE_S, "s")
        require_in_range("ridge", self.ridge, 0.0, 1e3)
        require_in_range("smoothness", self.smoothness, 0.0, 1e6)
        require_in_range("smooth_s", self.smooth_s, 0.0, 10.0, "s")
        require_in_range("lat_accel_g", self.lat_accel_g, 0.001, 1.0, "g")

    @property
    def tap_range(self) -> tuple[int, int]:
        """(first, last) tap index: tau_k = k x tap_spacing_s for k in [first, last]."""
        return -round(self.past_s / self.tap_spacing_s), round(self.future_s / self.tap_spacing_s)


@dataclass(frozen=True)
class PreviewFit:
    """The fitted responses and how well they explain the logs: steering_nrmse and measured_nrmse, the RMS over the
    logs of RMS(error) / range(signal) of the steering's kinematic curvature and of yaw rate / speed (-)."""

    response: PreviewResponse  # the fitted taps (the measured ones summing to one)
    steering_nrmse: float  # -, >= 0: the steering's NRMSE over the logs
    measured_nrmse: float  # -, >= 0: yaw rate / speed's NRMSE over the logs

    def summary(self) -> str:
        """One line for the tuning's progress.

        Returns
        -------
        str
            The taps' number and start, each response's NRMSE and the steering taps' sum (its steady-state gain).
        """
        r = self.response
        return (
            f"preview {len(r.steering_taps)} taps from {r.first_tap_s:g} s, steering NRMSE {self.steering_nrmse:.4f} "
            f"(sum {sum(r.steering_taps):.4f}), measured NRMSE {self.measured_nrmse:.4f}"
        )


def fit_preview(
    logs: Sequence[VehicleLog], geometry: VehicleGeometry | SteeringGeometry, options: PreviewFitOptions | None = None
) -> PreviewFit:
    """Fit the preview responses of one speed's logs (module docstring).

    Parameters
    ----------
    logs : sequence of VehicleLog
        Open-loop logs at one held speed, each with rear-axle positions and yaw rate, sampled at a whole fraction of
        tap_spacing_s, longer than the taps' future window.
    geometry : VehicleGeometry or SteeringGeometry
        The wheelbase and steering ratio that give the steering's kinematic curvature.
    options : PreviewFitOptions or None
        The taps and the regularisation (None: the defaults).

    Returns
    -------
    PreviewFit
        The responses (`PreviewResponse`) and their NRMSE over the logs.

    Raises
    ------
    WorkbenchInputError
        No log; a log without positions or yaw rate, stopped, sampled at other than a whole fraction of the tap
        spacing, or not longer than the future window; logs that do not turn the vehicle, or whose yaw rate over
        speed is not the path's curvature in a steady turn (its steady-state gain outside 0.5-2).
    """
    options = options or PreviewFitOptions()
    if not logs:
        raise WorkbenchInputError("fit_preview needs at least one log; got none")
    first, last = options.tap_range
    blocks = [_regression(log, geometry, options, first, last) for log in logs]
    x = np.vstack([b[0] for b in blocks])
    taps = last - first + 1
    gram = x.T @ x
    if not np.trace(gram) > 0.0:
        raise WorkbenchInputError(
            "the logs' path curvature is zero throughout: they do not excite the vehicle, and the preview responses "
            "need steering that turns it"
        )
    second = np.diff(np.eye(taps), 2, axis=0)
    penalty = options.ridge * np.trace(gram) / taps * (np.eye(taps) + options.smoothness * second.T @ second)
    targets = np.column_stack([np.concatenate([b[column] for b in blocks]) for column in (1, 2)])
    solved = np.linalg.solve(gram + penalty, x.T @ targets)
    steering, measured = solved[:, 0], solved[:, 1]
    if not 0.5 <= measured.sum() <= 2.0:  # a steady turn's is one; far off it, the yaw rate is not this vehicle's
        raise WorkbenchInputError(
            f"the measured response's steady-state gain is {measured.sum():.3g}, where a steady turn gives 1 (yaw rate "
            "/ speed = the path's curvature); allowed 0.5-2: check the logs' yaw rate (rad/s, positive turning left) "
            "and positions"
        )
    measured = measured / measured.sum()
    response = PreviewResponse(first * options.tap_spacing_s, options.tap_spacing_s, tuple(steering), tuple(measured))

    def nrmse(column: int, fitted: np.ndarray) -> float:
        errors = [
            math.sqrt(float(np.mean((b[0] @ fitted - b[column]) ** 2))) / max(float(np.ptp(b[column])), 1e-12)
            for b in blocks
        ]
        return math.sqrt(float(np.mean(np.square(errors))))

    return PreviewFit(response, nrmse(1, steering), nrmse(2, measured))


def _regression(
    log: VehicleLog, geometry: VehicleGeometry | SteeringGeometry, options: PreviewFitOptions, first: int, last: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(the path curvature at each tap of each sample kept, the steering's kinematic curvature, yaw rate / speed)
    of one log, at the taps' spacing."""
    if log.yaw_rate_rad_s is None:
        raise WorkbenchInputError(f"{log.name}: no yaw_rate_rad_s column; the preview fit needs the yaw rate")
    step = options.tap_spacing_s / log.dt_s
    if abs(step - round(step)) > 1e-6 * step or round(step) < 1:
        raise WorkbenchInputError(
            f"{log.name}: the tap spacing {options.tap_spacing_s:g} s must be a whole number of the log's samples "
            f"({log.dt_s:g} s)"
        )
    kappa = path_curvature(log, options.smooth_s)
    index = np.arange(0, len(log), round(step))
    n = index.size
    if n <= last:
        raise WorkbenchInputError(
            f"{log.name}: {log.duration_s:g} s is too short for the preview fit's future window of "
            f"{options.future_s:g} s"
        )
    sampled = kappa[index]
    padded = np.concatenate([np.zeros(max(0, -first)), sampled, np.zeros(max(0, last))])
    offset = max(0, -first)
    kept = n - max(0, last)  # the samples whose future window lies within the log
    columns = [padded[offset + k : offset + k + kept] for k in range(first, last + 1)]
    steering = kinematic_curvature(log.steer_wheel_rad, geometry)[index][:kept]
    measured = yaw_rate_curvature(log)[index][:kept]
    return np.column_stack(columns), steering, measured


__all__ = ["PreviewFit", "PreviewFitOptions", "fit_preview"]
