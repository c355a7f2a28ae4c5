"""The docs' generated benchmark tables: every committed result renders with its machine, date and every row, and the
publish helper writes what the renderer reads."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path
from types import ModuleType, SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
PUBLISHED = ROOT / "docs" / "benchmark-results"
#: The benchmarks the Benchmarks page includes: each must have a committed result.
PAGE_BENCHMARKS = ("steering", "cte_breakdown", "fmu_plant", "run", "startup")


def _load(path: Path, name: str) -> ModuleType:
    """The module at path (a script or a Sphinx extension, not a package), loaded under name."""
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def figures() -> ModuleType:
    return _load(ROOT / "docs" / "_ext" / "workbench_figures.py", "docs_workbench_figures")


@pytest.fixture(scope="module")
def publish() -> ModuleType:
    if str(ROOT / "benchmarks") not in sys.path:  # the script imports benchmark_report as when run
        sys.path.insert(0, str(ROOT / "benchmarks"))
    return _load(ROOT / "benchmarks" / "publish.py", "benchmark_publish")


def _table_lines(text: str) -> list[list[str]]:
    """The cells of each table row in a rendered snippet."""
    rows = [line for line in text.splitlines() if line.startswith("| ")]
    return [[c.strip() for c in line.strip().strip("|").split(" | ")] for line in rows]


def _assert_rows_rendered(figures: ModuleType, rows: list[dict[str, object]], text: str) -> None:
    lines = _table_lines(text)
    for row in rows:
        cells = [figures.format_cell(v) for v in row.values() if v is not None]
        assert any(all(c in line for c in cells) for line in lines), f"row {row} not in the table"


@pytest.mark.parametrize("name", PAGE_BENCHMARKS)
def test_committed_result_renders_with_machine_date_and_every_row(figures: ModuleType, name: str) -> None:
    document = json.loads((PUBLISHED / f"{name}.json").read_text())
    text = figures.render_benchmark(document)
    assert document["summary"], f"{name}: an empty summary"
    assert document["measured_utc"] in text
    assert str(document["machine"]["platform"]) in text
    assert f"Python {document['machine']['python']}" in text
    assert f"{document['machine']['cpus']} CPUs" in text
    _assert_rows_rendered(figures, document["summary"], text)
    for table in document["tables"]:
        assert f"**{table['title']}**" in text
        _assert_rows_rendered(figures, table["rows"], text)


def test_every_page_include_has_its_snippet(figures: ModuleType, tmp_path: Path) -> None:
    written = {p.name for p in figures.write_benchmark_tables(PUBLISHED, tmp_path)}
    page = (ROOT / "docs" / "benchmarks.md").read_text()
    included = {line.split("_generated/benchmarks/")[1].strip() for line in page.splitlines() if "{include}" in line}
    assert included == {f"{figures.SNIPPET_NAMES.get(n, n)}.md" for n in PAGE_BENCHMARKS}
    assert included <= written


def test_cells_format_numbers_booleans_and_pipes(figures: ModuleType) -> None:
    assert figures.format_cell(2.4432801391377925) == "2.443"
    assert figures.format_cell(True) == "yes"
    assert figures.format_cell(None) == ""
    assert figures.format_cell("a | b") == "a \\| b"
    table = figures.markdown_table([{"a": 1, "b": None}, {"a": 2.5, "c": "x"}])
    assert table.splitlines()[0] == "| a | c |"  # b is empty in every row: left out
    # a long column name may wrap after each underscore (a zero-width space), not inside its words
    assert figures.markdown_table([{"max_abs_cte_m": 1}]).splitlines()[0] == "| max_\u200babs_\u200bcte_\u200bm |"
    assert table.splitlines()[3] == "| 2.5 | x |"


def test_publish_keeps_the_recorded_machine_and_dates_the_result(publish: ModuleType) -> None:
    machine = {"python": "3.11.0", "platform": "Linux-test", "cpus": 8, "load_average": [1.0, 1.0, 1.0]}
    result = {"machine": machine, "created_unix_s": 0.0, "entries": [{"name": "step", "median_us": math.nan}]}
    document = publish.published_document("fmu_plant", result)
    assert document["machine"] == machine
    assert "machine_note" not in document
    assert document["measured_utc"] == "1970-01-01 00:00 UTC"
    assert document["summary"][0]["name"] == "step"
    assert document["summary"][0]["median_us"] is None  # strict JSON: no NaN
    json.dumps(document, allow_nan=False)


def test_publish_refuses_a_result_without_its_machine(publish: ModuleType) -> None:
    """The machine a result is published on is not the one it was measured on: publish does not fill it in."""
    result = {"created_unix_s": 86400.0, "cpu_count": 3, "load_average": 2.5, "summary": [{"vehicle": "v"}]}
    with pytest.raises(SystemExit, match="steering: the result does not record the machine it ran on"):
        publish.published_document("steering", result)


def test_publish_writes_what_the_docs_render_and_refuses_an_unknown_name(
    publish: ModuleType, figures: ModuleType, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    results, out = tmp_path / "results", tmp_path / "out"
    results.mkdir()
    machine = {"python": "3.11.0", "platform": "Linux-test", "cpus": 2, "load_average": None}
    entries = [{"name": "python -c pass", "median_s": 0.02, "goal": None, "goal_met": None, "times_s": [0.02]}]
    (results / "startup.json").write_text(json.dumps({"machine": machine, "created_unix_s": 0.0, "entries": entries}))
    assert publish.main(["startup", "--results", str(results), "--out", str(out)]) == 0
    assert publish.main(["run", "--results", str(results), "--out", str(out)]) == 1  # no result to publish
    assert "no result at" in capsys.readouterr().err
    text = figures.render_benchmark(json.loads((out / "startup.json").read_text()))
    assert "| python -c pass | 0.02 |" in text
    assert "times_s" not in text
    with pytest.raises(SystemExit) as refused:
        publish.main(["stearing"])
    assert refused.value.code == 2
    assert "unknown benchmark stearing" in capsys.readouterr().err


def test_cached_figure_remade_only_when_the_code_changes(figures: ModuleType, tmp_path: Path) -> None:
    made: list[Path] = []

    def make(out: Path) -> None:
        made.append(out)
        out.write_bytes(b"png")

    out = tmp_path / "figure.png"
    assert figures.cached_figure(out, make, "v1")
    assert not figures.cached_figure(out, make, "v1")
    assert figures.cached_figure(out, make, "v2")
    assert len(made) == 2


def test_source_hash_follows_the_sources(figures: ModuleType, tmp_path: Path) -> None:
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "a.py").write_text("x = 1\n")
    before = figures.source_hash(("pkg",), tmp_path)
    (tmp_path / "pkg" / "notes.txt").write_text("not code")
    assert figures.source_hash(("pkg",), tmp_path) == before
    (tmp_path / "pkg" / "a.py").write_text("x = 2\n")
    assert figures.source_hash(("pkg",), tmp_path) != before


def test_snippets_are_excluded_from_the_pages_once(figures: ModuleType) -> None:
    config = SimpleNamespace(exclude_patterns=["_build"])
    figures.exclude_snippets(None, config)
    figures.exclude_snippets(None, config)
    assert config.exclude_patterns == ["_build", figures.SNIPPETS_PATTERN]


def test_loop_margins_figure_is_drawn(figures: ModuleType, tmp_path: Path) -> None:
    out = tmp_path / "loop_margins_truck.png"
    figures.loop_margins_figure(out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_mpc_dlc_figure_is_drawn(figures: ModuleType, tmp_path: Path) -> None:
    out = tmp_path / "mpc_dlc_truck.png"
    figures.mpc_dlc_figure(out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
