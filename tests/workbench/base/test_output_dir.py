"""Output folders: checked before any work; a command's output written whole, with a manifest, so that
--overwrite removes exactly the earlier output and never a user's own files."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.base.output_dir import (
    MANIFEST,
    OutputDir,
    check_output_dir,
    check_output_file,
    check_study_dir,
    read_manifest,
)


def write_output(folder: Path, command: str, files: dict[str, str], overwrite: bool = False) -> OutputDir:
    out = OutputDir(folder, command, overwrite=overwrite)
    with out.writing():
        for name, text in files.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_text(text)
    return out


def test_a_new_or_empty_folder_is_written_with_a_manifest(tmp_path: Path) -> None:
    out = tmp_path / "a" / "b"
    write_output(out, "compare", {"summary.csv": "x", "runs/pp-car/trace.parquet": "t"})
    manifest = read_manifest(out)
    assert manifest is not None and manifest["command"] == "compare"
    assert manifest["files"] == ["runs/pp-car/trace.parquet", "summary.csv"]
    (tmp_path / "empty").mkdir()
    write_output(tmp_path / "empty", "run", {"metrics.json": "{}"})
    assert read_manifest(tmp_path / "empty")["files"] == ["metrics.json"]


def test_an_earlier_output_is_refused_without_overwrite_and_replaced_with_it(tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_output(out, "run", {"trace.parquet": "1", "metrics.json": "1", "trajectory.png": "1"})
    (out / "notes.txt").write_text("mine")
    with pytest.raises(WorkbenchInputError, match=r"holds the output of an earlier `workbench run` \(3 files, written"):
        OutputDir(out, "run")
    replaced = write_output(out, "run", {"trace.parquet": "2", "metrics.json": "2"}, overwrite=True)
    assert replaced.foreign == ["notes.txt"]
    # the earlier run's PNG is gone, the user's file is kept, the new files are the manifest's
    assert sorted(p.name for p in out.iterdir()) == sorted([MANIFEST, "metrics.json", "notes.txt", "trace.parquet"])
    assert (out / "trace.parquet").read_text() == "2" and (out / "notes.txt").read_text() == "mine"
    assert read_manifest(out)["files"] == ["metrics.json", "trace.parquet"]


def test_overwrite_removes_the_earlier_runs_folders_it_emptied(tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    write_output(out, "compare", {"runs/a-car/trace.parquet": "1", "runs/b-car/trace.parquet": "1", "s.csv": "1"})
    write_output(out, "compare", {"runs/a-car/trace.parquet": "2", "s.csv": "2"}, overwrite=True)
    assert not (out / "runs" / "b-car").exists()
    assert read_manifest(out)["files"] == ["runs/a-car/trace.parquet", "s.csv"]


def test_a_folder_of_other_files_is_refused_and_overwrite_keeps_them(tmp_path: Path) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("keep me")
    with pytest.raises(
        WorkbenchInputError, match=r"is not empty \(1 entry: thesis.tex\) and holds no workbench output"
    ):
        OutputDir(out, "paper")
    written = write_output(out, "paper", {"fig06.png": "x"}, overwrite=True)
    assert written.foreign == ["thesis.tex"] and (out / "thesis.tex").read_text() == "keep me"
    assert read_manifest(out)["files"] == ["fig06.png"]


def test_a_manifest_never_removes_anything_outside_the_folder(tmp_path: Path) -> None:
    out, outside = tmp_path / "out", tmp_path / "precious.txt"
    out.mkdir()
    outside.write_text("keep")
    (out / "a.png").write_text("x")
    files = ["../precious.txt", str(outside), "a.png", "", "./a.png"]
    (out / MANIFEST).write_text(json.dumps({"format": "workbench-output/1", "command": "run", "files": files}))
    write_output(out, "run", {"b.png": "y"}, overwrite=True)
    assert outside.read_text() == "keep"
    assert not (out / "a.png").exists() and read_manifest(out)["files"] == ["b.png"]


def test_a_failed_write_still_lists_what_it_wrote(tmp_path: Path) -> None:
    out = OutputDir(tmp_path / "out", "fig17")
    with pytest.raises(RuntimeError), out.writing():
        (tmp_path / "out" / "summary.csv").write_text("x")
        raise RuntimeError("disk full")
    assert read_manifest(tmp_path / "out")["files"] == ["summary.csv"]


@pytest.mark.parametrize("check", [check_output_dir, check_study_dir, lambda p: OutputDir(p, "run")])
def test_a_file_where_the_folder_should_be(tmp_path: Path, check) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(WorkbenchInputError, match=r"--out '.*file' is a file, not a folder"):
        check(tmp_path / "file")
    with pytest.raises(WorkbenchInputError, match=r"--out '.*file/sub/dir': '.*file' is a file, not a folder"):
        check(tmp_path / "file" / "sub" / "dir")
    assert not (tmp_path / "sub").exists()


def test_output_files(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    assert check_output_file(tmp_path / "new" / "lag.json") == tmp_path / "new" / "lag.json"
    assert check_output_file(tmp_path / "file") == tmp_path / "file"  # an existing file is replaced
    with pytest.raises(WorkbenchInputError, match=r"^--out '.*' is a folder, not a file"):
        check_output_file(tmp_path)
    with pytest.raises(WorkbenchInputError, match=r"^--plot '.*file/f.png': '.*file' is a file, not a folder"):
        check_output_file(tmp_path / "file" / "f.png", "--plot")


def test_unwritable_folders_are_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """As for a user without write permission (os.access says no; root may write anyway, so it is simulated)."""
    monkeypatch.setattr(os, "access", lambda *_args, **_kw: False)
    with pytest.raises(WorkbenchInputError, match=r"--out '.*': the folder is not writable \(permission denied\)"):
        check_output_dir(tmp_path)
    with pytest.raises(WorkbenchInputError, match=r"its parent '.*' is not writable \(permission denied\)"):
        check_output_dir(tmp_path / "new" / "deeper")
    with pytest.raises(WorkbenchInputError, match=r"the folder '.*' is not writable \(permission denied\)"):
        check_output_file(tmp_path / "x.csv")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root may write anywhere")
def test_a_read_only_folder_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        with pytest.raises(WorkbenchInputError, match="not writable"):
            check_output_dir(folder)
        with pytest.raises(WorkbenchInputError, match="not writable"):
            check_output_dir(folder / "sub")
        with pytest.raises(WorkbenchInputError, match="not writable"):
            check_output_file(folder / "lag.json")
    finally:
        folder.chmod(0o700)


def test_a_study_folder_resumes_but_takes_nothing_else(tmp_path: Path) -> None:
    study = tmp_path / "study"
    (study / "runs").mkdir(parents=True)
    (study / "spec.toml").write_text("")
    (study / "notes.md").write_text("my notes")
    assert check_study_dir(study) == study  # a study's folder, with a note beside it: resumable
    assert check_study_dir(tmp_path / "new") == tmp_path / "new"
    write_output(tmp_path / "run", "run", {"trace.parquet": "x"})
    with pytest.raises(WorkbenchInputError, match=r"holds the output of `workbench run`, not a study's"):
        check_study_dir(tmp_path / "run")
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "thesis.tex").write_text("x")
    with pytest.raises(WorkbenchInputError, match=r"not a study's folder \(no spec.toml or runs/\)"):
        check_study_dir(tmp_path / "home")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "spec.toml").write_text("")
    (tmp_path / "bad" / "runs").write_text("not a folder")
    with pytest.raises(WorkbenchInputError, match=r"runs' is not a folder"):
        check_study_dir(tmp_path / "bad")


def test_a_result_saved_again_replaces_its_own_files(tmp_path: Path) -> None:
    """SimulationResult.save removes the files a run writes before writing them: a run saved without plots where
    one with plots was leaves no PNG of the earlier run beside the new trace."""
    from controllers import make_controller
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import Simulation, SimulationConfig
    from workbench.vehicles import make_vehicle

    vehicle = make_vehicle("kinematic-bicycle")
    controller = make_controller("pure-pursuit", vehicle.geometry)
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    result = Simulation(scenario, vehicle, controller, SimulationConfig()).run()
    (tmp_path / "notes.txt").write_text("mine")
    assert len(result.save(tmp_path)) == 6
    assert sorted(p.name for p in result.save(tmp_path, with_plots=False)) == ["metrics.json", "trace.parquet"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["metrics.json", "notes.txt", "trace.parquet"]
