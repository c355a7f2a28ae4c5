"""Every case of the bad-input catalogue (tests/bad_input_catalogue.py) over both command lines: a bad input is
refused cleanly (exit code 2, an `error:` line naming it, no traceback), a meaningful one accepted. Each case runs
in-process in a folder holding the catalogue's files; the work an accepted input reaches (a simulation, a study's
backend, a tuning command's slow part) is stopped at its door, so that no case runs for long, and so that a
refusal that comes only once the work has started counts as a failure: bad input is refused before any work."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest
from bad_input_catalogue import ACCEPTED, REFUSED, Case, cases, files

CASES = cases()
#: Where the slow work of a tuning command starts, after its inputs are checked (the commands look these up in
#: their modules when they run): identifying a schedule's lags, a margins study, a rollover series; and where
#: `workbench export-fmu` starts packing and building the FMU.
THE_WORK = (
    ("tuning.schedule", "identification_logs"),
    ("tuning.margins", "run_margins"),
    ("tuning.rollover", "rollover_limits"),
    ("workbench.apps.fmu_export", "build_controller_fmu"),
)


class ReachedTheWork(BaseException):
    """Raised where an accepted input's work begins (a BaseException: no handler of the CLIs catches it)."""


def _stop(*args, **kwargs):
    raise ReachedTheWork


@pytest.fixture(scope="module")
def catalogue_files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("catalogue")
    for name, content in files().items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if content is None:
            path.mkdir(exist_ok=True)
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")
    return root


def _run(case: Case, folder: Path, monkeypatch: pytest.MonkeyPatch) -> int | None:
    """The case's exit code, or None when it reached the work."""
    import tuning.cli
    import workbench.apps.cli
    from workbench.apps.studies.backends import DaskBackend, LocalBackend
    from workbench.simulation.simulator import Simulation

    monkeypatch.chdir(folder)
    monkeypatch.setattr(Simulation, "run", _stop)
    for backend in (LocalBackend, DaskBackend):  # made (its options checked), never started
        monkeypatch.setattr(backend, "start", _stop)
        monkeypatch.setattr(backend, "map_runs", _stop)
    for module, function in THE_WORK:
        monkeypatch.setattr(importlib.import_module(module), function, _stop)
    main = workbench.apps.cli.main if case.program == "workbench" else tuning.cli.main
    try:
        return main(list(case.argv))
    except ReachedTheWork:
        return None
    except SystemExit as exc:  # argparse's refusals
        return exc.code


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_the_case(case: Case, catalogue_files: Path, tmp_path: Path, monkeypatch, capsys) -> None:
    import shutil

    folder = tmp_path / "case"
    shutil.copytree(catalogue_files, folder, symlinks=True)
    code = _run(case, folder, monkeypatch)
    out, err = capsys.readouterr()
    assert "Traceback" not in err + out, f"{case.id}: a traceback\n{err[-2000:]}"
    if case.expect == REFUSED:
        shown = f"stdout: {out[-600:]}\nstderr: {err[-600:]}"
        assert code == 2, f"{case.id}: exit code {code!r}, expected a refusal (2)\n{shown}"
        errors = [line for line in err.splitlines() if " error: " in line or line.startswith(f"{case.program}: error")]
        assert len(errors) == 1, f"{case.id}: expected one error line, got {errors}\n{err[-1000:]}"
    else:
        assert case.expect == ACCEPTED
        assert code in (None, 0), f"{case.id}: exit code {code!r}, expected acceptance\n{err[-1000:]}"


def test_the_catalogue_is_large_and_covers_every_command() -> None:
    from tuning.cli import _parser as tuning_parser
    from workbench.apps.cli import _parser as workbench_parser

    assert len(CASES) >= 500
    commands = {(c.program, c.argv[0]) for c in CASES if c.argv}
    for program, parser in (("workbench", workbench_parser(None)), ("tuning", tuning_parser(None))):
        sub = next(a for a in parser._actions if a.dest == "command")
        assert {(program, name) for name in sub.choices} <= commands
