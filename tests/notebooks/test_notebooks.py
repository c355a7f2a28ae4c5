"""The notebooks in notebooks/: each is stored without outputs and runs top to bottom headless.

Each notebook is executed with nbclient in a fresh kernel of this interpreter (a kernelspec written for
sys.executable, so that the kernel sees the same installed packages as the tests), with the Agg backend, in a
temporary working directory and with a timeout per cell. The last cell of each prints a JSON summary of what it
computed, which is checked here.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import nbformat
import pytest
from ipykernel.kernelspec import write_kernel_spec
from nbclient import NotebookClient

NOTEBOOK_DIR = Path(__file__).resolve().parents[2] / "notebooks"
#: Seconds any one cell may take (each notebook runs in well under a minute in all).
CELL_TIMEOUT_S = 300
KERNEL_NAME = "python3"


def check_clothoid_step_by_step(summary: dict) -> None:
    assert 5.0 <= summary["chosen_lookahead_m"] <= 20.0
    # The bisection scores fewer candidates than the whole grid.
    assert 2 <= summary["evaluations"] < summary["candidates"] == 31
    assert summary["frechet_m"] <= summary["threshold_m"]
    # discrete_frechet on the sampled clothoid and reference gives the score the search computed.
    assert summary["discrete_frechet_m"] == pytest.approx(summary["frechet_m"], abs=1e-9)
    assert summary["fit_ok"] and summary["fit_status"] == 0
    assert summary["sweep_nondecreasing"]
    assert summary["min_frechet_minus_cte_m"] < 0.03  # Figure 5b on a straight: least Fréchet distance = |CTE|
    assert summary["closed_loop_completed"]


def check_lag_and_lead(summary: dict) -> None:
    # The loaded truck's lag at 30 km/h (README: omega_n 4.29 rad/s, zeta 0.78, K 0.94).
    assert 3.5 < summary["omega_n_rad_s"] < 5.5
    assert 0.5 < summary["zeta"] < 1.1
    assert 0.8 < summary["steady_state_gain"] < 1.0
    assert summary["nrmse"] < 0.05
    # The design cancels the lag's poles and widens the bandwidth.
    assert summary["omega_z_rad_s"] == pytest.approx(summary["omega_n_rad_s"])
    assert summary["psi"] == pytest.approx(summary["zeta"])
    assert summary["omega_p_rad_s"] > summary["omega_z_rad_s"]
    assert summary["cascade_bandwidth_rad_s"] > 2.0 * summary["plant_bandwidth_rad_s"]
    for lagged, compensated in zip(
        summary["validation_nrmse_lagged"], summary["validation_nrmse_compensated"], strict=True
    ):
        assert compensated < lagged
    assert summary["closed_loop_completed"]
    cte = summary["closed_loop_max_abs_cte_m"]
    # the shipped filter (designed for the loop's margins) tracks better than none; every variant within 0.2 m
    assert cte["shipped (margins design)"] < cte["no filter"]
    assert max(cte.values()) < 0.2
    # The lag slows with speed (Figure 7b).
    omega_n = summary["schedule_omega_n_rad_s"]
    assert omega_n == sorted(omega_n, reverse=True)


def check_fig17_comparison(summary: dict) -> None:
    published = summary.pop("published")
    assert published == ["clothoid on tractor-semitrailer", "nmpc on dynamic-bicycle"]
    assert set(summary) == {
        f"{c} on {v}" for c in ("clothoid", "nmpc") for v in ("tractor-semitrailer", "dynamic-bicycle")
    }
    for run in summary.values():
        assert run["status"] == "completed"
        assert run["max_abs_cte_m"] == pytest.approx(1.0, abs=0.05)  # the initial offset
        assert math.isfinite(run["converge_distance_m"])


def check_parameter_study(summary: dict) -> None:
    rows = summary["rows"]
    assert len(rows) == 10
    assert all(row["status"] == "completed" for row in rows)
    for mode in ("excess", "absolute"):
        by_threshold = {row["frechet_threshold_m"]: row for row in rows if row["threshold_mode"] == mode}
        assert set(by_threshold) == {0.01, 0.02, 0.05, 0.2, 0.5}
        # With the feed-forward, tracking depends little on the threshold: every one within 0.1 m, thresholds up to
        # 0.2 m within 35 % of each other (measured 0.019-0.024 m, 31 %) and the longest lookaheads (0.5 m) within
        # 1.5 x the best; a larger threshold steers less (longer lookaheads, a lower loop gain).
        cte = [row["max_abs_cte_m"] for row in by_threshold.values()]
        short = [row["max_abs_cte_m"] for t, row in by_threshold.items() if t <= 0.2]
        assert max(cte) < 0.1 and max(cte) < 1.5 * min(cte) and max(short) < 1.35 * min(short)
        assert by_threshold[0.5]["rms_steer_rate_deg_s"] < 0.98 * by_threshold[0.01]["rms_steer_rate_deg_s"]
        for row in by_threshold.values():
            # the notebook's steering rate from the trace is the summary's metric
            assert row["max_steer_rate_deg_s"] == pytest.approx(row["max_abs_steer_rate_deg_s"], rel=1e-9)
            assert 0.0 < row["rms_steer_rate_deg_s"] <= row["max_steer_rate_deg_s"]
            assert 5.0 <= row["mean_lookahead_m"] <= 20.0
            assert row["step_time_ratio"] > 0.0
    # A larger lookahead on average with a larger threshold, the mechanism of the trade-off.
    excess = [row["mean_lookahead_m"] for row in rows if row["threshold_mode"] == "excess"]
    assert excess == sorted(excess)


CHECKS: dict[str, Callable[[dict], None]] = {
    "01_clothoid_step_by_step.ipynb": check_clothoid_step_by_step,
    "02_lag_and_lead.ipynb": check_lag_and_lead,
    "03_fig17_comparison.ipynb": check_fig17_comparison,
    "04_parameter_study.ipynb": check_parameter_study,
}


def test_the_notebooks_are_the_four_checked_here() -> None:
    assert sorted(p.name for p in NOTEBOOK_DIR.glob("*.ipynb")) == sorted(CHECKS)


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_notebook_is_stored_without_outputs(name: str) -> None:
    notebook = nbformat.read(NOTEBOOK_DIR / name, as_version=4)
    nbformat.validate(notebook)
    code_cells = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert code_cells
    for index, cell in enumerate(code_cells):
        assert cell.outputs == [], f"{name}: code cell {index} has stored outputs; clear them before committing"
        assert cell.execution_count is None, f"{name}: code cell {index} has an execution count; clear it"
    assert notebook.metadata.get("kernelspec", {}).get("name") == KERNEL_NAME


@pytest.fixture
def kernel_of_this_interpreter(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A "python3" kernelspec that starts sys.executable, found first (JUPYTER_PATH precedes the user's and the
    environment's kernelspecs), so that the kernel is this venv's whatever else is installed."""
    data_dir = tmp_path / "jupyter"
    write_kernel_spec(data_dir / "kernels" / KERNEL_NAME)
    monkeypatch.setenv("JUPYTER_PATH", str(data_dir))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    return KERNEL_NAME


def _stdout_json(cell: nbformat.NotebookNode) -> dict:
    """The JSON object the cell printed on stdout (its last line that starts with "{")."""
    text = "".join(o.text for o in cell.outputs if o.output_type == "stream" and o.name == "stdout")
    lines = [line for line in text.splitlines() if line.startswith("{")]
    assert lines, f"the last cell printed no JSON summary; it printed {text!r}"
    return json.loads(lines[-1])


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_notebook_runs_top_to_bottom(name: str, tmp_path: Path, kernel_of_this_interpreter: str) -> None:
    notebook = nbformat.read(NOTEBOOK_DIR / name, as_version=4)
    work_dir = tmp_path / "work"
    work_dir.mkdir()
    client = NotebookClient(
        notebook,
        timeout=CELL_TIMEOUT_S,
        kernel_name=kernel_of_this_interpreter,
        resources={"metadata": {"path": str(work_dir)}},
    )
    start = time.perf_counter()
    client.execute()  # raises CellExecutionError, with the cell and its traceback, if any cell fails
    elapsed = time.perf_counter() - start
    code_cells = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert not [o for cell in code_cells for o in cell.outputs if o.output_type == "error"]
    assert all(cell.execution_count is not None for cell in code_cells), "not every cell ran"
    CHECKS[name](_stdout_json(code_cells[-1]))
    print(f"{name}: {elapsed:.1f} s", file=sys.stderr)
