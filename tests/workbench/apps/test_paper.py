"""`workbench paper`: every figure file is written, and the table puts our numbers beside the paper's."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from workbench.apps.cli import main
from workbench.apps.paper import PAPER_REPORTS, TRACKING_FIGURES

TRACK = Path(__file__).resolve().parents[4] / "shared" / "tracks" / "Zandvoort_track.csv"


@pytest.mark.parametrize("with_track", [False, True])
def test_paper_writes_every_figure_and_the_table(with_track: bool, tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.delenv("WORKBENCH_ZANDVOORT_CSV", raising=False)
    if with_track and not TRACK.is_file():
        pytest.skip(f"TUMFTM Zandvoort_track.csv not found at {TRACK} (third-party data kept outside the repo)")
    args = ["paper", "--out", str(tmp_path)] + (["--track", str(TRACK)] if with_track else [])
    assert main(args) == 0
    out = capsys.readouterr().out
    expected = ["fig04b", "fig05b", "fig06", "fig07", "fig08", "fig09", "fig10"]
    expected += [f"fig{n}{suffix}_{scenario}" for n, scenario, _, suffix in TRACKING_FIGURES]
    written = {p.stem for p in tmp_path.glob("*.png")}
    for stem in expected:
        present = any(w.startswith(stem) for w in written)
        assert present == (with_track or "zandvoort" not in stem), stem
    assert all(p.stat().st_size > 10_000 for p in tmp_path.glob("*.png"))
    table = pd.read_csv(tmp_path / "paper_vs_ours.csv").set_index("quantity")
    assert list(table.index) == list(PAPER_REPORTS)
    # the paper's own bounds on the loaded truck at 30 km/h (section 6)
    assert table.loc["figure8 max |CTE|", "ours"] < 0.4
    assert table.loc["dlc max |CTE|", "ours"] < 0.2
    assert 200 < table.loc["figure8 steering-wheel peak", "ours"] < 600
    assert 12 < table.loc["figure8 speed at the largest curvature rate", "ours"] < 22  # mph; the paper: about 17
    assert pd.isna(table.loc["zandvoort max |CTE|", "ours"]) != with_track
    assert ("skipped: Figures 15-16" in out) != with_track
