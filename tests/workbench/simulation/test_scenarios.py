"""Tests for workbench.simulation.scenarios: the figure-8's crossing and closure, the Figure 17 path's piece lengths and
curvature profile, the ISO 3888-1 double lane change against its lane layout, Zandvoort from the shared track
file, scenarios from waypoint files, and the error messages for names and files.

Measured when written: the figure-8's geometry re-integrated from its analytic heading and curvature agrees with
the pyclothoids positions to 2e-8 m and closes to 1.4e-8 m; the double lane change's centre line deviates from
each lane's centre by < 3.5e-6 m inside the lane sections (the margin is 0.25-0.51 m), its curvature from the
analytic y(x) by 0.03% of the peak away from the smoothstep junctions (1.5% at them); Zandvoort's spline
length is 4317.1 m (0.014% above the nominal 4316.5 m).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation import scenarios
from workbench.simulation.scenarios import (
    SCENARIOS,
    ZANDVOORT_ENV,
    ScenarioOptions,
    describe_scenarios,
    make_scenario,
)

TRACKS = Path(__file__).resolve().parents[4] / "shared" / "tracks"
ZANDVOORT_TRACK = TRACKS / "Zandvoort_track.csv"
needs_zandvoort = pytest.mark.skipif(
    not ZANDVOORT_TRACK.is_file(),
    reason=f"TUMFTM Zandvoort_track.csv not found in {TRACKS} (third-party data kept outside the repo)",
)

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(6)


def integrate_from_heading(path: ReferencePath) -> tuple[np.ndarray, np.ndarray]:
    """Positions re-integrated from the path's heading and curvature samples alone.

    On each interval the heading is the cubic Hermite interpolant of (theta, kappa) at its ends (exact for a
    clothoid, whose heading is quadratic; nearly so where a piece boundary falls inside the interval), and cos/sin
    of it are integrated by 6-point Gauss-Legendre.
    """
    h = path.spacing_m
    th0, th1 = path.heading_rad[:-1, None], path.heading_rad[1:, None]
    k0, k1 = path.curvature_1pm[:-1, None], path.curvature_1pm[1:, None]
    u = 0.5 * (_GL_NODES[None, :] + 1.0)  # in [0, 1]
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    theta = h00 * th0 + h10 * h * k0 + h01 * th1 + h11 * h * k1
    dx = 0.5 * h * (np.cos(theta) @ _GL_WEIGHTS)
    dy = 0.5 * h * (np.sin(theta) @ _GL_WEIGHTS)
    return path.x_m[0] + np.concatenate(([0.0], np.cumsum(dx))), path.y_m[0] + np.concatenate(([0.0], np.cumsum(dy)))


def closest_distance(path: ReferencePath, px: float, py: float, lo: int, hi: int) -> tuple[float, float]:
    """(distance, s) of the closest point to (px, py) on the path's segments lo..hi-1 (brute force)."""
    ax, ay = path.x_m[lo:hi], path.y_m[lo:hi]
    dx, dy = path.x_m[lo + 1 : hi + 1] - ax, path.y_m[lo + 1 : hi + 1] - ay
    t = np.clip(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
    d = np.hypot(ax + t * dx - px, ay + t * dy - py)
    k = int(np.argmin(d))
    return float(d[k]), float((lo + k + t[k]) * path.spacing_m)


# ---------------------------------------------------------------------------------------------- figure-8
@pytest.fixture(scope="module")
def figure8_path() -> ReferencePath:
    return make_scenario("figure8").path


def test_figure8_is_closed_and_curvature_continuous(figure8_path: ReferencePath) -> None:
    path = figure8_path
    assert path.closed
    kappa = path.curvature_1pm
    radius = 1.0 / np.abs(kappa).max()
    assert 20.0 <= radius <= 25.0
    assert radius == pytest.approx(22.0, abs=1e-9)  # the documented default
    # Clothoid transitions of 15 m take the curvature from 0 to 1/R: that bounds every step between samples.
    assert np.abs(np.diff(kappa)).max() <= (1 / 22) / 15 * path.spacing_m + 1e-12
    assert abs(kappa[0] - kappa[-1]) < 1e-12
    assert np.abs(np.diff(path.heading_rad)).max() <= np.abs(kappa).max() * path.spacing_m + 1e-12
    # Two opposite 270-degree lobes: no net turning over the loop.
    assert path.heading_rad[-1] == pytest.approx(path.heading_rad[0], abs=1e-9)
    # Both lobes turn 270 degrees: the heading spans [pi/4 - 3 pi/2, pi/4] or similar, i.e. 270 degrees in all.
    assert np.ptp(path.heading_rad) == pytest.approx(1.5 * math.pi, abs=1e-9)


def test_figure8_self_crosses_at_the_origin(figure8_path: ReferencePath) -> None:
    path = figure8_path
    n = path.x_m.size
    assert math.hypot(path.x_m[0], path.y_m[0]) < 1e-12  # s = 0 is at the origin
    # A second, distinct s in the middle half of the loop passes through the origin too.
    distance, s_mid = closest_distance(path, 0.0, 0.0, n // 4, 3 * n // 4)
    assert distance < 1e-6
    assert path.length_m / 4 < s_mid < 3 * path.length_m / 4
    # ...and nowhere else: away from both passes the path keeps its distance from the origin.
    s = path.s_m
    away = (np.minimum(s, path.length_m - s) > 20.0) & (np.abs(s - s_mid) > 20.0)
    assert np.hypot(path.x_m[away], path.y_m[away]).min() > 10.0
    # The two passes cross at 90 degrees.
    h0 = float(path.heading(0.0))
    h1 = float(path.heading(s_mid))
    assert h0 == pytest.approx(math.pi / 4, abs=1e-12)
    assert abs(math.cos(h1 - h0)) < 1e-9
    # By symmetry of the lobes the second pass is halfway round.
    assert s_mid == pytest.approx(path.length_m / 2, abs=1e-6)


def test_figure8_closes_exactly(figure8_path: ReferencePath) -> None:
    path = figure8_path
    x, y = integrate_from_heading(path)
    # The pyclothoids positions agree with the heading re-integrated, and the re-integrated loop ends at its start
    # (the last sample is set equal to the first, so this checks the geometry, not that assignment).
    assert np.hypot(x[:-1] - path.x_m[:-1], y[:-1] - path.y_m[:-1]).max() < 1e-6
    assert math.hypot(x[-1] - path.x_m[0], y[-1] - path.y_m[0]) < 1e-6
    # The loop ends on a straight: the last sample is one spacing along the heading from the one before.
    h = path.heading_rad[-1]
    gap = math.hypot(
        path.x_m[-2] + path.spacing_m * math.cos(h) - path.x_m[-1],
        path.y_m[-2] + path.spacing_m * math.sin(h) - path.y_m[-1],
    )
    assert gap < 1e-6


# ---------------------------------------------------------------------------------------------- Figure 17
FIG17_PIECES = [  # (length, start curvature, end curvature) as the docstring states them
    (40.0, 0.0, 0.0),
    (20.0, 0.0, 1 / 30),
    (30.0, 1 / 30, 1 / 30),
    (40.0, 1 / 30, -1 / 30),
    (30.0, -1 / 30, -1 / 30),
    (20.0, -1 / 30, 0.0),
    (60.0, 0.0, 0.0),
]


def fig17_kappa(s: np.ndarray) -> np.ndarray:
    lengths = np.array([p[0] for p in FIG17_PIECES])
    starts = np.concatenate(([0.0], np.cumsum(lengths)))
    k = np.empty_like(s)
    for (length, k0, k1), a in zip(FIG17_PIECES, starts[:-1], strict=True):
        mask = (s >= a) & (s <= a + length)
        k[mask] = k0 + (k1 - k0) * (s[mask] - a) / length
    return k


def test_fig17_pieces_and_curvature_profile() -> None:
    scenario = make_scenario("fig17")
    path = scenario.path
    assert not path.closed
    assert sum(p[0] for p in FIG17_PIECES) == 240.0
    assert path.length_m == pytest.approx(240.0, abs=1e-9)
    assert np.abs(path.curvature_1pm).max() == pytest.approx(1 / 30, abs=1e-12)
    # The whole profile follows the stated pieces (so the breakpoints sit at 40, 60, 90, 130, 160, 180 m).
    assert np.abs(path.curvature_1pm - fig17_kappa(path.s_m)).max() < 1e-12
    # Spot values from the specification.
    spots = {50.0: 0.5 / 30, 75.0: 1 / 30, 100.0: 0.5 / 30, 150.0: -1 / 30, 175.0: -0.25 / 30, 210.0: 0.0}
    for s, kappa in spots.items():
        assert float(path.curvature(s)) == pytest.approx(kappa, abs=1e-9), f"kappa({s})"
    # Net turning: +1/30 * (10 + 30) ... the S-bend's two halves cancel, so it leaves heading as it came.
    assert path.heading_rad[-1] == pytest.approx(0.0, abs=1e-12)
    assert path.heading(90.0) == pytest.approx(20 / 30 / 2 + 30 / 30, abs=1e-9)  # clothoid turn + arc turn


def test_fig17_starts_one_metre_left_of_the_path() -> None:
    scenario = make_scenario("fig17")
    assert scenario.initial_offset_m == 1.0
    x, y, heading = scenario.initial_pose()
    assert (x, y, heading) == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)  # +y is left of a path along +x
    foot = scenario.path.tracker(0.0).update(x, y)
    assert foot.cte_m == pytest.approx(1.0, abs=1e-9)
    assert foot.s_m == pytest.approx(0.0, abs=1e-9)


# ---------------------------------------------------------------------------------------------- ISO 3888-1
B = 2.59


def iso3888_lanes(b: float) -> list[tuple[float, float, float, float]]:
    """(x start, x end, lane centre y, lane width) of sections 1, 3 and 5 from ISO 3888-1, as the scenario lays
    them out: 40 m run-in; sections 15/30/25/25/15 m; 3.5 m between the right-hand edges of lanes 1 and 3; the
    exit lane centred on the entry lane."""
    w1, w3, w5 = 1.1 * b + 0.25, 1.2 * b + 0.25, 1.3 * b + 0.25
    c3 = -w1 / 2 + 3.5 + w3 / 2
    return [(40.0, 55.0, 0.0, w1), (85.0, 110.0, c3, w3), (135.0, 150.0, 0.0, w5)]


def smoothstep_centre_line(x: np.ndarray, b: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """y, y', y'' of the analytic centre line: quintic smoothsteps over sections 2 (55-85 m) and 4 (110-135 m)."""
    h = iso3888_lanes(b)[1][2]
    y = np.zeros_like(x)
    y1 = np.zeros_like(x)
    y2 = np.zeros_like(x)
    for a, length, sign in ((55.0, 30.0, 1.0), (110.0, 25.0, -1.0)):
        u = np.clip((x - a) / length, 0.0, 1.0)
        inside = (x > a) & (x < a + length)
        y += sign * h * u**3 * (10 - 15 * u + 6 * u**2)
        y1 += np.where(inside, sign * h * 30 * u**2 * (1 - u) ** 2 / length, 0.0)
        y2 += np.where(inside, sign * h * 60 * u * (1 - u) * (1 - 2 * u) / length**2, 0.0)
    return y, y1, y2


def test_dlc_lane_widths_and_cones() -> None:
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=B))
    lanes = iso3888_lanes(B)
    assert [w for *_, w in lanes] == pytest.approx([3.099, 3.358, 3.617], abs=1e-12)
    expected_cones = []
    for start, end, centre, width in lanes:
        for x in np.linspace(start, end, 3):
            expected_cones += [(x, centre - width / 2), (x, centre + width / 2)]
    np.testing.assert_allclose(scenario.cones_xy, np.array(expected_cones), atol=1e-12)
    for text in ("3.10", "3.36", "3.62"):
        assert text in scenario.description


def test_dlc_centre_line_stays_in_every_lane() -> None:
    path = make_scenario("dlc", ScenarioOptions(vehicle_width_m=B)).path
    assert not path.closed
    assert path.x_m[0] == pytest.approx(0.0, abs=1e-12) and path.x_m[-1] == pytest.approx(190.0, abs=1e-9)
    for start, end, centre, width in iso3888_lanes(B):
        inside = (path.x_m >= start) & (path.x_m <= end)
        assert inside.sum() > 100
        deviation = np.abs(path.y_m[inside] - centre)
        # A vehicle of width b centred on the line keeps its half width clear of the cones on both sides.
        assert deviation.max() <= (width - B) / 2
        assert deviation.max() < 1e-4  # in fact the line is straight on the lane's centre there
    # Between the lanes the line never leaves the band spanned by the lane centres.
    assert path.y_m.min() > -1e-4 and path.y_m.max() < iso3888_lanes(B)[1][2] + 1e-4


def test_dlc_curvature_is_analytic_continuous_and_bounded() -> None:
    path = make_scenario("dlc", ScenarioOptions(vehicle_width_m=B)).path
    y, y1, y2 = smoothstep_centre_line(path.x_m, B)
    assert np.abs(path.y_m - y).max() < 1e-4
    kappa = y2 / (1 + y1**2) ** 1.5
    peak = np.abs(kappa).max()
    # The spline through the 0.5 m waypoints rings slightly where the smoothsteps join the straights (dkappa/ds
    # jumps there): 1.5% of the peak (4.9e-4 1/m) at worst, below 0.1% elsewhere.
    assert np.abs(path.curvature_1pm - kappa).max() < 0.02 * peak
    junctions = np.min(np.abs(path.x_m[:, None] - np.array([55.0, 85.0, 110.0, 135.0])[None, :]), axis=1) < 2.0
    assert np.abs(path.curvature_1pm - kappa)[~junctions].max() < 0.002 * peak
    assert np.abs(path.curvature_1pm).max() <= 0.04
    # Continuity: no step larger than the analytic curvature rate allows over one sample spacing.
    x_fine = np.linspace(0.0, 190.0, 190_001)
    _, f1, f2 = smoothstep_centre_line(x_fine, B)
    k_fine = f2 / (1 + f1**2) ** 1.5
    rate = np.abs(np.diff(k_fine) / np.diff(x_fine)).max()  # |dkappa/dx| >= |dkappa/ds| since dx/ds <= 1
    assert np.abs(np.diff(path.curvature_1pm)).max() <= 1.05 * rate * path.spacing_m


# ---------------------------------------------------------------------------------------------- Zandvoort
@needs_zandvoort
def test_zandvoort_from_the_environment_variable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ZANDVOORT_ENV, str(ZANDVOORT_TRACK))
    scenario = make_scenario("zandvoort")
    assert scenario.name == "zandvoort"
    path = scenario.path
    assert path.closed
    assert path.length_m == pytest.approx(4316.5, rel=0.005)
    # The loop closes smoothly: position, heading (one full turn) and curvature agree across the seam.
    assert path.x_m[-1] == path.x_m[0] and path.y_m[-1] == path.y_m[0]
    assert abs(abs(path.heading_rad[-1] - path.heading_rad[0]) - 2 * math.pi) < 1e-6
    assert abs(path.curvature_1pm[1] - path.curvature_1pm[-2]) < 0.01


@needs_zandvoort
def test_zandvoort_from_the_track_option(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ZANDVOORT_ENV, raising=False)
    path = make_scenario("zandvoort", ScenarioOptions(track_file=ZANDVOORT_TRACK)).path
    assert path.closed and path.length_m == pytest.approx(4316.5, rel=0.005)


def test_zandvoort_without_a_track_file(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv(ZANDVOORT_ENV, raising=False)
    monkeypatch.chdir(tmp_path)  # no tracks/ here
    monkeypatch.setattr(scenarios, "CHECKOUT_ROOT", tmp_path / "checkout")  # nothing in ../shared/tracks beside it
    with pytest.raises(WorkbenchInputError, match=r"download it") as info:
        make_scenario("zandvoort")
    message = str(info.value)
    assert "https://github.com/TUMFTM/racetrack-database" in message
    assert ZANDVOORT_ENV in message and "--track" in message
    for folder in (tmp_path / "tracks", tmp_path / "shared" / "tracks"):  # every place it looked, named
        for name in ("Zandvoort_track.csv", "Zandvoort.csv"):
            assert str(folder / name) in message
    # describe_scenarios still lists it, marked unavailable.
    rows = dict(describe_scenarios())
    assert list(rows) == [*SCENARIOS, "circuit:SEED"]
    assert "[unavailable:" in rows["zandvoort"]


def test_zandvoort_track_file_missing(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    missing = tmp_path / "nowhere" / "Zandvoort.csv"
    monkeypatch.setenv(ZANDVOORT_ENV, str(missing))
    with pytest.raises(WorkbenchInputError, match=rf"track file {re.escape(repr(str(missing)))} does not exist"):
        make_scenario("zandvoort")


# ---------------------------------------------------------------------------------------------- files and names
def test_csv_file_as_scenario(tmp_path: Path) -> None:
    radius = 30.0
    phi = np.linspace(0.0, math.pi, 40)
    file = tmp_path / "half_circle.csv"
    rows = "\n".join(f"{radius * math.cos(p)!r},{radius * math.sin(p)!r}" for p in phi)
    file.write_text("x,y\n" + rows + "\n", encoding="utf-8")
    scenario = make_scenario(str(file))
    assert scenario.name == "half_circle"
    assert not scenario.path.closed
    assert scenario.path.length_m == pytest.approx(math.pi * radius, rel=1e-4)
    assert np.abs(scenario.path.curvature_1pm * radius - 1.0).max() < 0.01
    assert "40 points, open path" in scenario.description


def test_closed_csv_file_as_scenario(tmp_path: Path) -> None:
    radius = 25.0
    phi = np.linspace(0.0, 2 * math.pi, 61)  # the last point repeats the first: a closed loop
    file = tmp_path / "ring.csv"
    rows = "\n".join(f"{radius * math.cos(p)!r},{radius * math.sin(p)!r},{10.0}" for p in phi)
    file.write_text("x_m,y_m,v\n" + rows + "\n", encoding="utf-8")
    path = make_scenario(str(file)).path
    assert path.closed
    assert path.length_m == pytest.approx(2 * math.pi * radius, rel=1e-4)
    assert np.abs(path.curvature_1pm * radius - 1.0).max() < 0.01
    assert path.speed_mps is not None and np.allclose(path.speed_mps, 10.0)


def test_unknown_scenario_name_lists_the_names() -> None:
    with pytest.raises(WorkbenchInputError, match=r"unknown scenario 'figure9'; choose one of figure8, dlc, fig17"):
        make_scenario("figure9")
    with pytest.raises(WorkbenchInputError, match=r"zandvoort or give a waypoint CSV file"):
        make_scenario("figure9")


def test_missing_waypoint_file(tmp_path: Path) -> None:
    missing = tmp_path / "missing.csv"
    with pytest.raises(WorkbenchInputError, match=rf"waypoint file {re.escape(repr(str(missing)))} does not exist"):
        make_scenario(str(missing))


@pytest.mark.parametrize("width", [0.2, 4.5, math.nan])
def test_bad_vehicle_width(width: float) -> None:
    with pytest.raises(WorkbenchInputError, match=rf"vehicle_width_m must be .*got {width!r}"):
        ScenarioOptions(vehicle_width_m=width)


def test_the_dlc_needs_the_width_of_the_vehicle_driven_on_it() -> None:
    """No default width: a dlc built without one is refused, naming the argument, rather than sized for another
    vehicle; each width gives its own lanes, and the scenarios that do not depend on the vehicle need none."""
    for options in (None, ScenarioOptions(), ScenarioOptions(track_file=Path("unused.csv"))):
        with pytest.raises(WorkbenchInputError, match=r"dlc sizes its lanes .*got vehicle_width_m=None"):
            make_scenario("dlc", options)
    car, truck = (make_scenario("dlc", ScenarioOptions(vehicle_width_m=b)) for b in (1.674, 2.59))
    # The entry lane is 1.1 b + 0.25 m wide: its cones lie +-(1.1 b + 0.25) / 2 about the centre line.
    assert np.ptp(car.cones_xy[:2, 1]) == pytest.approx(1.1 * 1.674 + 0.25, abs=1e-12)
    assert np.ptp(truck.cones_xy[:2, 1]) == pytest.approx(1.1 * 2.59 + 0.25, abs=1e-12)
    assert make_scenario("fig17").path.length_m > 0  # sized by nothing: no width needed
    described = dict(describe_scenarios())
    assert "lanes sized for the vehicle driven on it" in described["dlc"] and "2.59" not in described["dlc"]
