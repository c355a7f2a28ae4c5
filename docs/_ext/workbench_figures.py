"""Sphinx extension: the documentation's tables and figures, made from the code and its committed results when the
build starts (`builder-inited`), into docs/_generated/ (git-ignored).

- _generated/benchmarks/<name>.md (steering_summary.md for steering): each benchmark's published result
  (docs/benchmark-results/<name>.json, written by benchmarks/publish.py) as MyST Markdown tables, stating the
  machine and date it was measured on. The Benchmarks page includes them.
- _generated/loop_margins_truck.png: the clothoid controller's open loop L(z) on the loaded truck at 30 km/h with
  its shipped tuning, at the lookahead floor: Bode plot with the gain and phase margins
  (controllers/clothoid/loop_analysis.py).
- _generated/fig17_cte.png: CTE against distance on the fig17 scenario, the clothoid controller and the NMPC on the
  truck (`workbench.apps.comparison.compare`).

Both figures are kept between builds while the code that makes them is unchanged (a hash of its sources, in
<figure>.key beside each).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

DOCS = Path(__file__).resolve().parent.parent
REPO = DOCS.parent
RESULTS = DOCS / "benchmark-results"
GENERATED = DOCS / "_generated"

#: Snippet file name of each benchmark whose name alone would not say what it holds.
SNIPPET_NAMES = {"steering": "steering_summary"}
#: Speed (km/h) of the loop figure, the speed the tuning and benchmarks analyse the loop at.
LOOP_SPEED_KMH = 30.0
#: Vehicle of both figures: the loaded truck preset.
TRUCK = "tractor-semitrailer"
#: Source folders (from the repository's root) of the code that makes the figures, this extension included: a
#: change in any of their Python or TOML files makes the figures again.
FIGURE_SOURCES = ("controllers", "tuning", "workbench", "docs/_ext")
#: Significant digits of the numbers in the benchmark tables.
SIGNIFICANT_DIGITS = 4


def format_cell(value: object) -> str:
    """One table cell: numbers to SIGNIFICANT_DIGITS, booleans as yes/no, None as empty, text with its pipes
    escaped (MyST table syntax)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.{SIGNIFICANT_DIGITS}g}" if math.isfinite(value) else str(value)
    if isinstance(value, list | tuple):
        return ", ".join(format_cell(v) for v in value)
    return str(value).replace("|", "\\|").replace("\n", " ")


def markdown_table(rows: Sequence[Mapping[str, object]]) -> str:
    """rows as a Markdown table: a column per key (in order of first appearance, each underscore of its name
    followed by a zero-width space, where it may wrap), columns empty in every row left out."""
    columns: list[str] = []
    for row in rows:
        columns += [key for key in row if key not in columns]
    columns = [c for c in columns if any(row.get(c) is not None for row in rows)]
    if not rows or not columns:
        return "(no rows)\n"
    # A column name is a result's key (median_max_cte_vs_nominal): a zero-width space after each underscore lets a
    # long one wrap at its words, so that a table of numbers fits the page's column.
    lines = ["| " + " | ".join(c.replace("_", "_\u200b") for c in columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(format_cell(row.get(c)) for c in columns) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def measured_on(document: Mapping[str, Any]) -> str:
    """The sentence saying when and on what machine a published result was measured."""
    m = document["machine"]
    load = m.get("load_average")
    load_text = f", load average {format_cell(load)}" if load is not None else ""
    text = (
        f"Measured on {document['measured_utc']} with `{document['command']}` on {m.get('platform')}, "
        f"Python {m.get('python')}, {m.get('cpus')} CPUs{load_text}."
    )
    return text


def render_benchmark(document: Mapping[str, Any]) -> str:
    """A published benchmark result (benchmarks/publish.py) as MyST Markdown: when and where it was measured, its
    summary table, then each further table under a bold title."""
    parts = [measured_on(document), "", markdown_table(document["summary"])]
    for table in document.get("tables", []):
        parts += [f"**{table['title']}**", "", markdown_table(table["rows"])]
    return "\n".join(parts)


def write_if_changed(path: Path, text: str) -> None:
    """Write text to path unless it already holds it (an unchanged file keeps Sphinx from rereading its page)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.is_file() or path.read_text() != text:
        path.write_text(text)


def write_benchmark_tables(results: Path = RESULTS, out: Path = GENERATED / "benchmarks") -> list[Path]:
    """Render every docs/benchmark-results/<name>.json into out/<snippet name>.md; the paths written."""
    written = []
    for source in sorted(results.glob("*.json")):
        document = json.loads(source.read_text())
        target = out / f"{SNIPPET_NAMES.get(source.stem, source.stem)}.md"
        write_if_changed(target, render_benchmark(document))
        written.append(target)
    return written


def loop_margins_figure(out: Path) -> None:
    """The Bode plot of the clothoid loop on the loaded truck at LOOP_SPEED_KMH, at its lookahead floor, with the
    gain and phase margins marked; saved to out."""
    import numpy as np
    from matplotlib.figure import Figure

    from controllers.clothoid import loop_analysis as la
    from tuning.own_tuning import tuned_controller
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.vehicles import make_vehicle

    vehicle = make_vehicle(TRUCK)
    controller = tuned_controller("clothoid", vehicle)
    sample_time_s = 0.02
    controller.reset(make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m, None)).path, sample_time_s)
    speed_mps = LOOP_SPEED_KMH / 3.6
    lags = controller.plant_lags(LOOP_SPEED_KMH)
    settings = controller.loop_settings(LOOP_SPEED_KMH)
    floor_m = controller.lookahead_floor_m(speed_mps)
    loop = la.loop_transfer(lags, settings, speed_mps, floor_m)
    margins = la.loop_margins(lags, settings, speed_mps, floor_m)
    omega = np.logspace(-2, math.log10(math.pi / settings.sample_time_s) - 0.01, 2000)
    response = np.squeeze(loop(np.exp(1j * omega * settings.sample_time_s)))
    hz = omega / (2 * math.pi)
    phase_deg = np.degrees(np.unwrap(np.angle(response)))
    at_crossover_deg = float(phase_deg[np.argmin(np.abs(omega - margins.crossover_rad_s))])
    phase_deg -= 360.0 * math.floor((at_crossover_deg + 180.0) / 360.0)  # the crossover's phase in [-180, 180)

    fig = Figure(figsize=(8, 6), layout="constrained")
    ax_mag, ax_phase = fig.subplots(2, 1, sharex=True)
    ax_mag.semilogx(hz, 20 * np.log10(np.abs(response)), color="tab:blue")
    ax_mag.axhline(0.0, color="k", lw=0.6)
    ax_phase.semilogx(hz, phase_deg, color="tab:blue")
    ax_phase.axhline(-180.0, color="k", lw=0.6)
    crossover_hz = margins.crossover_rad_s / (2 * math.pi)
    # Where the phase crosses -180 deg with |L| > 1: the gain-reduction margin's frequencies.
    above_minus_180 = phase_deg > -180.0
    crossings = np.nonzero(above_minus_180[1:] != above_minus_180[:-1])[0]
    reduction_crossings = [i for i in crossings if abs(response[i]) > 1.0][-1:]
    phase_crossover_hz = margins.phase_crossover_rad_s / (2 * math.pi)
    for ax in (ax_mag, ax_phase):
        ax.axvline(crossover_hz, color="tab:green", ls="--", lw=0.8, label=f"gain crossover {crossover_hz:.2f} Hz")
        if math.isfinite(phase_crossover_hz):
            label = f"phase crossover {phase_crossover_hz:.2f} Hz"
            ax.axvline(phase_crossover_hz, color="tab:red", ls=":", lw=0.8, label=label)
        for i in reduction_crossings:
            ax.axvline(hz[i], color="tab:orange", ls=":", lw=0.8, label=f"phase crossover {hz[i]:.2f} Hz (|L| > 1)")
        ax.grid(True, which="both", alpha=0.3)
    ax_mag.legend(loc="lower left", fontsize=8)
    ax_mag.set(
        ylabel="|L| (dB)",
        title=(
            f"Clothoid loop L(z), {TRUCK} at {LOOP_SPEED_KMH:g} km/h, lookahead floor {floor_m:.2f} m\n"
            f"phase margin {margins.phase_margin_deg:.1f} deg, gain margin +{margins.gain_margin_db:.1f} dB, "
            f"gain-reduction margin {margins.gain_reduction_margin_db:.1f} dB"
        ),
    )
    ax_mag.title.set_fontsize(10)
    ax_phase.set(xlabel="frequency (Hz)", ylabel="phase of L (deg)")
    fig.savefig(out, dpi=110)


def source_hash(folders: Sequence[str] = FIGURE_SOURCES, root: Path = REPO) -> str:
    """SHA-256 over the paths and contents of the Python and TOML files under these folders: the code version a
    cached figure was made with."""
    digest = hashlib.sha256()
    for folder in folders:
        for path in sorted((root / folder).rglob("*")):
            if path.suffix in (".py", ".toml") and "__pycache__" not in path.parts and path.is_file():
                digest.update(str(path.relative_to(root)).encode())
                digest.update(path.read_bytes())
    return digest.hexdigest()


def fig17_cte_figure(out: Path) -> None:
    """CTE against distance on the fig17 scenario, the clothoid controller and the NMPC on the truck; saved to
    out."""
    from matplotlib.figure import Figure

    from workbench.apps.comparison import RunSpec, compare
    from workbench.apps.fig17 import SCENARIO, SPEED_KMH
    from workbench.simulation.simulator import SimulationConfig

    comparison = compare(
        SCENARIO,
        (RunSpec("clothoid", TRUCK), RunSpec("nmpc", TRUCK)),
        SimulationConfig(speed_kmh=SPEED_KMH),
        progress=False,
    )
    fig = Figure(figsize=(9, 4.5), layout="constrained")
    ax = fig.subplots()
    comparison.plot_cte(ax, zoom=False)
    ax.set_title(f"fig17 at {SPEED_KMH:g} km/h: CTE of the clothoid controller and the NMPC on the loaded truck")
    fig.savefig(out, dpi=110)


def mpc_dlc_figure(out: Path) -> None:
    """The NMPC, the linear MPC and the clothoid controller on the loaded truck's dlc at 30 km/h: CTE against
    distance and the steering each took, its step median in the legend; saved to out."""
    from matplotlib.figure import Figure

    from workbench.apps.comparison import RunSpec, compare
    from workbench.simulation.simulator import SimulationConfig

    comparison = compare(
        "dlc",
        (RunSpec("nmpc", TRUCK), RunSpec("lmpc", TRUCK), RunSpec("clothoid", TRUCK)),
        SimulationConfig(speed_kmh=LOOP_SPEED_KMH),
        progress=False,
    )
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    cte_ax, steer_ax = fig.subplots(2, 1)
    comparison.plot_cte(cte_ax, zoom=False)
    comparison.plot_steering(steer_ax)
    steps = dict(zip(comparison.labels, comparison.summary()["step_time_median_us"], strict=True))
    for ax in (cte_ax, steer_ax):
        for line in ax.get_lines():
            label = line.get_label()
            if label in steps:
                line.set_label(f"{label} (step median {float(steps[label]):.0f} us)")
        ax.legend(fontsize=8)
    cte_ax.set_title(f"dlc at {LOOP_SPEED_KMH:g} km/h on the loaded truck: the MPCs and the clothoid controller")
    fig.savefig(out, dpi=110)


def cached_figure(out: Path, make: Any, key: str) -> bool:
    """Make the figure at out with make(out) unless out exists with this key beside it (out.key); whether it
    was made."""
    key_file = out.with_suffix(".key")
    if out.is_file() and key_file.is_file() and key_file.read_text().strip() == key:
        return False
    out.parent.mkdir(parents=True, exist_ok=True)
    make(out)
    key_file.write_text(key + "\n")
    return True


def generate(app: Any = None) -> None:
    """Write every table and figure into docs/_generated/ (the `builder-inited` handler)."""
    import sys

    if str(REPO) not in sys.path:
        sys.path.insert(0, str(REPO))
    write_benchmark_tables()
    key = source_hash()
    cached_figure(GENERATED / "loop_margins_truck.png", loop_margins_figure, key)
    cached_figure(GENERATED / "fig17_cte.png", fig17_cte_figure, key)
    cached_figure(GENERATED / "mpc_dlc_truck.png", mpc_dlc_figure, key)


#: The generated table snippets: read by the pages' include directives, not pages of their own.
SNIPPETS_PATTERN = "_generated/benchmarks/**"


def exclude_snippets(app: Any, config: Any) -> None:
    """Keep the table snippets out of the pages Sphinx reads on its own (the `config-inited` handler)."""
    if SNIPPETS_PATTERN not in config.exclude_patterns:
        config.exclude_patterns.append(SNIPPETS_PATTERN)


def setup(app: Any) -> dict[str, object]:
    """Register the generator on `builder-inited` and the snippets' exclusion on `config-inited`."""
    app.connect("config-inited", exclude_snippets)
    app.connect("builder-inited", generate)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
