"""The sideslip's release (`tuning/release_fit.py`): the push and release time against logs whose sideslip is known
exactly, the steady sideslip's grid against its interpolation, what is refused; and on the plants, the steady
sideslip against the linear single track's and the release against what the truck and the kinematic model do."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.constants import g as G_MPS2

from controllers.clothoid.preview_model import HANDLING_GRID_G
from controllers.clothoid.sideslip_release import RELEASE_TIME_RANGE_S
from tuning.handling_fit import STEADY_WINDOW_S, SteadyTurn, fit_handling
from tuning.log_file import VehicleLog
from tuning.maneuvers import Braking
from tuning.release_fit import MIN_PUSH_RAD, fit_release, release_braking, steady_sideslip_grid
from tuning.schedule import handling_logs, release_log
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

SPEED_MPS = 8.0
YAW_RATE_RAD_S = 0.2
BRAKING = Braking(5.0, 0.5)
TURNS = (SteadyTurn(0.1, 1.0, math.radians(-0.5)), SteadyTurn(0.2, 1.0, math.radians(-1.2)))


def _braked_log(push_rad: float, time_s: float, final_rad: float = -0.02, left: bool = True) -> VehicleLog:
    """A turn at YAW_RATE_RAD_S (right: negated) whose rear-axle sideslip is final_rad, then push_rad more when the
    braking ends, decaying as exp(-t / time_s) after it: positions integrated on a 1 kHz grid, logged at 100 Hz."""
    sign = 1.0 if left else -1.0
    fine = np.arange(0.0, BRAKING.end_s + 8.0 + 1e-9, 0.001)
    after = np.clip(fine - BRAKING.end_s, 0.0, None)
    sideslip = sign * (final_rad + np.where(fine >= BRAKING.end_s, push_rad * np.exp(-after / time_s), push_rad))
    yaw = sign * YAW_RATE_RAD_S * fine
    course = yaw + sideslip
    step = 0.5 * (np.cos(course[1:]) + np.cos(course[:-1])), 0.5 * (np.sin(course[1:]) + np.sin(course[:-1]))
    x = np.concatenate([[0.0], np.cumsum(step[0])]) * SPEED_MPS * 0.001
    y = np.concatenate([[0.0], np.cumsum(step[1])]) * SPEED_MPS * 0.001
    logged = slice(None, None, 10)
    t = fine[logged]
    return VehicleLog(
        "braked", t, np.zeros(t.size), np.full(t.size, SPEED_MPS), x[logged], y[logged], yaw[logged],
        np.full(t.size, sign * YAW_RATE_RAD_S),
    )  # fmt: skip


@pytest.mark.parametrize(("push_deg", "time_s", "left"), [(-1.5, 0.08, True), (0.3, 0.4, True), (-1.5, 0.08, False)])
def test_the_push_and_release_time_of_a_known_sideslip(push_deg: float, time_s: float, left: bool) -> None:
    """The push and the release time as of a left turn whichever way the turn goes, within what 100 Hz positions
    resolve: the sideslip from their central differences averages the kink where the release starts over a sample
    (the push within dt / 2 time_s of itself, plus 2e-5 rad), and the release time within half a sample."""
    dt = 0.01
    fit = fit_release(TURNS, _braked_log(math.radians(push_deg), time_s, left=left), BRAKING)
    assert fit is not None
    push = math.radians(push_deg)
    assert fit.push_rad == pytest.approx(push, abs=abs(push) * dt / (2.0 * time_s) + 2e-5)
    assert fit.release.release_time_s == pytest.approx(time_s, abs=dt / 2.0)
    assert fit.release.rate_1ps == pytest.approx(1.0 / fit.release.release_time_s, rel=1e-12)


def test_a_push_too_small_to_time_is_not_identified() -> None:
    fit = fit_release(TURNS, _braked_log(0.5 * MIN_PUSH_RAD, 0.1), BRAKING)
    assert fit is not None and fit.release.release_time_s == math.inf and fit.release.rate_1ps == 0.0
    assert "not timed" in fit.summary()


def test_the_steady_sideslip_is_the_sideslip_per_g_interpolated_then_held() -> None:
    """Per g -5 deg at 0.1 g, -6 at 0.2 g: linear between, held beyond (so in proportion below 0.1 g and above
    0.2 g), zero at zero; turns without a sideslip are left out; none with one: None."""
    grid = steady_sideslip_grid((*TURNS, SteadyTurn(0.3, 1.0)))
    assert grid is not None
    per_g = np.interp(HANDLING_GRID_G, (0.1, 0.2), np.radians((-5.0, -6.0)))
    np.testing.assert_allclose(grid, np.asarray(HANDLING_GRID_G) * per_g, rtol=1e-12, atol=1e-15)
    assert grid[0] == 0.0
    assert steady_sideslip_grid((SteadyTurn(0.3, 1.0),)) is None
    assert fit_release((SteadyTurn(0.3, 1.0),), None, None) is None
    unbraked = fit_release(TURNS, None, None)
    assert unbraked is not None and math.isnan(unbraked.push_rad) and unbraked.release.rate_1ps == 0.0
    assert unbraked.summary() == "release: no braked turn"


def test_a_log_without_positions_or_too_short_is_refused() -> None:
    log = _braked_log(-0.02, 0.1)
    bare = VehicleLog("bare", log.t_s, log.steer_wheel_rad, log.speed_mps, yaw_rate_rad_s=log.yaw_rate_rad_s)
    with pytest.raises(WorkbenchInputError, match="bare: the sideslip needs x_m, y_m"):
        fit_release(TURNS, bare, BRAKING)
    late = Braking(log.t_s[-1] - STEADY_WINDOW_S + 0.5, 0.2)
    with pytest.raises(WorkbenchInputError, match=r"the braking ends at .* the steady turn after it"):
        fit_release(TURNS, log, late)


def test_the_braking_takes_at_most_a_quarter_of_the_speed() -> None:
    assert release_braking(100.0).duration_s == 1.0
    assert release_braking(20.0).duration_s == pytest.approx(0.25 * 20.0 / 3.6 / 2.0, rel=1e-12)


def test_the_dynamic_bicycles_steady_sideslip_is_the_linear_single_tracks() -> None:
    """The rear-axle sideslip of the single track's steady turns against the linear tyre's: the rear axle carries
    m a_y l_f / L on a cornering stiffness k_r m g l_f / L, so it slips -a_y / (g k_r); within 2 % up to 0.2 g (its
    tyres' curve bends beyond)."""
    vehicle = make_vehicle("dynamic-bicycle")
    fit = fit_handling(handling_logs(vehicle, 60.0), vehicle.geometry, 0.2)
    k_r = vehicle.params.rear_cornering_coeff_per_rad
    checked = [t for t in fit.turns if t.lat_accel_g <= 0.2 + 1e-9]
    assert len(checked) >= 3
    for turn in checked:
        assert turn.sideslip_rad == pytest.approx(-turn.lat_accel_g / k_r, rel=0.02)


def test_the_loaded_truck_pushes_out_and_the_kinematic_model_does_not() -> None:
    """Braked at 2 m/s^2 in a 0.2 g turn at 20 km/h, the loaded truck's rear axle ends the braking over 1 deg beyond
    the steady turn at the lower speed, released within 0.15 s; the kinematic bicycle's rear axle never slides
    (no push to time: inf)."""
    truck = make_vehicle("tractor-semitrailer")
    turns = fit_handling(handling_logs(truck, 20.0), truck.geometry, 0.2).turns
    braked = release_log(truck, 20.0)
    assert braked is not None
    fit = fit_release(turns, *braked)
    assert fit is not None
    assert abs(math.degrees(fit.push_rad)) > 1.0
    assert RELEASE_TIME_RANGE_S[0] < fit.release.release_time_s < 0.15
    kinematic = make_vehicle("kinematic-bicycle")
    turns = fit_handling(handling_logs(kinematic, 20.0), kinematic.geometry, 0.2).turns
    braked = release_log(kinematic, 20.0)
    assert braked is not None
    fit = fit_release(turns, *braked)
    assert fit is not None and fit.release.release_time_s == math.inf


def test_a_turn_past_the_lock_gives_no_braked_log() -> None:
    truck = make_vehicle("tractor-semitrailer")
    v = 5.0 / 3.6
    assert 0.2 * G_MPS2 / (v * v) > 0.1  # tighter than any truck's lock
    assert release_log(truck, 5.0) is None
