"""The track margin (issue 20, item 12): the least distance from the vehicle's outline, trailer included, to the
track's edges, against analytic values (a straight driven parallel at a known offset, a circle driven on a
concentric circle) and against a brute-force measure of a real run; and the metrics.json fields it fills."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from stadium_tracks import stadium_file

from controllers import make_controller
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path import ReferencePath
from workbench.simulation.metrics import compute_metrics
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.scenarios import Scenario, make_scenario
from workbench.simulation.simulator import Simulation
from workbench.simulation.track_margin import (
    CAR_FRONT_OVERHANG_M,
    CAR_REAR_OVERHANG_M,
    TRAILER_KINGPIN_SETBACK_M,
    TRAILER_REAR_OVERHANG_M,
    VehicleOutline,
    track_margins,
)
from workbench.vehicles import make_vehicle

CAR = VehicleOutline(width_m=1.6, front_m=3.4, rear_m=1.1)


def _with_widths(path: ReferencePath, left_m: float, right_m: float) -> ReferencePath:
    n = path.x_m.size
    return ReferencePath(
        path.x_m,
        path.y_m,
        path.heading_rad,
        path.curvature_1pm,
        path.spacing_m,
        path.closed,
        name=path.name,
        width_left_m=np.full(n, left_m),
        width_right_m=np.full(n, right_m),
    )


def _trace(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, s: np.ndarray) -> dict[str, np.ndarray]:
    n = x.size
    return {
        "t_s": np.arange(n) * 0.02,
        "x_m": x,
        "y_m": y,
        "yaw_rad": yaw,
        "path_s_m": s,
        "cte_m": np.zeros(n),
        "heading_error_rad": np.zeros(n),
        "steer_wheel_rad": np.zeros(n),
        "lat_accel_mps2": np.zeros(n),
        "speed_mps": np.full(n, 5.0),
        "step_time_s": np.full(n, 1e-5),
    }


def _straight_run(offset_m: float) -> tuple[ReferencePath, dict[str, np.ndarray]]:
    path = _with_widths(ClothoidChain().straight(100.0).to_path("straight"), left_m=3.0, right_m=2.0)
    x = np.linspace(5.0, 90.0, 400)
    return path, _trace(x, np.full(x.size, offset_m), np.zeros(x.size), x)


@pytest.mark.parametrize("offset_m", [0.8, -0.4, 2.6, -1.9])
def test_a_car_driven_parallel_on_a_straight_has_the_analytic_margin(offset_m: float) -> None:
    path, trace = _straight_run(offset_m)
    half = CAR.width_m / 2
    expected = min(3.0 - (offset_m + half), 2.0 + (offset_m - half))  # left edge at +3 m, right at -2 m
    np.testing.assert_allclose(track_margins(path, trace, CAR), expected, atol=1e-6)
    metrics = compute_metrics(
        trace, path, scenario="s", controller="c", vehicle="v", completed=True, path_length_m=100.0, outline=CAR
    )
    assert metrics.min_track_margin_m == pytest.approx(expected, abs=1e-6)
    assert metrics.left_track is (expected < 0.0)  # 2.6 m left: the car's left side is 0.405 m beyond the edge


def test_the_trailer_counts_for_the_tractor_semitrailer() -> None:
    path, trace = _straight_run(0.0)
    truck = VehicleOutline(width_m=2.6, front_m=6.6, rear_m=1.0, trailer_front_m=14.7, trailer_rear_m=1.5)
    trace["trailer_x_m"] = trace["x_m"] - 13.8
    trace["trailer_y_m"] = np.full(trace["x_m"].size, -0.5)  # the trailer 0.5 m right of the tractor's line
    trace["trailer_yaw_rad"] = np.zeros(trace["x_m"].size)
    # The trailer's right side is at -1.8 m, 0.2 m inside the right edge; the tractor's 0.7 m.
    np.testing.assert_allclose(track_margins(path, trace, truck), 0.2, atol=1e-6)
    without = dataclasses.replace(truck, trailer_front_m=None, trailer_rear_m=None)
    np.testing.assert_allclose(track_margins(path, trace, without), 0.7, atol=1e-6)


@pytest.mark.parametrize(
    ("radius_m", "expected_m", "nearest"),
    [
        # On the centre line: the front outer corner, at sqrt((R + b/2)^2 + front^2) from the centre, is nearest
        # the outer edge (radius 34 m).
        (30.0, 34.0 - math.hypot(30.8, 3.4), "outer corner"),
        # 2.5 m inside: the middle of the inner side, R - b/2 from the centre, is nearest the inner edge (26 m);
        # its corners are 0.22 m farther from it.
        (27.5, 27.5 - 0.8 - 26.0, "inner side"),
        # 3.5 m inside: the inner side's middle is 0.3 m beyond the inner edge, its corners only 0.08 m.
        (26.5, 26.5 - 0.8 - 26.0, "inner side beyond the edge"),
    ],
)
def test_a_car_on_a_concentric_circle_has_the_analytic_margin(radius_m: float, expected_m: float, nearest: str) -> None:
    circle = ClothoidChain(curvature_1pm=1 / 30.0).arc(2 * math.pi * 30.0).to_path("circle", closed=True)
    path = _with_widths(circle, left_m=4.0, right_m=4.0)
    angle = np.linspace(0.1, 2 * math.pi - 0.1, 300)  # counter-clockwise, the centre on the left
    x, y = radius_m * np.sin(angle), 30.0 - radius_m * np.cos(angle)  # circle about (0, 30) through the path's start
    trace = _trace(x, y, angle, 30.0 * angle)
    margins = track_margins(path, trace, CAR)
    # Edges sampled every 0.5 m lie within kappa h^2 / 8 = 1.2 mm of the circles; the foot points within 1 mm.
    np.testing.assert_allclose(margins, expected_m, atol=3e-3, err_msg=nearest)


def test_the_margin_of_a_truck_through_a_hairpin_matches_a_brute_force_measure(tmp_path: Path) -> None:
    """A loaded truck through two 15 m hairpins (its trailer axle cuts 6.6 m inside) against every point of its outline
    every 5 cm, measured to the edges with a search over all the path's samples."""
    file = _stadium_file(tmp_path, radius_m=15.0, left_m=8.5, right_m=5.0)
    truck = make_vehicle("tractor-semitrailer")
    scenario = make_scenario(str(file))
    result = Simulation(
        scenario, truck, make_controller("pure-pursuit", truck.geometry), SimulationConfig(speed_kmh=20.0)
    ).run()
    outline = VehicleOutline.of(truck)
    margins = track_margins(result.path, result.trace, outline)
    brute = _brute_force_margins(result.path, result.trace, outline, np.arange(0, margins.size, 7))
    np.testing.assert_allclose(margins[::7], brute, atol=0.02)  # the edges' sampling and the brute force's 5 cm
    tractor = track_margins(
        result.path, result.trace, dataclasses.replace(outline, trailer_front_m=None, trailer_rear_m=None)
    )
    assert margins.min() < 1.0 < tractor.min()  # the trailer's inner side came closest to the inner edge


def test_outline_of_the_presets() -> None:
    car = VehicleOutline.of(make_vehicle("dynamic-bicycle"))
    assert (car.width_m, car.rear_m, car.has_trailer) == (1.61, CAR_REAR_OVERHANG_M, False)
    assert car.front_m == pytest.approx(2.579 + CAR_FRONT_OVERHANG_M, abs=1e-9)
    truck = VehicleOutline.of(make_vehicle("tractor-semitrailer"))
    assert truck.trailer_front_m == pytest.approx(13.768 + TRAILER_KINGPIN_SETBACK_M, abs=1e-9)
    assert truck.trailer_rear_m == pytest.approx(TRAILER_REAR_OVERHANG_M, abs=1e-12)
    assert truck.trailer_front_m + truck.trailer_rear_m == pytest.approx(16.154, abs=1e-9)  # a 53 ft trailer


def test_without_widths_or_outline_the_track_fields_are_null(tmp_path: Path) -> None:
    path, trace = _straight_run(0.0)
    plain = ClothoidChain().straight(100.0).to_path("straight")
    for kwargs in ({"path": plain, "outline": CAR}, {"path": path, "outline": None}):
        m = compute_metrics(
            trace, scenario="s", controller="c", vehicle="v", completed=True, path_length_m=100.0, **kwargs
        )
        assert (m.min_track_margin_m, m.left_track) == (None, None)
    # metrics.json carries them (and infeasible_curvature) for a run whose result knows the outline.
    vehicle = make_vehicle("kinematic-bicycle")
    result = Simulation(Scenario("straight", path, "a straight"), vehicle, make_controller("stanley", vehicle.geometry))
    run = dataclasses.replace(result.run(), outline=VehicleOutline.of(vehicle), infeasible_curvature=())
    run.save(tmp_path, with_plots=False)
    document = json.loads((tmp_path / "metrics.json").read_text())
    assert document["min_track_margin_m"] == pytest.approx(2.0 - 1.61 / 2, abs=0.01)  # on the line, 2 m to the right
    assert document["left_track"] is False and document["infeasible_curvature"] == []
    assert list(document)[-3:] == ["infeasible_curvature", "status", "message"]


def _stadium_file(folder: Path, radius_m: float, left_m: float, right_m: float, straight_m: float = 80.0) -> Path:
    """The stadium track (`stadium_tracks.stadium_file`)."""
    return stadium_file(folder, "stadium.csv", radius_m, right_m, left_m, straight_m)


def _brute_force_margins(
    path: ReferencePath, trace: dict[str, np.ndarray], outline: VehicleOutline, steps: np.ndarray
) -> np.ndarray:
    """At each of `steps`, the least margin over the outline's perimeter every 5 cm: each point's foot is the path's
    nearest sample (over the whole path, 0.1 m apart), its margin the width there less its offset across the path."""
    units = [(("x_m", "y_m", "yaw_rad"), (outline.front_m, outline.rear_m))]
    if outline.trailer_front_m is not None and outline.trailer_rear_m is not None:
        units.append(
            (("trailer_x_m", "trailer_y_m", "trailer_yaw_rad"), (outline.trailer_front_m, outline.trailer_rear_m))
        )
    half = outline.width_m / 2
    result = np.full(steps.size, np.inf)
    for names, (front, rear) in units:
        along = np.arange(-rear, front + 1e-9, 0.05)
        across = np.arange(-half, half + 1e-9, 0.05)
        local = np.concatenate(
            [np.column_stack((along, np.full(along.size, side))) for side in (half, -half)]
            + [np.column_stack((np.full(across.size, end), across)) for end in (front, -rear)]
        )
        for k, step in enumerate(steps):
            x, y, yaw = (float(trace[name][step]) for name in names)
            px = x + local[:, 0] * math.cos(yaw) - local[:, 1] * math.sin(yaw)
            py = y + local[:, 0] * math.sin(yaw) + local[:, 1] * math.cos(yaw)
            nearest = np.argmin((px[:, None] - path.x_m) ** 2 + (py[:, None] - path.y_m) ** 2, axis=1)
            h = path.heading_rad[nearest]
            offset = (py - path.y_m[nearest]) * np.cos(h) - (px - path.x_m[nearest]) * np.sin(h)
            margin = np.minimum(path.width_left_m[nearest] - offset, path.width_right_m[nearest] + offset)
            result[k] = min(result[k], float(margin.min()))
    return result
