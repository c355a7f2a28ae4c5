"""The plot worker (`workbench/simulation/plot_worker.py`): a second process draws a run's plots exactly as this one
would, from a drawing that unpickles with numpy alone; whatever goes wrong there, the plots are drawn here."""

from __future__ import annotations

import json
import os
import pickle
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from workbench.simulation import plots
from workbench.simulation.plot_worker import PlotWorker
from workbench.simulation.plots import CourseLabel, PathOutline, RunDrawing
from workbench.simulation.result import SimulationResult

ROOT = Path(__file__).resolve().parents[3]


def _run(with_trailer: bool = True) -> RunDrawing:
    """A made-up lap of a 50 m circle: what a plot reads, and one signal it does not."""
    t = np.linspace(0.0, 40.0, 2001)
    angle = t / 40.0 * 2.0 * np.pi
    trace = {
        "t_s": t,
        "x_m": 50.0 * np.cos(angle),
        "y_m": 50.0 * np.sin(angle),
        "progress_m": 50.0 * angle,
        "cte_m": 0.1 * np.sin(5.0 * angle),
        "steer_wheel_cmd_rad": 0.5 + 0.01 * np.sin(30.0 * angle),
        "steer_wheel_rad": 0.5 + 0.01 * np.sin(30.0 * angle - 0.3),
        "speed_ref_mps": np.full_like(t, 7.85),
        "speed_mps": 7.85 + 0.05 * np.sin(angle),
        "ltr": np.zeros_like(t),
    }
    if with_trailer:
        trace["trailer_x_m"], trace["trailer_y_m"] = 45.0 * np.cos(angle), 45.0 * np.sin(angle)
    path_angle = np.linspace(0.0, 2.0 * np.pi, 315)
    path = PathOutline(50.0 * np.cos(path_angle), 50.0 * np.sin(path_angle), None)
    return RunDrawing(trace, path, CourseLabel("circle", "a 50 m circle", None), "pure-pursuit", "truck")


def test_a_drawing_keeps_only_what_the_plots_read() -> None:
    run = _run()
    drawing = RunDrawing.of(run)
    assert set(drawing.trace) == set(plots.RUN_PLOT_SIGNALS)
    assert "ltr" not in drawing.trace
    assert set(RunDrawing.of(_run(with_trailer=False)).trace) == set(plots.RUN_PLOT_SIGNALS) - {
        "trailer_x_m",
        "trailer_y_m",
    }
    assert drawing.scenario == run.scenario and drawing.controller == "pure-pursuit"


def test_a_drawing_unpickles_without_the_runs_libraries(tmp_path: Path) -> None:
    """What the worker receives needs numpy and the plots module only: not scipy, numba or pandas, which a
    SimulationResult would import (and which would compete with the simulation for the CPU)."""
    file = tmp_path / "drawing.pkl"
    file.write_bytes(pickle.dumps(_run()))
    code = (
        "import json, pickle, sys\n"
        f"pickle.loads(open({str(file)!r}, 'rb').read())\n"
        "print(json.dumps(sorted(m for m in ('scipy', 'numba', 'pandas', 'matplotlib') if m in sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []


def test_the_worker_draws_the_plots_this_process_would(tmp_path: Path) -> None:
    run = _run()
    here, there = tmp_path / "here", tmp_path / "there"
    here.mkdir()
    there.mkdir()
    expected = plots.save_run_plots(run, here)
    with PlotWorker() as worker:
        worker.submit(run, there)
        drawn = worker.wait()
    assert drawn == [there / path.name for path in expected]
    for mine, theirs in zip(expected, drawn, strict=True):
        np.testing.assert_array_equal(imread(theirs), imread(mine), err_msg=mine.name)


def test_a_worker_that_is_gone_leaves_the_plots_to_the_caller(tmp_path: Path) -> None:
    worker = PlotWorker()
    worker._process.kill()
    worker._process.join()
    worker.submit(_run(), tmp_path)
    assert worker.wait() is None
    worker.close()
    assert not worker._process.is_alive()


def test_a_drawing_that_fails_in_the_worker_is_left_to_the_caller(tmp_path: Path) -> None:
    broken = _run()
    del broken.trace["cte_m"]
    with PlotWorker() as worker:
        worker.submit(broken, tmp_path)
        assert worker.wait() is None
    with pytest.raises(KeyError, match="cte_m"):  # drawn again here, the error is this process's own
        plots.save_run_plots(broken, tmp_path)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")
def test_ctrl_c_is_left_to_this_process_from_the_workers_start(tmp_path: Path) -> None:
    """A terminal's Ctrl-C reaches the whole process group: the worker neither dies of it nor prints a
    KeyboardInterrupt, even in its start-up; this process ends it."""
    with PlotWorker() as worker:
        os.kill(worker._process.pid, signal.SIGINT)  # at once: the worker is still starting
        worker.submit(_run(), tmp_path)
        assert worker.wait() == [tmp_path / name for name in plots.RUN_PLOTS]


def test_closing_an_unused_worker_stops_it() -> None:
    worker = PlotWorker()
    worker.close()
    assert not worker._process.is_alive()
    assert worker.wait() is None


@pytest.fixture(scope="module")
def dlc_result() -> SimulationResult:
    from controllers.pure_pursuit import PurePursuit
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import Simulation, SimulationConfig
    from workbench.vehicles import make_vehicle

    vehicle = make_vehicle("kinematic-bicycle")
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    return Simulation(scenario, vehicle, PurePursuit(vehicle.geometry), SimulationConfig(speed_kmh=30.0)).run()


@pytest.mark.parametrize("alive", [True, False], ids=["worker", "worker gone"])
def test_a_saved_run_has_its_plots_whether_or_not_the_worker_draws_them(
    dlc_result: SimulationResult, tmp_path: Path, alive: bool
) -> None:
    with PlotWorker() as worker:
        if not alive:
            worker._process.kill()
            worker._process.join()
        written = dlc_result.save(tmp_path, plot_worker=worker)
    names = ["trace.parquet", "metrics.json", *plots.RUN_PLOTS]
    assert [path.name for path in written] == names
    assert all((tmp_path / name).stat().st_size > 0 for name in names)
