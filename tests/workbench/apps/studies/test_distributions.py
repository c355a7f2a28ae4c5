"""Random draws of a study spec: parsing, bounds, reproducibility, and optuna search spaces."""

from __future__ import annotations

import math

import numpy as np
import optuna
import pytest

from workbench.apps.studies.distributions import Distribution, key_rng
from workbench.base.errors import WorkbenchInputError


def test_each_kind_draws_within_its_bounds() -> None:
    rng = np.random.default_rng(0)
    assert all(2.0 <= v < 5.0 for v in Distribution.parse("x", {"uniform": [2, 5]}).draw(rng, 500))
    logs = Distribution.parse("x", {"log_uniform": [0.01, 1.0]}).draw(rng, 2000)
    assert all(0.01 <= v < 1.0 for v in logs)
    assert np.median(logs) == pytest.approx(0.1, rel=0.15)  # the log-midpoint, not 0.505
    ints = Distribution.parse("x", {"integers": [10, 12]}).draw(rng, 300)
    assert set(ints) == {10, 11, 12} and all(isinstance(v, int) for v in ints)
    normal = Distribution.parse("x", {"normal": [1.0, 0.5]}).draw(rng, 4000)
    assert np.mean(normal) == pytest.approx(1.0, abs=0.05) and np.std(normal) == pytest.approx(0.5, rel=0.05)
    assert set(Distribution.parse("x", {"choice": ["a", "b"]}).draw(rng, 100)) == {"a", "b"}


def test_draws_are_reproducible_per_key_and_prefix_stable() -> None:
    dist = Distribution("uniform", (0.0, 1.0))
    first = dist.draw(key_rng(7, "speed_kmh"), 5)
    assert first == dist.draw(key_rng(7, "speed_kmh"), 5)
    assert dist.draw(key_rng(7, "speed_kmh"), 10)[:5] == first  # more samples keep the first ones
    assert first != dist.draw(key_rng(8, "speed_kmh"), 5)  # another seed
    assert first != dist.draw(key_rng(7, "payload_kg"), 5)  # another key


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"gaussian": [0, 1]}, "unknown distribution 'gaussian'; allowed: uniform, log_uniform, normal"),
        ({"uniform": [1, 2], "normal": [0, 1]}, "one-entry table"),
        ({"uniform": [2, 1]}, "low < high"),
        ({"uniform": [1, math.nan]}, "finite numbers"),
        ({"log_uniform": [0, 1]}, "0 < low"),
        ({"integers": [1.5, 3]}, "whole numbers"),
        ({"normal": [0, 0]}, "standard deviation > 0"),
        ({"choice": []}, "at least one value"),
        ({"choice": [1, 1]}, "twice"),
        ({"uniform": 3}, "needs a list"),
        ([1, 2], "one-entry table"),
    ],
)
def test_bad_distributions_are_refused_naming_the_key(table: object, message: str) -> None:
    with pytest.raises(WorkbenchInputError, match=r"random\.speed_kmh") as info:
        Distribution.parse("random.speed_kmh", table)
    assert message in str(info.value)


def test_optuna_spaces() -> None:
    space = Distribution("log_uniform", (0.01, 1.0)).to_optuna()
    assert isinstance(space, optuna.distributions.FloatDistribution) and space.log and space.low == 0.01
    assert isinstance(Distribution("integers", (1, 4)).to_optuna(), optuna.distributions.IntDistribution)
    assert Distribution("choice", ("a", "b")).to_optuna().choices == ("a", "b")
    with pytest.raises(WorkbenchInputError, match="bounded distribution"):
        Distribution("normal", (0.0, 1.0)).to_optuna()
