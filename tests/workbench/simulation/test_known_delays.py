"""KnownDelays: the nominal delays and pose noise of each conditions preset, as a controller may be told them, and
the refusal of values outside the conditions' ranges."""

from __future__ import annotations

import math

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import CONDITIONS, Actuation, Conditions, Inertial, Localisation
from workbench.simulation.known_delays import MAX_POSE_NOISE_M, KnownDelays


def test_ideal_conditions_tell_nothing() -> None:
    delays = KnownDelays.from_conditions(CONDITIONS["ideal"])
    assert delays == KnownDelays()
    assert delays.loop_delay_s == 0.0 and not delays.pose_is_noisy


@pytest.mark.parametrize(
    ("preset", "pose_latency", "yaw_latency", "dead_time", "noise_m", "drift_m", "heading_deg"),
    [
        # conditions.py's preset table: RTK pose 10 ms, 1 cm white + 1 cm drift, 0.1 deg; automotive adds the CAN
        # yaw rate at 20 ms and 0.1 s dead time; degraded: 0.1 s pose latency, 0.2 m white + 0.75 m drift, 0.5 deg
        ("rtk", 0.010, 0.010, 0.0, 0.01, 0.01, 0.1),
        ("automotive", 0.010, 0.020, 0.1, 0.01, 0.01, 0.1),
        ("degraded", 0.1, 0.020, 0.1, 0.2, 0.75, 0.5),
    ],
)
def test_presets_give_their_stated_nominal_values(
    preset: str,
    pose_latency: float,
    yaw_latency: float,
    dead_time: float,
    noise_m: float,
    drift_m: float,
    heading_deg: float,
) -> None:
    delays = KnownDelays.from_conditions(CONDITIONS[preset])
    assert delays.pose_latency_s == pytest.approx(pose_latency, abs=1e-12)
    assert delays.yaw_rate_latency_s == pytest.approx(yaw_latency, abs=1e-12)
    assert delays.dead_time_s == pytest.approx(dead_time, abs=1e-12)
    assert delays.pose_noise_m == pytest.approx(math.sqrt(noise_m**2 + drift_m**2), rel=1e-12)
    assert delays.heading_noise_rad == pytest.approx(math.radians(heading_deg), rel=1e-12)
    assert delays.loop_delay_s == pytest.approx(pose_latency + dead_time, abs=1e-12)
    assert delays.pose_is_noisy


def test_noise_alone_or_heading_alone_makes_the_pose_noisy_and_latency_alone_does_not() -> None:
    late = Conditions(localisation=Localisation(latency_s=0.05), actuation=Actuation(dead_time_s=0.2))
    assert not KnownDelays.from_conditions(late).pose_is_noisy
    assert KnownDelays.from_conditions(late).loop_delay_s == pytest.approx(0.25, abs=1e-12)
    drifting = Conditions(localisation=Localisation(position_drift_m=0.3))
    assert KnownDelays.from_conditions(drifting).pose_noise_m == pytest.approx(0.3, rel=1e-12)
    assert KnownDelays(heading_noise_rad=0.001).pose_is_noisy
    yaw_only = Conditions(inertial=Inertial(latency_s=0.03))
    assert KnownDelays.from_conditions(yaw_only) == KnownDelays(yaw_rate_latency_s=0.03)


@pytest.mark.parametrize(
    ("field", "value", "allowed"),
    [
        ("pose_latency_s", -0.01, "[0, 2] s"),
        ("yaw_rate_latency_s", math.nan, "[0, 2] s"),
        ("dead_time_s", 2.5, "[0, 2] s"),
        ("pose_noise_m", MAX_POSE_NOISE_M * 2, "m"),
        ("heading_noise_rad", -1.0, "rad"),
        ("dead_time_s", "0.1", "[0, 2] s"),
    ],
)
def test_values_outside_the_conditions_ranges_are_refused_naming_the_field(
    field: str, value: object, allowed: str
) -> None:
    with pytest.raises(WorkbenchInputError, match=field) as caught:
        KnownDelays(**{field: value})
    assert allowed in str(caught.value) and repr(value) in str(caught.value)


def test_describe_names_each_value() -> None:
    text = KnownDelays.from_conditions(CONDITIONS["automotive"]).describe()
    assert "pose latency 10 ms" in text and "yaw-rate latency 20 ms" in text and "dead time 100 ms" in text
    assert "pose not noisy" in KnownDelays(dead_time_s=0.1).describe()
