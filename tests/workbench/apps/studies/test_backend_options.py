"""The study commands' backend options (sweep, optimise, robustness, tournament), refused before any work when out
of range: --max-runs (below 1, and a robustness study larger than it), --workers (below 1 or above
MAX_WORKERS_PER_CPU per usable CPU) and --scheduler (not tcp://HOST:PORT, or no scheduler answering there)."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import NotSimulating, write_spec

import workbench.apps.studies.backends as backends
from workbench.apps.cli import main
from workbench.apps.robustness import plan_robustness
from workbench.apps.studies import DaskBackend, LocalBackend
from workbench.base.errors import WorkbenchInputError

ROBUSTNESS = ["robustness", "dlc", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle"]
#: The tiny study (study_helpers.TINY_SPEC) with an optimisation of one option of pure pursuit.
OPTIMISE = """
[optimise]
trials = 2

[optimise.objective]
rms_cte_m = 1.0

[optimise.search]
lookahead_gain_s = { uniform = [0.5, 1.5] }
"""

#: A tournament of pure pursuit alone, tuned on the dlc and judged on fig17.
TOURNAMENT = """
[tournament]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle"]
trials = 2

[train]
scenarios = ["dlc"]
speeds_kmh = [30]

[test]
scenarios = ["fig17"]
speeds_kmh = [30]
"""


def _study_commands(spec: Path, out: Path) -> list[list[str]]:
    """sweep, optimise, robustness and tournament, each complete but for the option under test."""
    text = spec.read_text().replace('controllers = ["pure-pursuit", "clothoid"]', 'controllers = ["pure-pursuit"]')
    text = text.split("[grid.clothoid]")[0]
    optimise = write_spec(spec.parent, text + OPTIMISE, "optimise.toml")
    return [
        ["sweep", str(spec), "--out", str(out)],
        ["optimise", str(optimise), "--out", str(out)],
        [*ROBUSTNESS, "--out", str(out)],
        ["tournament", str(write_spec(spec.parent, TOURNAMENT, "tournament.toml")), "--out", str(out)],
    ]


@pytest.mark.parametrize("value", ["0", "-1"])
def test_max_runs_below_1_is_refused_by_every_study_command(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    out = tmp_path / "out"
    for command in _study_commands(tiny_spec, out):
        assert main([*command, "--max-runs", value]) == 2, command[0]
        assert f"--max-runs must be a whole number >= 1; got {value}" in capsys.readouterr().err, command[0]
    assert not out.exists()


def test_robustness_refuses_a_study_larger_than_max_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    planned = len(plan_robustness("dlc", ["pure-pursuit"], "kinematic-bicycle"))
    out = tmp_path / "out"
    assert main([*ROBUSTNESS, "--out", str(out), "--max-runs", str(planned - 1)]) == 2
    err = capsys.readouterr().err
    assert f"the robustness study plans {planned} runs" in err and f"more than the limit of {planned - 1}" in err
    assert "--max-runs N" in err and not out.exists()

    backend = NotSimulating()  # the study at its limit runs (without simulating here)
    monkeypatch.setattr("workbench.apps.studies.make_backend", lambda *_: backend)
    assert main([*ROBUSTNESS, "--out", str(out), "--max-runs", str(planned)]) == 0
    assert [len(given) for given in backend.given] == [planned]


def test_workers_from_1_to_the_bound_are_taken_and_outside_refused(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bound = backends.max_workers()
    assert bound == backends.MAX_WORKERS_PER_CPU * backends.default_workers()
    for workers in (1, bound):
        assert LocalBackend(workers).workers == workers and DaskBackend(workers=workers).workers == workers
    for workers in (0, -1, bound + 1, 10**9):
        with pytest.raises(WorkbenchInputError, match=f"got {workers}$"):
            LocalBackend(workers)
    out = tmp_path / "out"
    for command in _study_commands(tiny_spec, out):
        assert main([*command, "--workers", str(bound + 1)]) == 2, command[0]
        err = capsys.readouterr().err
        assert f"workers must be at most {bound} ({backends.MAX_WORKERS_PER_CPU} per usable CPU" in err
        assert err.rstrip().endswith(f"got {bound + 1}")
    assert not out.exists()


@pytest.mark.parametrize(
    "address",
    [
        "not a url",
        "",
        "localhost:8786",
        "tcp://host",
        "tcp://host:",
        "tcp://host:0",
        "tcp://host:65536",
        "http://host:8786",
        "tcp://host:8786/path",
        "tcp://:8786",
        "tcp://[::1:8786",
    ],
)
def test_a_scheduler_address_not_tcp_host_port_is_refused(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], address: str
) -> None:
    for command in _study_commands(tiny_spec, tmp_path / "out"):
        assert main([*command, "--backend", "dask", "--scheduler", address]) == 2, command[0]
        err = capsys.readouterr().err
        assert err.startswith("workbench: error: scheduler must be a dask scheduler's address, tcp://HOST:PORT")
        assert err.rstrip().endswith(f"got {address!r}") and "Traceback" not in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", "tcp://[::1]:1", "tcp://scheduler.example.org:65535"])
def test_a_tcp_host_port_scheduler_address_is_taken(address: str) -> None:
    assert DaskBackend(address).describe() == f"dask scheduler {address}"


def test_a_scheduler_that_does_not_answer_is_refused_within_the_timeout(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(backends, "SCHEDULER_TIMEOUT_S", 1.0)
    command = ["sweep", str(tiny_spec), "--out", str(tmp_path / "out"), "--backend", "dask"]
    assert main([*command, "--scheduler", "tcp://127.0.0.1:1"]) == 2  # port 1: nothing listens
    err = capsys.readouterr().err
    assert "workbench: error: cannot reach the dask scheduler 'tcp://127.0.0.1:1' within 1 s" in err
    assert "Traceback" not in err
