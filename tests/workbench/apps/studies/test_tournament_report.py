"""The tournament's report (`tournament_report.py`): one self-contained page with every section, every figure an
embedded PNG that decodes, nothing fetched from elsewhere; its figures drawn on given axes."""

from __future__ import annotations

import base64
import io
from html.parser import HTMLParser
from pathlib import Path

import matplotlib
import pytest
from judging_frames import FAILURE_SCORE, OBJECTIVES, RANKING, Run, history_frame, results_frame, summary

from workbench.apps.studies.tournament_judging import judge
from workbench.apps.studies.tournament_report import SECTIONS, front_metrics, training_front, write_report
from workbench.apps.studies.tournament_spec import DEFAULT_OBJECTIVES
from workbench.base.errors import WorkbenchInputError

matplotlib.use("Agg")

CONTROLLERS = ("pure-pursuit", "stanley", "clothoid")
TRAIN = (("dlc", 1), ("figure8", 1))
TEST = tuple((f"circuit:{k}", seed) for k in range(3) for seed in (11, 12))
#: pure pursuit's trials: trial -> (max |CTE|, RMS steering rate) on every training case; 2 is chosen, 1 and 3
#: are carried; 4 failed.
TRIALS = {0: (0.30, 8.0), 1: (0.35, 5.0), 2: (0.20, 9.0), 3: (0.15, 14.0), 4: (0.50, 20.0)}
#: Each controller's max |CTE| on test case k beyond pure pursuit's: Stanley as good on average (better on some
#: cases, worse on others: not distinguishable), the clothoid controller 0.06 m worse on every case.
OFFSET = {"pure-pursuit": lambda k: 0.0, "stanley": lambda k: 0.03 * (-1) ** k, "clothoid": lambda k: 0.06}


def _runs() -> list[Run]:
    runs = []
    for c, controller in enumerate(CONTROLLERS):
        for trial, (cte, rate) in TRIALS.items():
            for scenario, seed in TRAIN:
                runs.append(
                    Run(
                        controller,
                        "train",
                        "trial",
                        trial,
                        scenario,
                        seed,
                        cte + 0.02 * c,
                        rate,
                        failed=trial == 4,
                        cpu_time_s=1.0 + c,
                    )
                )
        judged = [("default", 0), ("tuned", 2)] + ([("front-1", 3), ("front-2", 1)] if c == 0 else [])
        for config, trial in judged:
            cte, rate = TRIALS[trial]
            for k, (scenario, seed) in enumerate(TEST):
                failed = controller == "clothoid" and config == "default" and k == 0
                value = cte + 0.05 * k + OFFSET[controller](k)
                runs.append(
                    Run(
                        controller,
                        "test",
                        config,
                        trial,
                        scenario,
                        seed,
                        value,
                        rate,
                        failed=failed,
                        step_time_median_us=40.0 + 30 * c,
                    )
                )
    return runs


def _traces() -> dict:
    """Pure pursuit and Stanley on the car's dlc at 30 km/h: real runs, a second or two each."""
    from controllers import make_controller
    from workbench.simulation.run_config import SimulationConfig
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import Simulation
    from workbench.vehicles.presets import load_vehicle

    vehicle = load_vehicle("kinematic-bicycle")
    scenario = make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m))
    return {
        name: Simulation(
            scenario,
            vehicle,
            make_controller(name, vehicle.geometry, None, vehicle=vehicle),
            SimulationConfig(speed_kmh=30.0),
        ).run()
        for name in CONTROLLERS[:2]
    }


class _Page(HTMLParser):
    """What the tests read of a page: heading ids, image sources, every URL-bearing attribute, tags seen."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: list[str] = []
        self.images: list[str] = []
        self.urls: list[tuple[str, str, str]] = []
        self.tags: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.add(tag)
        values = dict(attrs)
        if tag == "h2" and values.get("id"):
            self.ids.append(str(values["id"]))
        if tag == "img":
            self.images.append(str(values.get("src")))
        self.urls += [(tag, key, str(value)) for key, value in attrs if key in ("src", "href", "action", "data")]


@pytest.fixture(scope="module")
def tournament() -> tuple:
    results = results_frame(_runs())
    history = history_frame(results, chosen=dict.fromkeys(CONTROLLERS, 2), carried={"pure-pursuit": {3: 1, 1: 2}})
    judgement = judge(results, RANKING, 3, 500, failure_score=FAILURE_SCORE, objectives=OBJECTIVES)
    return results, history, judgement


@pytest.fixture(scope="module")
def page(tournament, tmp_path_factory) -> tuple[str, Path]:
    results, history, judgement = tournament
    out = tmp_path_factory.mktemp("tournament")
    path = write_report(out, summary(results), results, history, judgement, _traces())
    return path.read_text(encoding="utf-8"), path


def _parsed(text: str) -> _Page:
    parser = _Page()
    parser.feed(text)
    parser.close()
    return parser


def test_the_report_is_written_as_report_html_with_every_section_in_order(page) -> None:
    text, path = page
    assert path.name == "report.html" and path.parent.is_dir()
    assert _parsed(text).ids == [key for key, _ in SECTIONS]


def test_every_figure_is_an_embedded_png_that_decodes(page) -> None:
    images = _parsed(page[0]).images
    assert len(images) == len(CONTROLLERS) + 3  # a front per controller, default/tuned, train/test, the traces
    for source in images:
        prefix = "data:image/png;base64,"
        assert source.startswith(prefix)
        pixels = matplotlib.image.imread(io.BytesIO(base64.b64decode(source.removeprefix(prefix))), format="png")
        assert pixels.shape[0] > 300 and pixels.shape[1] > 500  # drawn at FIGURE_DPI, not an empty image
        assert pixels[..., :3].std() > 0.01  # not one colour


def test_nothing_is_fetched_from_elsewhere(page) -> None:
    text = page[0]
    parsed = _parsed(text)
    assert not parsed.tags & {"script", "link", "iframe", "object", "embed"}
    for tag, key, value in parsed.urls:
        assert value.startswith("data:image/png;base64,") if key == "src" else value.startswith("#"), (tag, value)
    assert "http" not in text.replace("http-equiv", "") and "url(" not in text and "@import" not in text


def test_the_leaderboard_names_the_ranking_and_who_cannot_be_told_apart(page, tournament) -> None:
    text = page[0]
    board = tournament[2].leaderboard
    leaderboard = text[text.index('id="leaderboard"') : text.index('id="fronts"')]
    positions = [leaderboard.index(f"<td>{name}</td>") for name in board["controller"]]
    assert positions == sorted(positions)
    assert list(board["not_distinguishable_from"]) == ["stanley", "pure-pursuit", ""]
    for row in board.itertuples():
        assert f"<td>{row.not_distinguishable_from or '–'}</td>" in leaderboard
    assert "max_abs_cte_m + 0.002 x rms_steer_rate_deg_s" in leaderboard
    rules = text[text.index('id="rules"') : text.index('id="reading"')]
    stated = (
        "Selection:",
        "Ranking:",
        f"scores {FAILURE_SCORE:g}",
        "Known delays: the controllers are told",
        "Budget: every controller gets 5 trials",
        "MPC solve budget: max_solve_time_s = 10 s",
    )
    for words in stated:
        assert words in rules


def test_the_per_scenario_table_and_the_traces_name_what_they_show(page) -> None:
    text = page[0]
    scenarios = text[text.index('id="per-scenario"') : text.index('id="traces"')]
    for k in range(3):
        assert f"<td>circuit:{k}</td>" in scenarios
    traces = text[text.index('id="traces"') : text.index('id="rules"')]
    assert "test scenario dlc (kinematic-bicycle, 30 km/h" in traces


def test_the_training_front_marks_the_default_the_chosen_and_the_carried_points(tournament) -> None:
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    assert training_front(tournament[1], "pure-pursuit", ax, error="max_abs_cte_m") is ax
    labels = ax.get_legend_handles_labels()[1]
    for label in ("trials", "failed trials", "front", "default (trial 0)", "chosen (tuned)", "carried to the test set"):
        assert label in labels
    assert sorted(a.get_text() for a in ax.texts) == ["F1", "F2"]
    front = next(c for c in ax.collections if c.get_label() == "front")
    assert sorted(front.get_offsets()[:, 0]) == [5.0, 8.0, 9.0, 14.0]  # trials 1, 0, 2, 3; 4 failed


@pytest.mark.parametrize(
    ("objectives", "ranking", "expected"),
    [
        (DEFAULT_OBJECTIVES, RANKING, ("rms_steer_rate_deg_s", "max_abs_cte_on_path_m")),
        (DEFAULT_OBJECTIVES, {"max_abs_cte_on_path_m": 1.0}, ("rms_steer_rate_deg_s", "max_abs_cte_on_path_m")),
        (OBJECTIVES, RANKING, ("rms_steer_rate_deg_s", "max_abs_cte_m")),
        (DEFAULT_OBJECTIVES, {"rms_cte_m": 1.0}, ("rms_steer_rate_deg_s", "rms_cte_m")),
        (("rms_cte_m", "max_abs_steer_rate_deg_s"), RANKING, ("max_abs_steer_rate_deg_s", "rms_cte_m")),
    ],
)
def test_the_fronts_are_drawn_with_the_objectives_the_ranking_weighs(objectives, ranking, expected) -> None:
    assert front_metrics(objectives, ranking) == expected


def test_a_trace_of_a_controller_not_judged_and_a_history_without_an_objective_are_refused(
    tournament, tmp_path: Path
) -> None:
    results, history, judgement = tournament
    with pytest.raises(WorkbenchInputError, match="a trace is given for 'nmpc', which was not judged"):
        write_report(tmp_path, summary(results), results, history, judgement, {"nmpc": None})
    with pytest.raises(WorkbenchInputError, match=r"the history lacks the column.s. train_max_abs_cte_m, carried$"):
        bare = history.drop(columns=["train_max_abs_cte_m", "carried"])
        write_report(tmp_path, summary(results), results, bare, judgement, {})
    assert not (tmp_path / "report.html").exists()
