"""The lookahead floors the tuning's margins design computed (lead.json's `lookahead_floor_m` per speed) are used
by the controller where they are the floors it would compute (the tuning's lags and lead filter, the same loop,
arc, search grid and margins), and computed where not; the floors used equal those computed."""

from __future__ import annotations

import dataclasses
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from controllers.clothoid import loop_analysis
from controllers.clothoid.controller import FLOOR_SPEED_STEP_KMH, ClothoidConfig, ClothoidController
from controllers.clothoid.vehicle_tuning import FloorDesign
from tuning.own_tuning import shipped_tuning_dir, tuning_for
from tuning.tuning_dirs import LEAD_FILE, MANIFEST_FILE, files_sha256, read_vehicle_tuning
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.vehicles import make_vehicle

STRAIGHT = ReferencePath.from_xy(np.linspace(0.0, 100.0, 11), np.zeros(11), name="straight")
#: The search grid of the shipped tunings' margins design (tuning.schedule.MARGINS_LOOKAHEAD_M).
TUNING_GRID = {"min_lookahead_m": 3.0, "lookahead_step_m": 0.5}


def _controller(vehicle_name: str, **options: object) -> ClothoidController:
    """A controller of the preset with its shipped tuning and these options, reset at 50 Hz."""
    vehicle = make_vehicle(vehicle_name)
    controller = ClothoidController(vehicle.geometry, ClothoidConfig(tuning=tuning_for(vehicle), **options))
    controller.reset(STRAIGHT, 0.02)
    return controller


@pytest.fixture
def computed(monkeypatch: pytest.MonkeyPatch) -> list[tuple[float, float]]:
    """(speed m/s, floor m) of every floor `loop_analysis.lookahead_floor` computes during the test."""
    calls: list[tuple[float, float]] = []
    compute = loop_analysis.lookahead_floor

    def counted(*args: object, **kwargs: object) -> float:
        floor = compute(*args, **kwargs)
        calls.append((float(args[2]), floor))  # type: ignore[arg-type]
        return floor

    monkeypatch.setattr(loop_analysis, "lookahead_floor", counted)
    return calls


def _computed_floor_m(controller: ClothoidController, node: int, min_lookahead_m: float | None = None) -> float:
    """The floor `loop_analysis.lookahead_floor` computes for the controller's speed node, on its own grid or on one
    from min_lookahead_m (the reference a recorded floor must equal)."""
    lags, settings, v, curvatures, delayed = controller._floor_inputs(node)
    cfg = controller.config
    low = cfg.min_lookahead_m if min_lookahead_m is None else min_lookahead_m
    return loop_analysis.lookahead_floor(
        lags, settings, v, low, controller._floor_search_top_m, cfg.lookahead_step_m, curvatures,
        cfg.min_phase_margin_deg, cfg.min_gain_margin_db, delayed,
    )  # fmt: skip


@pytest.mark.parametrize("vehicle_name", ["tractor-semitrailer", "dynamic-bicycle"])
def test_recorded_floors_are_used_at_every_identified_speed_and_equal_the_analysis(
    vehicle_name: str, computed: list[tuple[float, float]]
) -> None:
    """On the design's grid every identified speed reuses its floor: the controller's arc (capped by its curvature
    limit, v**2) differs from the design's (capped at the lock, v * v) by a rounding at most once the same cap
    applies to both (the car's limits table rounds 0.4 g / v^2 in its tenth decimal)."""
    controller = _controller(vehicle_name, **TUNING_GRID)
    tuning = controller.tuning
    assert tuning is not None and tuning.floor_design is not None and len(tuning.floors) == 10
    for speed_kmh, recorded in tuning.floors:
        node = round(speed_kmh / FLOOR_SPEED_STEP_KMH)
        assert controller._node_floor_m(node) == recorded, speed_kmh
        assert not computed, speed_kmh
    for speed_kmh, recorded in tuning.floors:  # the reference, computed on the controller's own grid
        assert recorded == _computed_floor_m(controller, round(speed_kmh / FLOOR_SPEED_STEP_KMH)), speed_kmh


def test_a_reset_reusing_every_floor_runs_no_loop_analysis(monkeypatch: pytest.MonkeyPatch) -> None:
    """Paths planned at an identified speed: the reset fills the node's floor from the tuning, without importing
    the loop analysis (python-control) or computing a floor."""

    def refused(*args: object, **kwargs: object) -> float:
        raise AssertionError("a floor computed")

    monkeypatch.setattr(loop_analysis, "lookahead_floor", refused)
    monkeypatch.setitem(sys.modules, "controllers.clothoid.loop_analysis", None)  # importing it fails
    vehicle = make_vehicle("tractor-semitrailer")
    tuning = tuning_for(vehicle)
    for speed_kmh, recorded in tuning.floors:
        path = ReferencePath.from_xy(np.linspace(0.0, 100.0, 11), np.zeros(11), speed_mps=np.full(11, speed_kmh / 3.6))
        controller = ClothoidController(vehicle.geometry, ClothoidConfig(tuning=tuning, **TUNING_GRID))
        controller.reset(path, 0.02)
        assert controller._floors == {round(speed_kmh / FLOOR_SPEED_STEP_KMH): recorded}


@pytest.mark.parametrize(
    "grid", [{"min_lookahead_m": 3.25, "lookahead_step_m": 0.5}, {"min_lookahead_m": 3.0, "lookahead_step_m": 0.25}]
)
def test_a_floor_searched_on_another_grid_is_computed(grid: dict, computed: list[tuple[float, float]]) -> None:
    """A grid shifted off the design's or with another step visits other lookaheads: its floor is computed."""
    controller = _controller("tractor-semitrailer", **grid)
    controller._node_floor_m(round(30.0 / FLOOR_SPEED_STEP_KMH))
    assert len(computed) == 1


def test_a_floor_searched_from_a_lower_start_is_not_the_floor_from_a_higher_one() -> None:
    """Why the default grid (from min_lookahead_m = 5 m) does not reuse floors searched from 3 m: where the margins
    fail in a gap above a lookahead that keeps them, the search's bisection stops at other lookaheads from another
    start. The kinematic bicycle's shipped floor at 90 km/h, 5.5 m (kept 5.5-7 m, lost 7.5-9 m), is 9.5 m from
    5 m; max(recorded, 5 m) would be 5.5 m."""
    controller = _controller("kinematic-bicycle")
    node = round(90.0 / FLOOR_SPEED_STEP_KMH)
    recorded = dict(controller.tuning.floors)[90.0]
    assert _computed_floor_m(controller, node, TUNING_GRID["min_lookahead_m"]) == recorded
    assert controller.lookahead_floor_m(90.0 / 3.6) == _computed_floor_m(controller, node) > recorded + 1.0


def test_floor_inputs_match_within_a_rounding() -> None:
    """Computed inputs one rounding apart are one floor's; a difference a floor could see is not."""
    tuning = tuning_for(make_vehicle("tractor-semitrailer"))
    design = tuning.floor_design
    inputs = design.inputs(30.0, tuning.filter_schedule.at_speed(30.0), 0.1)
    arc = inputs.path_curvatures_1pm[1]
    assert inputs.matches(dataclasses.replace(inputs, path_curvatures_1pm=(0.0, arc * (1.0 + 1e-12))))
    assert not inputs.matches(dataclasses.replace(inputs, path_curvatures_1pm=(0.0, arc * (1.0 + 1e-6))))
    assert not inputs.matches(dataclasses.replace(inputs, lookahead_grid_m=(5.0, 40.0, 0.5)))
    assert design.inputs(30.0, inputs.lead, 0.1, curvature_limit_1pm=0.5 * arc).path_curvatures_1pm[1] == 0.5 * arc


def test_floors_are_computed_where_the_controller_analyses_another_loop(computed: list[tuple[float, float]]) -> None:
    """The default search grid (from min_lookahead_m = 5 m) is not the design's (from 3 m); another prediction time
    or margin is another loop; a speed between the identified ones has interpolated lags."""
    for options in (
        {},
        {**TUNING_GRID, "prediction_time_s": 0.3},
        {**TUNING_GRID, "min_phase_margin_deg": 50.0},
        {**TUNING_GRID, "use_lead_filter": False},
    ):
        controller = _controller("tractor-semitrailer", **options)
        before = len(computed)
        controller._node_floor_m(round(30.0 / FLOOR_SPEED_STEP_KMH))
        assert len(computed) == before + 1, options
    controller = _controller("tractor-semitrailer", **TUNING_GRID)
    before = len(computed)
    controller._node_floor_m(35)  # 35 km/h, between the identified 30 and 40
    assert len(computed) == before + 1


def test_a_tuning_refuses_floors_it_cannot_use() -> None:
    tuning = tuning_for(make_vehicle("tractor-semitrailer"))
    with pytest.raises(WorkbenchInputError, match=r"floors must be \(one of the lags' speeds .*got \(35\.0, 8\.0\)"):
        dataclasses.replace(tuning, floors=((35.0, 8.0),))
    with pytest.raises(WorkbenchInputError, match="floors need their floor_design"):
        dataclasses.replace(tuning, floors=((30.0, 8.0),), floor_design=None)
    assert tuning.floor_design == FloorDesign(0.02, 0.2, 0.4, (3.0, 40.0, 0.5))


def test_the_step_tables_are_built_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The limits', lags' and lead filter's tables depend on the config alone: built with the controller, not again
    at each reset."""
    built = []
    build = ClothoidController._tables
    monkeypatch.setattr(ClothoidController, "_tables", lambda self: built.append(1) or build(self))
    controller = _controller("tractor-semitrailer")
    controller.reset(STRAIGHT, 0.01)
    assert len(built) == 1
    assert controller.uses_preview and controller._lags is controller.tuning.preview_lag_tables[1]
    lags = _controller("dynamic-bicycle")
    assert not lags.uses_preview and lags._lags is lags.tuning.lag_tables[1]


def test_a_design_with_other_margins_has_floors_the_controller_computes_with_its_own(
    tmp_path: Path, computed: list[tuple[float, float]]
) -> None:
    """A lead file's design names the margins its floors keep; floors kept with other margins than the controller's
    are not its floors."""
    vehicle = make_vehicle("tractor-semitrailer")
    copied = tmp_path / "tuning"
    shutil.copytree(shipped_tuning_dir(vehicle), copied)
    lead = copied / LEAD_FILE
    doc = json.loads(lead.read_text())
    doc["design"]["phase_margin_deg"] = 50.0
    lead.write_text(json.dumps(doc))
    manifest = json.loads((copied / MANIFEST_FILE).read_text())
    manifest["files_sha256"] = files_sha256(copied)
    (copied / MANIFEST_FILE).write_text(json.dumps(manifest))
    tuning = read_vehicle_tuning(copied)
    assert tuning.floor_design is not None and tuning.floor_design.phase_margin_deg == 50.0
    controller = ClothoidController(vehicle.geometry, ClothoidConfig(tuning=tuning, **TUNING_GRID))
    controller.reset(STRAIGHT, 0.02)
    controller._node_floor_m(round(30.0 / FLOOR_SPEED_STEP_KMH))
    assert len(computed) == 1
