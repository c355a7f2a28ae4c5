"""The sideslip's release (`sideslip_release.py`): what a release accepts, its table row, the steady sideslip read
from it (linear on the grid, in proportion beyond, odd in lateral acceleration); in the controller, nothing
released where the plan holds the speed, and at a braked hairpin the delayed loop brought near the delay-free
one; in the loop analysis, the release of the lags' own sideslip changing nothing, the fast margins those of the
whole loop, and the floor keeping the margins with the release in the loop where the controller may release."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.constants import g as G_MPS2

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig, LeadFilterParams
from controllers.clothoid.loop_analysis import (
    LoopSettings,
    PlantLags,
    controller,
    loop_margins,
    loop_transfer,
    margins,
    plant,
)
from controllers.clothoid.preview_model import HANDLING_GRID_G
from controllers.clothoid.sideslip_release import SideslipRelease, steady_sideslip
from tuning.own_tuning import tuned_controller
from tuning.tuning_dirs import read_vehicle_tuning, shipped_tuning_root
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.conditions import load_conditions
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle
from workbench.vehicles.steering_lag import SteeringLag

#: A rear axle slipping 0.5 deg per 0.1 g, a little more above 0.2 g.
GRID = tuple(math.radians(-5.0 * a - (20.0 * (a - 0.2) ** 2 if a > 0.2 else 0.0)) for a in HANDLING_GRID_G)


def test_the_row_is_the_rate_then_the_grid() -> None:
    release = SideslipRelease(GRID, 0.08)
    assert release.row() == [pytest.approx(12.5, rel=1e-12), *GRID]
    assert SideslipRelease(GRID).rate_1ps == 0.0  # not identified: nothing released


@pytest.mark.parametrize(
    ("grid", "time", "message"),
    [
        (GRID[:-1], 0.1, "steady_sideslip_rad must be 9 sideslips"),
        ((1e-3, *GRID[1:]), 0.1, "the first 0"),
        ((*GRID[:-1], math.nan), 0.1, "each within"),
        ((*GRID[:-1], math.radians(25.0)), 0.1, "each within"),
        (GRID, 0.0, r"release_time_s must be in \[0.001, 10\] s, or inf"),
        (GRID, math.nan, "release_time_s must be"),
        (GRID, True, "release_time_s must be"),
        (GRID, 11.0, "release_time_s must be"),
    ],
)
def test_an_impossible_release_is_refused(grid: tuple[float, ...], time: float, message: str) -> None:
    with pytest.raises(WorkbenchInputError, match=message):
        SideslipRelease(grid, time)


def test_on_the_grid_the_steady_sideslip_is_the_grids() -> None:
    row = np.array(SideslipRelease(GRID, 0.1).row())
    for a, expected in zip(HANDLING_GRID_G, GRID, strict=True):
        assert steady_sideslip(row, a * G_MPS2) == pytest.approx(expected, rel=1e-12, abs=1e-18)


@settings(max_examples=80, deadline=None)
@given(lat_accel_mps2=st.floats(-12.0, 12.0))
def test_the_steady_sideslip_is_the_grids_interpolation_odd_and_proportional_beyond(lat_accel_mps2: float) -> None:
    """Against np.interp on the grid within it; beyond its last point, the last point's sideslip per g times the
    lateral acceleration; a right turn's the opposite of the left turn's."""
    row = np.array(SideslipRelease(GRID, 0.1).row())
    a = abs(lat_accel_mps2) / G_MPS2
    top = HANDLING_GRID_G[-1]
    expected = np.interp(a, HANDLING_GRID_G, GRID) if a <= top else GRID[-1] * a / top
    got = steady_sideslip(row, lat_accel_mps2)
    assert math.copysign(1.0, lat_accel_mps2) * got == pytest.approx(expected, rel=1e-9, abs=1e-15)
    assert steady_sideslip(row, -lat_accel_mps2) == pytest.approx(-got, abs=1e-15)


def test_a_release_read_as_a_rate() -> None:
    """As a tuning file holds it: rate 0 is not identified (inf), a rate its time's inverse; out of range refused."""
    assert SideslipRelease.from_rate(GRID, 0.0).release_time_s == math.inf
    assert SideslipRelease.from_rate(GRID, 12.5).release_time_s == pytest.approx(0.08, rel=1e-15)
    for rate in (-1.0, 0.05, 2000.0, math.nan, "fast", True):
        with pytest.raises(WorkbenchInputError, match=r"release_rate_1ps must be in \[0.1, 1000\] 1/s, or 0"):
            SideslipRelease.from_rate(GRID, rate)


TRUCK = make_vehicle("tractor-semitrailer")
#: A hairpin like Zandvoort's (radius 11.4 m): 12 m clothoids either side of a 7.5 m arc; the scenario plans
#: braking into it and accelerating out (its 0.3 g profile).
HAIRPIN = (
    ClothoidChain().straight(80.0).clothoid_to(-1 / 11.4, 12.0).arc(7.5).clothoid_to(0.0, 12.0).straight(60.0)
).to_path("hairpin")


#: A straight, a clothoid into a 30 m arc, a clothoid out and a straight (the weaving measurements' bend).
BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).straight(40.0)
BEND_PATH = BEND.to_path("bend")


def _commands(path: ReferencePath, release: bool, measurements: list[Measurement]) -> list[float]:
    controller = tuned_controller("clothoid", TRUCK, ClothoidConfig(known_delay_s=0.11, sideslip_release=release))
    controller.reset(path, 0.02)
    return [controller.step(m, path) for m in measurements]


def test_where_the_plan_holds_the_speed_nothing_is_released(weaving) -> None:
    """The truck's tuning has a release at every speed it was braked at; stepping along a bend (made-up
    measurements with sideslip) with no planned speeds or a held one, the commands are those without the release,
    bit for bit; with a planned braking through the bend they are not."""
    measurements = weaving(BEND_PATH, 120, 7)
    assert read_vehicle_tuning(shipped_tuning_root() / TRUCK.name).release_table[:, 0].max() > 0.0
    held = BEND_PATH.with_speed(np.full(BEND_PATH.s_m.size, 8.0))
    for path in (BEND_PATH, held):
        assert _commands(path, True, measurements) == _commands(path, False, measurements)
    braking = BEND_PATH.with_speed(np.sqrt(np.maximum(100.0 - 2.0 * 1.5 * BEND_PATH.s_m, 1.0)))  # 1.5 m/s^2
    assert _commands(braking, True, measurements) != _commands(braking, False, measurements)


@pytest.mark.parametrize(("vehicle", "measured"), [("tractor-semitrailer", (0.126, 0.121, 0.121)),
                                                     ("dynamic-bicycle", (0.042, 0.033, 0.030))])  # fmt: skip
def test_the_release_brings_a_braked_hairpin_near_the_delay_free_loop(vehicle: str, measured: tuple) -> None:
    """Automotive conditions (pose 10 ms late, steering 0.1 s dead time), known_delay_s = 0.11, braking into the
    hairpin and accelerating out: the sideslip the braking pushes and the vehicle releases is predicted over the
    dead time, and max |CTE| falls by at least 4 mm, to within 20 % of the delay-free controller's under `ideal`
    (measured: without the release, with it, delay-free, in `measured`; with it, the floor keeps the margins of the
    loop with the release in it too, the car's 0.5 m higher at 30 km/h), the steering's oscillation and RMS rate
    within 2 % of the run without."""
    plant = make_vehicle(vehicle)
    metrics = {}
    for name, conditions, delay, release in (
        ("without", "automotive", 0.11, False), ("with", "automotive", 0.11, True), ("delay-free", "ideal", 0.0, True),
    ):  # fmt: skip
        controller = tuned_controller("clothoid", plant, ClothoidConfig(known_delay_s=delay, sideslip_release=release))
        sim = SimulationConfig(conditions=load_conditions(conditions))
        result = Simulation(Scenario("hairpin", HAIRPIN, "test"), plant, controller, sim).run()
        assert result.completed, result.message
        metrics[name] = result.metrics
    without, with_release, delay_free = (metrics[k].max_abs_cte_m for k in ("without", "with", "delay-free"))
    assert with_release <= without - 0.004
    assert with_release <= 1.2 * delay_free
    assert [round(v, 3) for v in (without, with_release, delay_free)] == pytest.approx(measured, abs=0.002)
    for key in ("steer_oscillation_deg", "rms_steer_rate_deg_s"):
        assert getattr(metrics["with"], key) <= 1.02 * getattr(metrics["without"], key)


# ---- the release in the loop analysis ----------------------------------------------------------------------------

#: The loaded truck's lags at 30 km/h (test_clothoid_delay.py's) and a lead filter.
TRUCK_LAGS = PlantLags(
    SteeringLag(28.0, 2.0, 0.24, steady_state_gain=0.935), SteeringLag(9.42, 0.94, 0.062, steady_state_gain=0.942)
)
TRUCK_LEAD = LeadFilterParams(6.0, 1.2, 24.0)
V = 30 / 3.6


def _lags_own_release(lags: PlantLags, settings: LoopSettings, speed_mps: float) -> SideslipRelease:
    """A release whose steady sideslip is the lags' own in whole periods (`delay_predictor.lag_transient_sideslip`'s
    steady part, (group delay_m - group delay_p) x the measured curvature x V, over V^2 x that curvature)."""
    path, measured = lags.path, lags.measured or lags.path
    dt = settings.sample_time_s
    taps = [round((lag.delay_s + settings.known_delay_s) / dt) for lag in (path, measured)]
    part = 2 * measured.zeta / measured.omega_n_rad_s - 2 * path.zeta / path.omega_n_rad_s + (taps[1] - taps[0]) * dt
    return SideslipRelease(tuple(part / speed_mps * a * G_MPS2 for a in HANDLING_GRID_G), 0.08)


def _steering_after_an_offset(settings: LoopSettings, lookahead_m: float, steps: int = 150) -> np.ndarray:
    """The steering sent (1/m) by the linearised loop (`loop_analysis.plant` and `controller`, about a straight at
    30 km/h) over `steps` periods after the vehicle starts 0.1 m off the path, everything else at rest."""
    plant_ss, controller_ss = plant(TRUCK_LAGS, V, 0.0, settings), controller(settings, TRUCK_LAGS, V, lookahead_m)
    a, b, c = (np.asarray(m) for m in (plant_ss.A, plant_ss.B, plant_ss.C))
    a_c, b_c, c_c, d_c = (np.asarray(m) for m in (controller_ss.A, controller_ss.B, controller_ss.C, controller_ss.D))
    x, x_c, sent = np.zeros(a.shape[0]), np.zeros(a_c.shape[0]), []
    x[3] = 0.1  # the plant's lateral offset (`loop_analysis._plant_continuous`)
    for _ in range(steps):
        measured = c @ x
        u = float((c_c @ x_c + d_c @ measured)[0])
        sent.append(u)
        x, x_c = a @ x + b[:, 0] * u, a_c @ x_c + b_c @ measured
    return np.array(sent)


@pytest.mark.parametrize("lookahead_m", [6.0, 9.0, 14.0])
def test_releasing_the_lags_own_sideslip_changes_nothing_in_the_loop(lookahead_m: float) -> None:
    """Where the vehicle's steady sideslip is the lags' own and the dead time is as told, the plant's sideslip less
    the model's transient is that steady sideslip whatever the steering: the deviation is identically zero, and the
    loop with the release in it steers as the loop without, step for step (within 1e-12 of the largest command),
    after the vehicle starts off the path. With the truck's own steady sideslip (more than its lags' in a turn) the
    release is in the loop: the commands differ by more than 1 %."""
    settings = LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.11)
    own = dataclasses.replace(settings, release=_lags_own_release(TRUCK_LAGS, settings, V))
    without, with_own = (_steering_after_an_offset(s, lookahead_m) for s in (settings, own))
    scale = np.abs(without).max()
    assert np.abs(with_own - without).max() <= 1e-12 * scale
    truck = read_vehicle_tuning(shipped_tuning_root() / TRUCK.name).release_at(30.0)
    with_truck = _steering_after_an_offset(dataclasses.replace(settings, release=truck), lookahead_m)
    assert np.abs(with_truck - without).max() > 0.01 * scale


@pytest.mark.parametrize("error_s", [-0.05, 0.0, 0.05])
@pytest.mark.parametrize("curvature_1pm", [0.0, 0.05])
def test_the_release_loops_margins_are_those_of_the_whole_loop(error_s: float, curvature_1pm: float) -> None:
    """The floor search's margins, composed from cached parts (the plant's sideslip output with its commands between
    the two lags' delays as z^-k), are those of the whole loop transfer built with python-control, within 1e-6, with
    the dead time as told and 50 ms off, about a straight and an arc."""
    release = read_vehicle_tuning(shipped_tuning_root() / TRUCK.name).release_at(30.0)
    settings = LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.11, measurement_delay_s=error_s, release=release)
    fast = loop_margins(TRUCK_LAGS, settings, V, 9.0, curvature_1pm)
    whole = margins(loop_transfer(TRUCK_LAGS, settings, V, 9.0, curvature_1pm))
    assert fast.stable == whole.stable
    for name in ("phase_margin_deg", "gain_margin_db", "gain_reduction_margin_db", "crossover_rad_s"):
        assert getattr(fast, name) == pytest.approx(getattr(whole, name), abs=1e-6), name


def test_a_release_is_analysed_only_where_it_is_predicted_over_a_known_delay() -> None:
    release = SideslipRelease(GRID, 0.08)
    with pytest.raises(WorkbenchInputError, match="release acts over a known delay with delay_compensation 'model'"):
        LoopSettings(known_delay_s=0.11, delay_compensation="arc", release=release)
    with pytest.raises(WorkbenchInputError, match="known_delay_s 0 s"):
        LoopSettings(release=release)
    assert LoopSettings(known_delay_s=0.11, release=release).nominal.release is None  # delay-free: none released


def test_the_controller_analyses_the_release_where_it_may_release() -> None:
    """The truck's tuned controller puts its release at the speed into the loop it analyses with a known delay, the
    release on and the course as heading; not without a known delay, with the release off, or at 10 km/h (none
    identified there: the braked turn's push is under the smallest timed); its floor keeps the margins of both
    loops (measured at 40 and 45 km/h: 10.5 and 12.5 m without the release, 11.5 and 15.0 m with it; 30 km/h
    8.5 m either way)."""
    tuning = read_vehicle_tuning(shipped_tuning_root() / TRUCK.name)
    floors = {}
    for name, config in (
        ("with", ClothoidConfig(known_delay_s=0.11)),
        ("without", ClothoidConfig(known_delay_s=0.11, sideslip_release=False)),
        ("no delay", ClothoidConfig()),
        ("yaw", ClothoidConfig(known_delay_s=0.11, heading="yaw")),
    ):
        controller = tuned_controller("clothoid", TRUCK, config)
        controller.reset(BEND_PATH, 0.02)
        settings = controller.loop_settings(40.0)
        assert (settings.release == tuning.release_at(40.0)) if name == "with" else settings.release is None, name
        floors[name] = [controller.lookahead_floor_m(kmh / 3.6) for kmh in (30.0, 40.0, 45.0)]
    assert tuning.release_at(10.0) is None
    assert floors["with"] == [8.5, 11.5, 15.0]
    assert floors["without"] == [8.5, 10.5, 12.5]


def test_the_release_between_identified_speeds_is_interpolated() -> None:
    """`VehicleTuning.release_at` reads the release table as the compiled step does: an identified speed's release
    itself, linear in speed between two."""
    tuning = read_vehicle_tuning(shipped_tuning_root() / TRUCK.name)
    releases = dict(tuning.releases)
    assert tuning.release_at(30.0) == releases[30.0]
    between = tuning.release_at(35.0)
    assert between is not None
    assert between.rate_1ps == pytest.approx(0.5 * (releases[30.0].rate_1ps + releases[40.0].rate_1ps), rel=1e-12)
    expected = 0.5 * (np.array(releases[30.0].steady_sideslip_rad) + np.array(releases[40.0].steady_sideslip_rad))
    assert np.array(between.steady_sideslip_rad) == pytest.approx(expected, rel=1e-12, abs=1e-15)
