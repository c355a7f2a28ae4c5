"""The MPCs' pose filter (`pose_filter_cutoff_hz`, `yaw_rate_latency_s`; `pose_filter.PoseFilter`), which
keeps pose noise from reaching the steering command: off by default and then changing nothing; its response (a
first-order low-pass at the cutoff on the measured pose, exact on the motion the rates describe, the yaw rate
aligned with the pose); its option checks; and, closed loop, the loaded truck under the automotive conditions,
whose NMPC steering limit-cycles on a straight without it and does not with it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from controllers.base import Measurement
from controllers.mpc import LMPCConfig, LMPCController, MPCConfig, NMPCConfig, NMPCController
from controllers.mpc.pose_filter import PoseFilter
from tuning.own_tuning import tuned_controller
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import load_conditions
from workbench.simulation.limit_cycle import detect_limit_cycle
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

#: Generous solver budget: a loaded machine must not make solves late.
RELAXED = 0.5
PERIOD = 0.02
BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).straight(40.0)
BEND_PATH = BEND.to_path("bend")
FILTER_KEYS = {"pose_filter_offset_m", "pose_filter_heading_offset_rad"}


def _at_rest(t_s: float, x_m: float = 0.0, y_m: float = 0.0, yaw_rad: float = 0.0) -> Measurement:
    return Measurement(t_s, x_m, y_m, 0.0, 0.0, yaw_rad, 0.0, 0.0)


# ---------------------------------------------------------------------------------------------- off by default


def test_off_by_default() -> None:
    for config in (MPCConfig(), NMPCConfig(), LMPCConfig()):
        assert config.pose_filter_cutoff_hz == 0.0 and config.yaw_rate_latency_s is None
        assert config.yaw_rate_lead_s == 0.0


@pytest.mark.parametrize(
    ("cls", "config_type", "options"),
    [(NMPCController, NMPCConfig, {"solver": "rti"}), (LMPCController, LMPCConfig, {})],
    ids=["nmpc-rti", "lmpc"],
)
@pytest.mark.parametrize("delays", [{}, {"input_delay_s": 0.1, "measurement_latency_s": 0.02}], ids=["now", "late"])
def test_off_changes_nothing(cls, config_type, options, delays, weaving) -> None:
    """pose_filter_cutoff_hz = 0 (the default): commands and every diagnostic but the solve time equal bit for bit
    those of a controller built without the option; no filter is built and its diagnostics are not logged. With it
    on, the same measurements give other commands and the filter's diagnostics."""
    vehicle = make_vehicle("dynamic-bicycle")
    build = lambda **extra: cls(  # noqa: E731
        vehicle.geometry, config_type(max_solve_time_s=RELAXED, **options, **delays, **extra), vehicle=vehicle
    )
    plain, explicit, filtered = build(), build(pose_filter_cutoff_hz=0.0), build(pose_filter_cutoff_hz=0.5)
    for controller in (plain, explicit, filtered):
        controller.reset(BEND_PATH, PERIOD)
    differ = 0
    for m in weaving(BEND_PATH, 60, 7, 8.0):
        a, b, c = plain.step(m, BEND_PATH), explicit.step(m, BEND_PATH), filtered.step(m, BEND_PATH)
        assert a == b  # exactly
        differ += a != c
        da, db = dict(plain.diagnostics), dict(explicit.diagnostics)
        da.pop("solve_time_s"), db.pop("solve_time_s")
        assert da == db and not FILTER_KEYS & set(da)
        assert FILTER_KEYS <= set(filtered.diagnostics)
    assert explicit._pose_filter is None and differ > 50


# ---------------------------------------------------------------------------------------------- the filter's response


def test_a_pose_step_is_a_first_order_low_pass_at_the_cutoff() -> None:
    """At rest (no velocity, no yaw rate) a step of the measured pose: the estimate is 1 - exp(-t / tau) of it,
    tau = 1 / (2 pi f_c), to 1e-12 at every step: 63.2 % at t = tau (here 0.1 s, 5 steps of 20 ms)."""
    tau = 0.1
    f = PoseFilter(1.0 / (2.0 * math.pi * tau))
    assert f(_at_rest(0.0)) == _at_rest(0.0)  # the first measurement is taken as it is
    for k in range(1, 51):
        e = f(_at_rest(k * PERIOD, 2.0, -1.0, 0.3))
        expected = 1.0 - math.exp(-k * PERIOD / tau)
        assert e.x_m == pytest.approx(2.0 * expected, abs=1e-12)
        assert e.y_m == pytest.approx(-1.0 * expected, abs=1e-12)
        assert e.yaw_rad == pytest.approx(0.3 * expected, abs=1e-12)
        if k == 5:
            assert e.x_m / 2.0 == pytest.approx(1.0 - math.exp(-1.0), abs=1e-12)  # 63.2 % at tau


def test_at_rest_it_is_scipys_first_order_filter_and_attenuates_white_noise() -> None:
    """At rest the estimate of each pose component is lfilter([k], [1, k - 1]) of the measured one (started at the
    first measurement), k = 1 - exp(-2 pi f_c T), to 1e-12; white noise keeps k / (2 - k) of its variance (within
    15 % on 20000 samples: at 0.3 Hz and 50 Hz, 1.9 % of it)."""
    cutoff, n, sigma = 0.3, 20000, 0.01
    rng = np.random.default_rng(3)
    x, y, yaw = rng.normal(0.0, sigma, (3, n))
    f = PoseFilter(cutoff)
    estimates = np.array([_pose(f(_at_rest(k * PERIOD, x[k], y[k], yaw[k]))) for k in range(n)])
    k = f.gain(PERIOD)
    assert k == pytest.approx(1.0 - math.exp(-2.0 * math.pi * cutoff * PERIOD), rel=1e-15)
    for column, measured in enumerate((x, y, yaw)):
        expected, _ = lfilter([k], [1.0, k - 1.0], measured, zi=[(1.0 - k) * measured[0]])
        np.testing.assert_allclose(estimates[:, column], expected, rtol=0.0, atol=1e-12)
    settled = estimates[200:, 0]
    assert np.var(settled) / sigma**2 == pytest.approx(k / (2.0 - k), rel=0.15)


def _pose(m: Measurement) -> tuple[float, float, float]:
    return m.x_m, m.y_m, m.yaw_rad


def test_exact_signals_pass_without_lag() -> None:
    """A vehicle on a circle (constant body velocities and yaw rate), measured exactly: the estimate is the measured
    pose to 1e-9 m and rad at every step, however low the cutoff (the dead reckoning, exact on an arc, carries the
    motion)."""
    vx, vy, rate, f = 8.0, 0.3, 0.2, PoseFilter(0.05)
    speed = math.hypot(vx, vy)
    for k in range(500):
        t = k * PERIOD
        yaw = rate * t
        course = yaw + math.atan2(vy, vx)  # the velocity's direction; the centre is speed / rate to its left
        x = speed / rate * (math.sin(course) - math.sin(math.atan2(vy, vx)))
        y = speed / rate * (math.cos(math.atan2(vy, vx)) - math.cos(course))
        e = f(Measurement(t, x, y, vx, vy, yaw, rate, 0.0))
        assert math.hypot(e.x_m - x, e.y_m - y) < 1e-9 and abs(e.yaw_rad - yaw) < 1e-9


@pytest.mark.parametrize("lead", [0.0, 0.01, -0.005])
def test_the_yaw_rate_is_aligned_with_the_pose(lead: float) -> None:
    """Yaw rate rising at alpha, the pose (stamped t) describing t - L and the yaw rate t - L_r: with the filter told
    lead = L_r - L the heading estimate is exact (to 1e-12); told 0 instead, it lags by the analytic steady error
    (1 - k) alpha lead T / k of a first-order loop whose every step integrates alpha lead T too little."""
    alpha, pose_latency, cutoff = 0.5, 0.01, 0.3
    aligned, unaligned = PoseFilter(cutoff, lead), PoseFilter(cutoff, 0.0)
    for k in range(600):
        t = k * PERIOD
        tp, tr = t - pose_latency, t - pose_latency - lead
        m = Measurement(t, 0.0, 0.0, 0.0, 0.0, 0.5 * alpha * tp * tp, alpha * tr, 0.0)
        assert aligned(m).yaw_rad == pytest.approx(m.yaw_rad, abs=1e-12)
        lagging = unaligned(m).yaw_rad - m.yaw_rad
    k = unaligned.gain(PERIOD)
    assert lagging == pytest.approx(-(1.0 - k) * alpha * lead * PERIOD / k, abs=1e-12)


def test_a_held_pose_counts_as_measured_again() -> None:
    """A localisation refreshing every 5th step (the pose held between): at rest the estimate is lfilter of the held
    sequence, every step pulled toward the last pose, as the controller without the filter uses it every step."""
    rng = np.random.default_rng(5)
    held = np.repeat(rng.normal(0.0, 0.05, 40), 5)
    f = PoseFilter(0.5)
    out = [f(_at_rest(k * PERIOD, held[k])).x_m for k in range(held.size)]
    k = f.gain(PERIOD)
    expected, _ = lfilter([k], [1.0, k - 1.0], held, zi=[(1.0 - k) * held[0]])
    np.testing.assert_allclose(out, expected, rtol=0.0, atol=1e-12)


# ---------------------------------------------------------------------------------------------- option checks


@pytest.mark.parametrize("value", [-0.1, 100.5, math.nan, math.inf])
def test_the_cutoff_is_checked(value: float) -> None:
    with pytest.raises(WorkbenchInputError, match=r"pose_filter_cutoff_hz must be a finite number in \[0, 100\] Hz"):
        NMPCConfig(pose_filter_cutoff_hz=value)


@pytest.mark.parametrize("value", [-0.01, 1.5, math.nan])
def test_the_yaw_rate_latency_is_checked(value: float) -> None:
    with pytest.raises(
        WorkbenchInputError,
        match=r"yaw_rate_latency_s must be a finite number in \[0, 1\] s \(or None: measurement_latency_s\)",
    ):
        LMPCConfig(pose_filter_cutoff_hz=0.3, yaw_rate_latency_s=value)


def test_the_yaw_rate_latency_needs_the_filter() -> None:
    with pytest.raises(WorkbenchInputError, match=r"yaw_rate_latency_s is used by the pose filter only.*got 0.02$"):
        NMPCConfig(yaw_rate_latency_s=0.02)
    config = NMPCConfig(pose_filter_cutoff_hz=0.3, measurement_latency_s=0.01, yaw_rate_latency_s=0.02)
    assert config.yaw_rate_lead_s == pytest.approx(0.01, abs=1e-15)
    assert NMPCConfig(pose_filter_cutoff_hz=0.3, measurement_latency_s=0.01).yaw_rate_lead_s == 0.0


# ---------------------------------------------------------------------------------------------- closed loop


def _truck_on_a_straight(**options: float):
    """The loaded truck at 30 km/h on a 450 m straight under the automotive conditions (seed 0), NMPC compensating
    their 0.1 s steering dead time and 10 ms pose latency."""
    vehicle = make_vehicle("tractor-semitrailer")
    config = NMPCConfig(input_delay_s=0.1, measurement_latency_s=0.01, max_solve_time_s=RELAXED, **options)
    controller = tuned_controller("nmpc", vehicle, config)
    scenario = Scenario("straight", ClothoidChain().straight(450.0).to_path("straight"), "450 m straight")
    run_config = SimulationConfig(speed_kmh=30.0, conditions=load_conditions("automotive"), seed=0)
    result = Simulation(scenario, vehicle, controller, run_config).run()
    assert result.completed, result.message
    return result


def test_the_truck_does_not_limit_cycle_with_the_pose_filter() -> None:
    """Measured: without the filter the steering limit-cycles (0.80 Hz, +-12 deg of steering wheel for 4.4 s from
    t = 36.4 s: pose noise in the NMPC's own correction band, 0.6-0.8 Hz on the truck); with it at 0.3 Hz (the yaw
    rate's 20 ms latency given) it does not, the steering oscillation drops from 3.8 to 1.5 deg RMS and max |CTE|
    stays 0.03 m (the position drift the filter passes)."""
    off = _truck_on_a_straight()
    on = _truck_on_a_straight(pose_filter_cutoff_hz=0.3, yaw_rate_latency_s=0.02)
    assert detect_limit_cycle(off.trace["t_s"], off.trace["steer_wheel_rad"]).detected
    assert not detect_limit_cycle(on.trace["t_s"], on.trace["steer_wheel_rad"]).detected
    assert not on.metrics.limit_cycle
    assert on.metrics.steer_oscillation_deg < 0.5 * off.metrics.steer_oscillation_deg
    assert on.metrics.max_abs_cte_m < 0.05
    assert np.all(on.trace["ctrl_fallback"] == 0.0)
    # What the filter takes off the measured pose: its noise (1 cm white and 1 cm drift per axis), after the first
    # second, in which the 8 cm the estimate runs ahead of the pose held before the start (10 ms latency) decays.
    settled = np.asarray(on.trace["t_s"]) >= 1.0
    assert np.max(np.asarray(on.trace["ctrl_pose_filter_offset_m"])[settled]) < 0.05
