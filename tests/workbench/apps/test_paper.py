"""`workbench paper`: every figure file is written, the table puts our numbers beside the paper's, and report.html
shows every figure under the paper's caption, self-contained; a progress line counts the steps."""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

import pandas as pd
import pytest

from workbench.apps.cli import main
from workbench.apps.paper import PAPER_FIGURES, PAPER_REPORTS, TRACKING_FIGURES, figure_number

TRACK = Path(__file__).resolve().parents[4] / "shared" / "tracks" / "Zandvoort_track.csv"
#: The steps the progress line counts: four figure groups, a run per scenario, then Figures 11-16 and the report.
STEPS = {False: 4 + 2 + 1, True: 4 + 3 + 1}


@pytest.mark.parametrize("with_track", [False, True])
def test_paper_writes_every_figure_and_the_table(with_track: bool, tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.delenv("WORKBENCH_ZANDVOORT_CSV", raising=False)
    monkeypatch.chdir(tmp_path)  # without --track: no file in ./tracks nor beside the checkout
    monkeypatch.setattr("workbench.simulation.scenarios.CHECKOUT_ROOT", None)
    if with_track and not TRACK.is_file():
        pytest.skip(f"TUMFTM Zandvoort_track.csv not found at {TRACK} (third-party data kept outside the repo)")
    monkeypatch.setattr("sys.stderr.isatty", lambda: True)  # a terminal: the CLI shows its progress line
    args = ["paper", "--out", str(tmp_path)] + (["--track", str(TRACK)] if with_track else [])
    assert main(args) == 0
    captured = capsys.readouterr()
    out = captured.out
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
    assert f"paper:   0%|          | 0/{STEPS[with_track]} " in captured.err
    for step in ("Figures 4b-5b", "Figures 8-10", "figure8 run", "dlc run", "Figures 11-16 and report.html"):
        assert step in captured.err
    assert ("zandvoort run" in captured.err) == with_track

    # report.html: every PNG written, embedded, under its figure's caption; nothing outside the file
    report = (tmp_path / "report.html").read_text(encoding="utf-8")
    pngs = sorted(tmp_path.glob("*.png"))
    sources = re.findall(r'src="([^"]*)"', report)
    assert len(sources) == len(pngs) and all(s.startswith("data:image/png;base64,") for s in sources)
    assert {base64.b64decode(s.split(",", 1)[1]) for s in sources} == {p.read_bytes() for p in pngs}
    assert all(h.startswith("#") for h in re.findall(r"href='([^']*)'", report))  # links within the page only
    for number in {figure_number(p) for p in pngs}:
        caption, said = PAPER_FIGURES[number]
        assert f"<h2 id='fig{number}'>Figure {number}</h2>" in report
        assert html.escape(caption) in report and html.escape(said) in report
    assert ("Figure 15</h2>" in report) == with_track and ("Skipped: Figures 15-16" in report) != with_track
    for quantity, (reported, _) in PAPER_REPORTS.items():  # under its figure (if drawn), our number beside it
        assert (html.escape(f"{quantity}: {reported}") in report) == (with_track or "zandvoort" not in quantity)


def test_paper_names_another_track_and_gives_it_no_verdict(tmp_path: Path, capsys, monkeypatch) -> None:
    """`paper --track good.csv` (a 60 m line): said before any work to be another track than the paper's, by its
    file; Figures 15-16 and the Zandvoort row are skipped for it, naming it."""
    from workbench.apps import paper
    from workbench.apps.paper import PaperResult, zandvoort_skip_reason

    good = tmp_path / "good.csv"
    good.write_text("x,y\n" + "".join(f"{x},0\n" for x in range(0, 61, 5)))
    seen = []

    def reproduce(out_dir: Path, options) -> PaperResult:  # the figures themselves: test_paper_writes_every_figure
        seen.append(zandvoort_skip_reason(options))
        return PaperResult([], pd.DataFrame({"quantity": []}), [seen[-1]])

    monkeypatch.setattr(paper, "reproduce_paper", reproduce)
    assert main(["paper", "--out", str(tmp_path / "out"), "--track", str(good)]) == 0
    captured = capsys.readouterr()
    expected = f"Figures 15-16 and the Zandvoort row: the track file {good} is not the TUMFTM Zandvoort track"
    assert seen[0].startswith(expected)
    assert captured.err.startswith(f"workbench: warning: skipping {expected}")
    assert f"skipped: {expected}" in captured.out
