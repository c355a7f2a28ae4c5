"""The search spaces the controllers declare (`controllers/search_space.py`): a `Tunable` refuses what is no range;
every registered controller's space names its real parameters, within each option's allowed range and holding its
shipped default; its TOML (`search_space_toml`, `workbench controllers --show NAME --search-space`) reads back as
the studies' distributions it declares; and points drawn from it (the bounds' corners and seeded random draws) run
a short path to completion. The example plugin's controller meets the same contract."""

from __future__ import annotations

import dataclasses
import math
import sys
import tomllib
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

from controllers import CONTROLLERS, ControllerRegistry, make_controller
from controllers.base import Controller
from controllers.config_checks import option_rule
from controllers.search_space import SCALES, Tunable, controller_search_space, search_space_toml
from workbench.apps.cli import main
from workbench.apps.controller_config import option_types
from workbench.apps.studies.distributions import Distribution
from workbench.apps.studies.run_build import LEAD_FILTER_SCALES
from workbench.apps.studies.runner import build_controller_config
from workbench.apps.studies.spec import PlannedRun, controller_parameters
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.control_interface import Measurement
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

NAMES = list(CONTROLLERS)
PLUGIN_SRC = Path(__file__).resolve().parents[2] / "examples" / "plugin" / "src"
#: A short path (about 55 m, 6.6 s at 30 km/h): a straight, a clothoid into a 30 m arc, out, a straight.
SHORT = Scenario(
    "short",
    ClothoidChain()
    .straight(10.0)
    .clothoid_to(1 / 30, 10.0)
    .arc(15.0)
    .clothoid_to(0.0, 10.0)
    .straight(10.0)
    .to_path("short"),
    "a short bend",
)
#: The random points drawn from each space besides its two corners (seeded).
RANDOM_POINTS = 2


def _plugin_controller() -> type[Controller]:
    """The example plugin's controller class, imported from its source folder (not installed here)."""
    sys.path.insert(0, str(PLUGIN_SRC))
    try:
        from workbench_example_plugin.lateral_pd import LateralPD
    finally:
        sys.path.remove(str(PLUGIN_SRC))
    return LateralPD


def _check_against_options(cls: type[Controller], space: tuple[Tunable, ...], parameters: dict[str, Any]) -> None:
    """Each tunable names one of `parameters`; its bounds (or choices) pass the option's own rule, and its range
    holds the shipped default. The lead-filter scales, run parameters, are factors > 0 whose default is 1."""
    fields = {f.name: f for f in dataclasses.fields(cls.config_type)}
    defaults = cls.config_type()
    for tunable in space:
        assert tunable.name in parameters, (tunable.name, sorted(parameters))
        ends = tunable.choices if tunable.scale == "choice" else (tunable.low, tunable.high)
        if tunable.name in LEAD_FILTER_SCALES:
            assert all(v > 0 for v in ends), tunable
            assert tunable.contains(1.0), tunable  # a run without the scale: factor 1
            continue
        rule = option_rule(fields[tunable.name])
        assert rule is not None, tunable.name
        for value in ends:
            rule.check(tunable.name, value)  # raises WorkbenchInputError outside the option's range
        default = getattr(defaults, tunable.name)
        assert tunable.contains(default), (tunable, default)


def _points(space: tuple[Tunable, ...], seed: int) -> list[dict[str, Any]]:
    """The space's two corners (every bound low, every bound high; a choice's first and last value) and
    RANDOM_POINTS draws, each drawn as the studies draw (`Distribution.draw`) with one seeded generator."""
    dists = {t.name: Distribution.parse(t.name, t.distribution_table()) for t in space}
    corners = [{k: d.values[0] for k, d in dists.items()}, {k: d.values[-1] for k, d in dists.items()}]
    rng = np.random.default_rng(seed)
    draws = [{k: d.draw(rng, 1)[0] for k, d in dists.items()} for _ in range(RANDOM_POINTS)]
    return corners + draws


# ---------------------------------------------------------------------------------------------- the Tunable
@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"scale": "cubic", "low": 0.0, "high": 1.0},
            r"scale must be one of linear, log, integer, choice; got 'cubic'",
        ),
        ({"scale": "linear", "low": 1.0, "high": 1.0}, r"finite bounds with low < high; got low = 1.0, high = 1.0"),
        (
            {"scale": "linear", "low": 0.0, "high": math.nan},
            r"finite bounds with low < high; got low = 0.0, high = nan",
        ),
        ({"scale": "linear", "low": None, "high": 1.0}, r"finite bounds with low < high; got low = None"),
        ({"scale": "linear", "low": True, "high": 2.0}, r"got low = True"),
        ({"scale": "log", "low": 0.0, "high": 1.0}, r"a log scale needs low > 0; got low = 0.0"),
        ({"scale": "integer", "low": 1.5, "high": 3}, r"whole-number bounds with low <= high; got low = 1.5"),
        ({"scale": "integer", "low": 5, "high": 3}, r"whole-number bounds with low <= high; got low = 5, high = 3"),
        ({"scale": "linear", "low": 0.0, "high": 1.0, "choices": (1,)}, r"only a choice has choices"),
        ({"scale": "choice"}, r"choices must be a non-empty tuple of values; got \(\)"),
        ({"scale": "choice", "choices": ["a"]}, r"choices must be a non-empty tuple of values; got \['a'\]"),
        ({"scale": "choice", "choices": ("a", "a")}, r"choices list a value twice: \['a', 'a'\]"),
        ({"scale": "choice", "choices": (1.0, math.inf)}, r"choices must be finite numbers, text or booleans; got inf"),
        ({"scale": "choice", "choices": ("a",), "low": 0.0}, r"a choice has no bounds"),
        ({"scale": "linear", "low": 0.0, "high": 1.0, "reason": ""}, r"reason must be one non-empty line"),
        ({"scale": "linear", "low": 0.0, "high": 1.0, "reason": "two\nlines"}, r"reason must be one non-empty line"),
    ],
)
def test_a_tunable_that_is_no_range_is_refused_naming_what_is_allowed(kwargs: dict[str, Any], message: str) -> None:
    arguments = {"reason": "what it trades"} | kwargs
    with pytest.raises(WorkbenchInputError, match=message):
        Tunable("some_option", **arguments)


def test_a_tunable_needs_an_option_name() -> None:
    with pytest.raises(WorkbenchInputError, match=r"an option's name \(an identifier\); got 'not a name'"):
        Tunable("not a name", "linear", 0.0, 1.0, reason="r")


@pytest.mark.parametrize(
    ("tunable", "table", "inside", "outside"),
    [
        (Tunable("a", "linear", 0, 2, reason="r"), {"uniform": [0.0, 2.0]}, (0.0, 1.3, 2), (-0.1, 2.1, math.nan)),
        (Tunable("a", "log", 0.01, 1.0, reason="r"), {"log_uniform": [0.01, 1.0]}, (0.01, 0.5), (0.0, 2.0)),
        (Tunable("a", "integer", 2, 5, reason="r"), {"integers": [2, 5]}, (2, 5, 3.0), (1, 6, 2.5)),
        (Tunable("a", "choice", choices=("x", 3), reason="r"), {"choice": ["x", 3]}, ("x", 3), ("y", 3.5, True)),
    ],
)
def test_a_tunable_in_the_studies_distribution_form(
    tunable: Tunable, table: dict[str, list[Any]], inside: tuple[Any, ...], outside: tuple[Any, ...]
) -> None:
    """Each scale is the studies' distribution kind of the same range (a linear or log scale's bounds as floats),
    and `contains` says which values lie in it."""
    assert tunable.distribution_table() == table
    assert Distribution.parse("a", tunable.distribution_table()) == Distribution.parse("a", table)
    assert all(tunable.contains(v) for v in inside)
    assert not any(tunable.contains(v) for v in outside)
    assert set(SCALES) == {"linear", "log", "integer", "choice"}


# ------------------------------------------------------------------------------- every registered controller
@pytest.mark.parametrize("name", NAMES)
def test_every_tunable_is_a_parameter_of_its_controller_within_its_range_holding_its_default(name: str) -> None:
    space = controller_search_space(name)
    built_in = CONTROLLERS[name].__module__.startswith("controllers.")
    assert space or not built_in, f"{name} declares no search space"  # an installed plugin's may be empty
    _check_against_options(CONTROLLERS[name], space, controller_parameters(name))


@pytest.mark.parametrize("name", NAMES)
def test_the_toml_reads_back_as_the_distributions_declared(name: str) -> None:
    """The printed table parses (tomllib) into the declared tunables' distributions, key for key, in order, each
    line carrying its reason."""
    text = search_space_toml(name)
    table = tomllib.loads(text)["search"][name]
    space = controller_search_space(name)
    assert list(table) == [t.name for t in space]
    for tunable in space:
        parsed = Distribution.parse(tunable.name, table[tunable.name])
        assert parsed == Distribution.parse(tunable.name, tunable.distribution_table())
        assert parsed.values == (tunable.choices if tunable.scale == "choice" else (tunable.low, tunable.high))
        line = next(line for line in text.splitlines() if line.startswith(f"{tunable.name} = "))
        assert line.endswith(f"  # {tunable.reason}")


@pytest.mark.parametrize("name", NAMES)
def test_points_drawn_from_the_space_run_a_short_path_to_completion(name: str) -> None:
    """The two corners and RANDOM_POINTS seeded draws, each built as a study run builds its controller (the
    controller-config options, the vehicle's tuning, the lead-filter scales), run a short bend on the dynamic
    bicycle at 30 km/h to completion."""
    vehicle = make_vehicle("dynamic-bicycle")
    for point in _points(controller_search_space(name), seed=31):
        run = PlannedRun("contract", 0, "short", name, vehicle.name, options=tuple(point.items()))
        config = build_controller_config(run, vehicle)
        controller = make_controller(name, vehicle.geometry, config, vehicle=vehicle)
        result = Simulation(SHORT, vehicle, controller, SimulationConfig(speed_kmh=30.0)).run()
        assert result.status.value == "completed", (point, result.message)
        assert math.isfinite(result.metrics.max_abs_cte_m), point


def test_the_example_plugins_controller_meets_the_same_contract() -> None:
    """The example plugin's controller (examples/plugin/) declares a space naming its options within their ranges,
    and its points run."""
    cls = _plugin_controller()
    space = cls.search_space
    assert space and all(isinstance(t, Tunable) for t in space)
    _check_against_options(cls, space, option_types(cls.config_type))
    vehicle = make_vehicle("kinematic-bicycle")
    for point in _points(space, seed=31):
        controller = cls(vehicle.geometry, cls.config_type(**point))
        result = Simulation(SHORT, vehicle, controller, SimulationConfig(speed_kmh=30.0)).run()
        assert result.status.value == "completed", (point, result.message)


# ------------------------------------------------------------------------------ spaces that are not declared
class _Quiet(Controller):
    """A controller that declares no search space (as a plugin may)."""

    name: ClassVar[str] = "quiet"
    config_type: ClassVar[type] = dict

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        pass

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        return 0.0


class _Twice(_Quiet):
    name: ClassVar[str] = "twice"
    search_space: ClassVar[tuple[Tunable, ...]] = (
        Tunable("gain", "linear", 0.0, 1.0, reason="r"),
        Tunable("gain", "log", 0.1, 1.0, reason="r"),
    )


class _NotTunables(_Quiet):
    name: ClassVar[str] = "loose"
    search_space = ({"uniform": [0, 1]},)  # type: ignore[assignment]


@pytest.fixture
def registry(monkeypatch: pytest.MonkeyPatch) -> None:
    """The registered controllers with three stand-ins: one declaring no space, two declaring a malformed one."""
    classes = [CONTROLLERS[n] for n in NAMES] + [_Quiet, _Twice, _NotTunables]
    registered = ControllerRegistry({cls.name: (cls.__module__, cls.__name__) for cls in classes})
    monkeypatch.setattr("controllers.CONTROLLERS", registered)
    monkeypatch.setattr("workbench.apps.cli.CONTROLLERS", registered)


@pytest.mark.usefixtures("registry")
def test_a_controller_without_a_space_has_none_and_its_toml_says_how_to_give_one() -> None:
    assert controller_search_space("quiet") == ()
    text = search_space_toml("quiet")
    assert tomllib.loads(text) == {}  # comments only: nothing a spec would copy by mistake
    assert "controller 'quiet' declares no search space" in text and "[search.quiet] table" in text


@pytest.mark.usefixtures("registry")
@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("twice", r"controller 'twice': its search_space names gain more than once"),
        ("loose", r"controller 'loose': search_space must be a tuple of controllers.search_space.Tunable"),
        ("stanly", r"unknown controller 'stanly'; choose one of clothoid, "),
    ],
)
def test_a_malformed_space_or_an_unknown_name_is_refused(name: str, message: str) -> None:
    with pytest.raises(WorkbenchInputError, match=message):
        controller_search_space(name)


# ---------------------------------------------------------------------------------------------- the command
def test_the_command_prints_the_space_as_toml(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["controllers", "--show", "stanley", "--search-space"]) == 0
    out = capsys.readouterr().out
    assert out == search_space_toml("stanley")
    assert "gain_per_s = {log_uniform = [0.3, 5.0]}" in out


@pytest.mark.usefixtures("registry")
def test_the_command_says_when_a_controller_declares_no_space(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["controllers", "--show", "quiet", "--search-space"]) == 0
    assert "declares no search space" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["controllers", "--search-space"], "--search-space needs --show NAME"),
        (["controllers", "--show", "stanly", "--search-space"], "unknown controller 'stanly'"),
    ],
)
def test_the_command_refuses_what_it_cannot_show(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(args) == 2
    assert message in capsys.readouterr().err
