"""The preview responses' fit (`tuning.preview_fit`) against logs through a known lag (`synthetic_logs`): the
steering response is the inverse of gain x Eq. 5 (x delay), whose steady-state gain is 1 / K and whose
low-frequency delay (first moment over its sum) is the dead time plus 2 zeta / omega_n; the measured response of a
log whose yaw rate / speed is the path's curvature is the identity (sum one, first moment zero). It generalises to a
maneuver it was not fitted on; bad input is refused, naming the value."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_logs import GEOMETRY, synthetic_frame

from tuning.lag_fit import kinematic_curvature, path_curvature
from tuning.log_file import VehicleLog
from tuning.preview_fit import PreviewFitOptions, fit_preview
from workbench.base.errors import WorkbenchInputError

OMEGA_N, ZETA, GAIN, DELAY_S = 8.0, 0.7, 0.9, 0.1
KINDS = ("dlc", "step-series", "chirp")


def _logs(kinds: tuple[str, ...] = KINDS, **kwargs: float) -> list[VehicleLog]:
    frames = (
        synthetic_frame(k, OMEGA_N, ZETA, gain=GAIN, delay_s=DELAY_S, seed=i, **kwargs) for i, k in enumerate(kinds)
    )
    return [VehicleLog.from_frame(frame, kind) for frame, kind in zip(frames, kinds, strict=True)]


def _moments(first_tap_s: float, spacing_s: float, taps: tuple[float, ...]) -> tuple[float, float]:
    h = np.asarray(taps)
    tau = first_tap_s + spacing_s * np.arange(h.size)
    return float(h.sum()), float((tau * h).sum() / h.sum())


@pytest.mark.parametrize(("spacing_s", "delay_tolerance_s"), [(0.01, 0.002), (0.05, 0.02)])
def test_the_responses_of_a_known_lag(spacing_s: float, delay_tolerance_s: float) -> None:
    """Gain and low-frequency delay of both responses; the delay within a fraction of the taps' spacing (the taps
    resolve the lag's derivatives no finer). The steering's NRMSE is that of the steps' corners, which taps
    spacing_s apart cannot follow."""
    fit = fit_preview(_logs(), GEOMETRY, PreviewFitOptions(past_s=2.0, tap_spacing_s=spacing_s))
    r = fit.response
    gain, centroid = _moments(r.first_tap_s, r.tap_spacing_s, r.steering_taps)
    assert gain == pytest.approx(1.0 / GAIN, rel=0.005)
    assert centroid == pytest.approx(DELAY_S + 2.0 * ZETA / OMEGA_N, abs=delay_tolerance_s)
    gain, centroid = _moments(r.first_tap_s, r.tap_spacing_s, r.measured_taps)
    assert gain == pytest.approx(1.0, abs=1e-9)
    assert centroid == pytest.approx(0.0, abs=0.002)
    assert fit.steering_nrmse < 0.03 and fit.measured_nrmse < 0.005


def test_it_predicts_a_maneuver_it_was_not_fitted_on() -> None:
    """Fitted on the dlc and the step series, the steering of the chirp from its path curvature within 3 % NRMSE."""
    options = PreviewFitOptions(past_s=2.0)
    response = fit_preview(_logs(KINDS[:2]), GEOMETRY, options).response
    (chirp,) = _logs(KINDS[2:])
    step = round(options.tap_spacing_s / chirp.dt_s)
    kappa = path_curvature(chirp)[::step]
    steering = kinematic_curvature(chirp.steer_wheel_rad, GEOMETRY)[::step]
    first = round(response.first_tap_s / options.tap_spacing_s)
    taps = np.asarray(response.steering_taps)
    padded = np.concatenate([np.zeros(-first), kappa, np.zeros(taps.size)])
    predicted = np.array([padded[i : i + taps.size] @ taps for i in range(kappa.size)])
    kept = kappa.size - (taps.size + first)
    error = np.sqrt(np.mean((predicted[:kept] - steering[:kept]) ** 2)) / np.ptp(steering)
    assert error < 0.03


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"tap_spacing_s": 0.0}, "tap_spacing_s"),
        ({"past_s": float("nan")}, "past_s"),
        ({"future_s": -1.0}, "future_s"),
        ({"ridge": 1e4}, "ridge"),
        ({"lat_accel_g": 0.0}, "lat_accel_g"),
    ],
)
def test_options_out_of_range_are_refused(options: dict[str, float], match: str) -> None:
    with pytest.raises(WorkbenchInputError, match=match):
        PreviewFitOptions(**options)


def test_bad_logs_are_refused() -> None:
    with pytest.raises(WorkbenchInputError, match="at least one log"):
        fit_preview([], GEOMETRY)
    with pytest.raises(WorkbenchInputError, match="whole number of the log's samples"):
        fit_preview(_logs(KINDS[:1]), GEOMETRY, PreviewFitOptions(tap_spacing_s=0.015))
    with pytest.raises(WorkbenchInputError, match="too short"):
        fit_preview(_logs(KINDS[:1], duration_s=2.0), GEOMETRY, PreviewFitOptions(future_s=3.0))
    flipped = synthetic_frame("dlc", OMEGA_N, ZETA).assign(yaw_rate_rad_s=lambda f: -f["yaw_rate_rad_s"])
    with pytest.raises(WorkbenchInputError, match=r"steady-state gain is -0.99\d, where a steady turn gives 1"):
        fit_preview([VehicleLog.from_frame(flipped, "dlc")], GEOMETRY)
    no_yaw = synthetic_frame("dlc", OMEGA_N, ZETA).drop(columns=["yaw_rate_rad_s"])
    with pytest.raises(WorkbenchInputError, match="yaw_rate_rad_s"):
        fit_preview([VehicleLog.from_frame(no_yaw, "dlc")], GEOMETRY)
