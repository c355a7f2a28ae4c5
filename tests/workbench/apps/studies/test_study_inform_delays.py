"""The run parameter inform_delays: a study's grid may tell its controllers the conditions' nominal delays
(`KnownDelays`, `Controller.informed_config`), after the vehicle's tuning; a spec without it plans the runs it
planned before."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import TINY_SPEC, write_spec

from workbench.apps.studies import execute_run, load_spec
from workbench.apps.studies import runner as study_runner
from workbench.apps.studies.spec import RUN_PARAMETERS
from workbench.base.errors import WorkbenchInputError

SPEC = """
[study]
scenarios = ["dlc"]
controllers = ["clothoid", "nmpc"]
vehicles = ["kinematic-bicycle"]

[grid]
conditions = "automotive"
inform_delays = [true, false]
max_time_s = 1.0
"""


def test_inform_delays_in_a_grid_reaches_the_controller_config(tmp_path: Path, monkeypatch) -> None:
    built: dict[tuple[str, bool], object] = {}
    make = study_runner.make_controller
    told_now: list[bool] = []

    def spy(name: str, geometry: object, config: object = None, **kwargs: object) -> object:
        built[name, told_now[-1]] = config
        return make(name, geometry, config, **kwargs)

    monkeypatch.setattr(study_runner, "make_controller", spy)
    spec = load_spec(write_spec(tmp_path, SPEC))
    rows = {}
    for run in spec.plan():
        told_now.append(dict(run.values)["inform_delays"])
        rows[run.controller, told_now[-1]] = execute_run(run)
    assert set(rows) == set(built) == {(c, t) for c in ("clothoid", "nmpc") for t in (True, False)}
    assert all(row["status"] in ("completed", "timeout") for row in rows.values())
    # automotive: pose latency 10 ms + dead time 100 ms, the clothoid's known delay; the NMPC's delay compensation
    # and, the pose being noisy, its pose filter
    assert built["clothoid", True].known_delay_s == pytest.approx(0.11, abs=1e-12)
    assert built["clothoid", False].known_delay_s == 0.0
    assert built["clothoid", True].tuning is not None  # told after the vehicle's tuning, which it keeps
    told = built["nmpc", True]
    assert (told.input_delay_s, told.measurement_latency_s, told.pose_filter_cutoff_hz) == (0.1, 0.010, 0.3)
    assert built["nmpc", False] == type(told)()
    assert rows["clothoid", True]["inform_delays"] is True and rows["clothoid", False]["inform_delays"] is False


def test_a_spec_without_inform_delays_plans_runs_without_it(tmp_path: Path) -> None:
    assert RUN_PARAMETERS["inform_delays"] is bool
    runs = load_spec(write_spec(tmp_path, TINY_SPEC)).plan()
    assert runs and all("inform_delays" not in dict(r.values) for r in runs)
    assert all("inform_delays" not in r.parameters() for r in runs)  # nor in their rows, nor in their ids' document


def test_an_inform_delays_that_is_not_true_or_false_is_refused(tmp_path: Path) -> None:
    text = SPEC.replace("inform_delays = [true, false]", 'inform_delays = "yes"')
    with pytest.raises(WorkbenchInputError, match="inform_delays"):
        load_spec(write_spec(tmp_path, text))
