"""design-lead: the designed Eq. 6 against python-control and closed forms; bounds; the time-domain check."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from synthetic_logs import GEOMETRY, synthetic_frame

from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.loop_analysis import LoopSettings, Margins, PlantLags, loop_margins
from tuning.lead_design import design_lead, design_lead_for_margins, margin_score, validate
from tuning.log_file import VehicleLog
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.steering_lag import SteeringLag

G3 = 10 ** (-3 / 20)  # python-control's -3 dB


def plant_bandwidth(wn: float, zeta: float) -> float:
    """-3 dB bandwidth of Eq. 5 in closed form: |G(jw)|^2 = G3^2 is a quadratic in w^2."""
    a = 1 - 2 * zeta**2
    return wn * math.sqrt(a + math.sqrt(a * a + 1 / G3**2 - 1))


@settings(max_examples=25, deadline=None)
@given(wn=st.floats(0.5, 20.0), zeta=st.floats(0.5, 3.0), bound=st.floats(10.0, 30.0))
def test_dc_gain_one_stable_minimum_phase_and_at_least_twice_the_bandwidth(
    wn: float, zeta: float, bound: float
) -> None:
    design = design_lead(SteeringLag(wn, zeta), max_lead_gain=bound)
    lead = design.params.transfer_function()
    assert design.params.dc_gain == pytest.approx(1.0, abs=1e-12)
    assert float(control.dcgain(lead)) == pytest.approx(1.0, abs=1e-9)
    assert np.all(np.real(control.poles(lead)) < 0)  # stable
    assert np.all(np.real(control.zeros(lead)) < 0)  # minimum phase
    assert design.plant_bandwidth_rad_s == pytest.approx(plant_bandwidth(wn, zeta), rel=1e-6)
    assert design.cascade_bandwidth_rad_s >= 2.0 * design.plant_bandwidth_rad_s  # for bounds from 10 up
    assert design.lead_peak_gain <= bound * (1 + 1e-9)
    assert design.cascade_peak_db <= 1.0 + 1e-9


@pytest.mark.parametrize(
    ("bound", "ratio", "bandwidth_ratio"), [(None, 3.93, 2.23), (3.0, 2.77, 1.57), (10.0, 5.09, 2.88)]
)
def test_the_default_design_of_the_trucks_30_kmh_lag(bound: float | None, ratio: float, bandwidth_ratio: float) -> None:
    # Zeros on the lag's poles; the triple pole as high as the peak gain allows: wp = 3.93 wn under the default
    # bound of 6 (15.6 dB), 2.77 wn under 3, 5.09 wn under 10 (20 dB).
    wn, zeta = 4.28, 0.78
    design = design_lead(SteeringLag(wn, zeta)) if bound is None else design_lead(SteeringLag(wn, zeta), bound)
    p = design.params
    assert (p.omega_z_rad_s, p.psi) == (wn, zeta)
    assert design.lead_peak_gain == pytest.approx(bound or 6.0, rel=1e-6)  # the bound is active
    assert p.omega_p_rad_s == pytest.approx(ratio * wn, rel=0.01)
    # Cancellation leaves wp^3 / (s + wp)^3: bandwidth wp sqrt(G3^(-2/3) - 1), phase -3 atan(w / wp).
    assert design.cascade_bandwidth_rad_s == pytest.approx(p.omega_p_rad_s * math.sqrt(G3 ** (-2 / 3) - 1), rel=1e-6)
    w = design.phase_frequency_rad_s
    assert w == design.plant_bandwidth_rad_s
    assert design.plant_phase_deg == pytest.approx(-math.degrees(math.atan2(2 * zeta * wn * w, wn**2 - w**2)))
    assert design.cascade_phase_deg == pytest.approx(-3 * math.degrees(math.atan(w / p.omega_p_rad_s)), abs=1e-6)
    assert design.bandwidth_ratio == pytest.approx(bandwidth_ratio, abs=0.02)
    assert p == LeadFilterParams.from_lag(wn, zeta, p.omega_p_rad_s / wn)


def test_a_looser_bound_buys_bandwidth_and_the_delay_shows_in_the_phase() -> None:
    lag = SteeringLag(3.0, 1.0)
    designs = [design_lead(lag, max_lead_gain=m) for m in (2.0, 10.0, 30.0)]
    assert designs[0].cascade_bandwidth_rad_s < designs[1].cascade_bandwidth_rad_s < designs[2].cascade_bandwidth_rad_s
    for m, d in zip((2.0, 10.0, 30.0), designs, strict=True):
        assert d.lead_peak_gain == pytest.approx(m, rel=1e-6)
    # A lightly damped lag: its resonance widens its own bandwidth, so the cascade gains less than x2 here.
    assert 1.5 < design_lead(SteeringLag(3.0, 0.3), max_lead_gain=10.0).bandwidth_ratio < 2.0
    assert design_lead(SteeringLag(3.0, 0.3), max_lead_gain=3.0).bandwidth_ratio == pytest.approx(1.0, abs=0.01)
    delayed = design_lead(SteeringLag(3.0, 1.0, delay_s=0.1), phase_frequency_rad_s=2.0)
    plain = design_lead(lag, phase_frequency_rad_s=2.0)
    assert delayed.plant_phase_deg == pytest.approx(plain.plant_phase_deg - math.degrees(0.2))
    assert delayed.cascade_phase_deg == pytest.approx(plain.cascade_phase_deg - math.degrees(0.2))
    assert delayed.params == plain.params
    assert delayed.metadata()["plant_delay_s"] == 0.1
    far = design_lead(lag, phase_frequency_rad_s=200.0)  # beyond -180 deg: unwrapped, not wrapped to +
    wp = far.params.omega_p_rad_s
    assert far.cascade_phase_deg == pytest.approx(-3 * math.degrees(math.atan(200.0 / wp)), abs=1e-6)
    assert far.cascade_phase_deg < -180.0


def test_frequency_response_matches_the_transfer_functions() -> None:
    design = design_lead(SteeringLag(4.0, 0.7))
    w = np.logspace(-1, 2, 50)
    response = design.frequency_response(w)
    plant, lead, cascade = design.transfer_functions()
    for name, tf in (("plant", plant), ("compensator", lead), ("cascade", cascade)):
        np.testing.assert_allclose(response[name][0], np.abs(tf(1j * w)), rtol=1e-9)
    np.testing.assert_allclose(response["cascade"][0], response["plant"][0] * response["compensator"][0], rtol=1e-9)


def test_compensation_brings_the_lagged_curvature_to_the_kinematic_one_figure_9() -> None:
    lag = SteeringLag(4.0, 0.8)
    log = VehicleLog.from_frame(synthetic_frame("dlc", 4.0, 0.8), "dlc")
    trace = validate(design_lead(lag), log, GEOMETRY)
    # Measured: NRMSE against the kinematic curvature 0.145 lagged; compensated 0.072 with the default bound of 6,
    # 0.100 with 3 and 0.056 with 10 (a faster filter follows the kinematic curvature more closely).
    assert trace.nrmse_compensated < 0.55 * trace.nrmse_lagged
    errors = [validate(design_lead(lag, max_lead_gain=b), log, GEOMETRY).nrmse_compensated for b in (3.0, 6.0, 10.0)]
    assert errors == sorted(errors, reverse=True) and errors[0] < 0.75 * trace.nrmse_lagged
    assert trace.measured_1pm is not None
    np.testing.assert_allclose(trace.lagged_1pm, trace.measured_1pm, atol=0.01 * np.ptp(trace.kinematic_1pm))


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"max_lead_gain": 0.5}, "max_lead_gain must be a finite number in [1, 1000]"),
        ({"max_cascade_peak_db": -1.0}, "max_cascade_peak_db must be a finite number in [0, 20] dB"),
        ({"phase_frequency_rad_s": float("nan")}, "phase_frequency_rad_s must be a finite number"),
    ],
)
def test_bad_bounds(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        design_lead(SteeringLag(4.0, 0.8), **kwargs)
    assert needle in str(info.value)


def test_an_overdamped_lag_beyond_the_filters_range_is_explained() -> None:
    with pytest.raises(WorkbenchInputError, match=r"zeta = 6 is over 5"):
        design_lead(SteeringLag(4.0, 6.0))


def test_a_lag_damped_beyond_3_8_needs_a_bound_above_3() -> None:
    # Zeros with psi = 4 alone peak above 3 even with wp = wz: a bound of 3 cannot be met; the default 6 can.
    with pytest.raises(WorkbenchInputError, match="no lead filter meets the bounds; raise max_lead_gain"):
        design_lead(SteeringLag(4.0, 4.0), max_lead_gain=3.0)
    assert design_lead(SteeringLag(4.0, 4.0)).lead_peak_gain == pytest.approx(6.0, rel=1e-6)


# --- the margins design ----------------------------------------------------------------------------------------

#: The loaded truck's lags at 60 km/h (`tuning schedule --delay`): to the path and to the measured curvature.
TRUCK_60 = PlantLags(
    SteeringLag(8.18, 2.0, 0.176, steady_state_gain=0.836), SteeringLag(13.15, 2.0, 0.073, steady_state_gain=0.835)
)
SETTINGS = LoopSettings(sample_time_s=0.02, prediction_time_s=0.2)
ARC_60 = 0.4 * 9.80665 / (60 / 3.6) ** 2


def test_the_margins_design_shortens_the_floor_and_keeps_the_margins_there() -> None:
    """Measured: a floor of 17.5 m with the lead (omega_z 4.76, psi 1.40, omega_p 17.0 rad/s, peak gain 5.5), none
    up to 40 m without one; about 2 s."""
    result = design_lead_for_margins(TRUCK_60, 60 / 3.6, SETTINGS, path_curvatures_1pm=(0.0, ARC_60))
    params = result.design.params
    assert result.floor_m == pytest.approx(17.5, abs=1.0) and math.isnan(result.floor_without_lead_m)
    assert math.isnan(result.margin_score) and result.design.method == "margins"
    assert params.peak_gain <= 6.0 * (1 + 1e-9) and result.candidates > 100
    with_lead = LoopSettings(sample_time_s=0.02, prediction_time_s=0.2, lead=params)
    for kr in (0.0, ARC_60):
        assert loop_margins(TRUCK_60, with_lead, 60 / 3.6, result.floor_m, kr).meets()
        assert not loop_margins(TRUCK_60, with_lead, 60 / 3.6, result.floor_m - 1.0, kr).meets() or kr == ARC_60
    # the bound on the peak gain holds
    tight = design_lead_for_margins(TRUCK_60, 60 / 3.6, SETTINGS, path_curvatures_1pm=(0.0,), max_lead_gain=2.0)
    assert tight.design.params.peak_gain <= 2.0 * (1 + 1e-9) and not tight.floor_m < result.floor_m


def test_where_no_lookahead_keeps_the_margins_the_least_bad_filter_is_chosen() -> None:
    result = design_lead_for_margins(TRUCK_60, 60 / 3.6, SETTINGS, max_lookahead_m=8.0, path_curvatures_1pm=(0.0,))
    assert math.isnan(result.floor_m) and math.isnan(result.floor_without_lead_m)
    assert 0.0 < result.margin_score < 1.0
    assert margin_score(loop_margins(TRUCK_60, SETTINGS, 60 / 3.6, 8.0), 45.0, 6.0) < result.margin_score


def test_margin_score() -> None:
    ok = Margins(50.0, 8.0, -9.0, 2.0, 5.0, True, 0.9)
    assert margin_score(ok, 45.0, 6.0) == pytest.approx(min(50 / 45, 8 / 6, 9 / 6))
    assert margin_score(Margins(20.0, 8.0, -9.0, 2.0, 5.0, True, 0.9), 45.0, 6.0) == pytest.approx(20 / 45)
    assert margin_score(Margins(50.0, 8.0, -9.0, 2.0, 5.0, False, 1.1), 45.0, 6.0) == -math.inf
