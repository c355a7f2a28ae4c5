"""`workbench sweep` and `workbench optimise` on bad input: exit code 2 and a message naming the value."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import write_spec

from workbench.cli import main


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--workers", "0"], "workers must be a whole number >= 1; got 0"),
        (["--scheduler", "tcp://localhost:8786"], "needs the dask backend (--backend dask)"),
        (["--backend", "dask", "--scheduler", "tcp://x:1", "--workers", "2"], "applies to a LocalCluster"),
    ],
)
def test_bad_backend_options(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    assert main(["sweep", str(tiny_spec), "--out", str(tmp_path / "out"), *extra]) == 2
    assert message in capsys.readouterr().err


def test_bad_specs(tmp_path: Path, tiny_spec: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sweep", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "out")]) == 2
    assert "missing.toml' does not exist" in capsys.readouterr().err
    assert main(["optimise", str(tiny_spec), "--out", str(tmp_path / "out")]) == 2
    assert "needs an [optimise] table" in capsys.readouterr().err
    bad = write_spec(tmp_path, tiny_spec.read_text().replace("speed_kmh = [20, 30]", "speed_kmh = [20, nan]"))
    assert main(["sweep", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "grid.speed_kmh[1] must be a finite number; got nan" in capsys.readouterr().err
