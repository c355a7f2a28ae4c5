"""rollover-limits: the step-steer series of Figure 6 on the loaded truck, and its limits file."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from controllers.clothoid.curvature_limits import CurvatureLimits
from tuning.limits_file import read_limits_file, write_limits_file
from tuning.rollover import rollover_limit, rollover_limits, step_steer, to_curvature_limits
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

G = 9.80665


@pytest.fixture(scope="module")
def truck():
    return make_vehicle("tractor-semitrailer")


@pytest.fixture(scope="module")
def limits(truck):
    return rollover_limits(truck, [20.0, 40.0, 60.0, 80.0])


def test_limits_fall_with_speed_figure_6(limits) -> None:
    # Measured (path curvature at LTR = 1): 0.040, 0.016, 0.0088 1/m at 40, 60, 80 km/h.
    by_speed = {lim.speed_kmh: lim for lim in limits}
    curvatures = [lim.path_curvature_1pm for lim in limits]
    assert all(b < a for a, b in itertools.pairwise(curvatures))
    for speed, expected in ((40.0, 0.040), (60.0, 0.016), (80.0, 0.0088)):
        lim = by_speed[speed]
        assert lim.limited_by == "rollover"
        assert lim.path_curvature_1pm == pytest.approx(expected, rel=0.03)
        assert lim.peak_ltr == pytest.approx(1.0, abs=0.01)  # the smallest step that lifts a wheel
        assert lim.kinematic_curvature_1pm > lim.path_curvature_1pm  # the truck understeers
        assert 0.4 < lim.lateral_accel_g < 0.55  # about the static rollover threshold, 0.45 g


def test_a_step_just_below_the_limit_keeps_the_wheels_down(truck, limits) -> None:
    lim = next(lim for lim in limits if lim.speed_kmh == 60.0)
    assert step_steer(truck, 60.0, 0.99 * lim.kinematic_curvature_1pm).peak_ltr < 1.0
    assert step_steer(truck, 60.0, lim.kinematic_curvature_1pm).peak_ltr >= 1.0


def test_at_low_speed_the_steering_lock_limits(limits) -> None:
    slow = limits[0]
    assert slow.speed_kmh == 20.0 and slow.limited_by == "steering lock"
    assert slow.peak_ltr < 1.0
    assert slow.path_curvature_1pm == pytest.approx(slow.kinematic_curvature_1pm, rel=0.1)


def test_the_limits_file_round_trips_for_the_controller(truck, limits, tmp_path: Path) -> None:
    table = to_curvature_limits(limits, truck)
    write_limits_file(table, tmp_path / "limits.csv")
    back = read_limits_file(tmp_path / "limits.csv", truck.geometry)
    assert back.speeds_kmh == (20.0, 40.0, 60.0, 80.0)
    assert back.max_curvature_1pm == pytest.approx([lim.path_curvature_1pm for lim in limits], rel=1e-8)
    rate = CurvatureLimits.default_for(truck.geometry).at_speed(0.0)[1]  # the steering-rate limit
    assert back.max_curvature_rate_1pm_s == pytest.approx([rate] * 4, rel=1e-8)
    assert back.at_speed(50 / 3.6)[0] == pytest.approx(
        0.5 * (limits[1].path_curvature_1pm + limits[2].path_curvature_1pm)
    )


def test_a_vehicle_without_roll_is_refused() -> None:
    with pytest.raises(WorkbenchInputError, match="vehicle 'kinematic-bicycle' has no 'ltr' output"):
        rollover_limits(make_vehicle("kinematic-bicycle"), [40.0])


def test_bad_speeds(truck) -> None:
    with pytest.raises(WorkbenchInputError, match="speeds must increase strictly"):
        rollover_limits(truck, [60.0, 40.0])
    with pytest.raises(WorkbenchInputError, match="speed_kmh must be a finite number in"):
        rollover_limit(truck, 0.0)
