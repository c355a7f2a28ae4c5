"""Random parameter draws of a study spec: `{uniform = [low, high]}` and friends, drawn reproducibly.

A distribution is written in the spec as a one-entry table naming its kind:

    speed_kmh = { uniform = [20, 60] }                 # low <= x < high, float
    frechet_threshold_m = { log_uniform = [0.005, 0.5] }  # log-uniform, 0 < low < high, float
    initial_heading_error_deg = { normal = [0, 2] }    # mean, standard deviation > 0, float (sweeps only)
    horizon_steps = { integers = [10, 40] }            # low <= n <= high, whole numbers
    lookahead_mode = { choice = ["adaptive", "fixed"] } # one of the values, equally likely

A sweep draws `samples` values of each key with its own generator, `np.random.default_rng([seed, key hash])`: the
draws of one key do not depend on the other keys or their order, and asking for more samples keeps the first
ones. `workbench optimise` gives the same distributions to optuna as its search space.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from workbench.base.errors import WorkbenchInputError, value_text

if TYPE_CHECKING:
    import optuna

#: The distribution kinds, and what their list holds.
KINDS: dict[str, str] = {
    "uniform": "[low, high] (floats)",
    "log_uniform": "[low, high] (floats, 0 < low)",
    "normal": "[mean, standard deviation]",
    "integers": "[low, high] (whole numbers, both included)",
    "choice": "[value, value, ...]",
}
#: Kinds with bounds, which an optimiser can search.
SEARCHABLE = ("uniform", "log_uniform", "integers", "choice")


def _number(where: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise WorkbenchInputError(f"{where} must hold finite numbers; got {value_text(value)}")
    return float(value)


@dataclass(frozen=True)
class Distribution:
    """kind: one of KINDS; values: its list (bounds, mean and deviation, or the choices)."""

    kind: str
    values: tuple[Any, ...]

    def __post_init__(self) -> None:
        where = f"{{{self.kind} = ...}}"
        if self.kind not in KINDS:
            raise WorkbenchInputError(f"unknown distribution {self.kind!r}; allowed: {', '.join(KINDS)}")
        values = tuple(self.values)
        object.__setattr__(self, "values", values)
        if self.kind == "choice":
            if not values:
                raise WorkbenchInputError(f"{where} needs at least one value; got []")
            for v in values:
                if isinstance(v, float) and not math.isfinite(v):
                    raise WorkbenchInputError(f"{where} values must be finite; got {value_text(v)}")
                if isinstance(v, dict | list):
                    raise WorkbenchInputError(f"{where} values must be numbers, text or booleans; got {v!r}")
            if len({repr(v) for v in values}) != len(values):
                raise WorkbenchInputError(f"{where} lists a value twice: {list(values)}")
            return
        if len(values) != 2:
            raise WorkbenchInputError(f"{where} needs {KINDS[self.kind]}; got {list(values)}")
        a, b = (_number(where, v) for v in values)
        if self.kind == "integers":
            if not all(isinstance(v, int) and not isinstance(v, bool) for v in values) or a > b:
                raise WorkbenchInputError(f"{where} needs {KINDS[self.kind]} with low <= high; got {list(values)}")
        elif self.kind == "normal":
            if b <= 0:
                raise WorkbenchInputError(f"{where} needs a standard deviation > 0; got {list(values)}")
        elif not a < b or (self.kind == "log_uniform" and a <= 0):
            raise WorkbenchInputError(f"{where} needs {KINDS[self.kind]} with low < high; got {list(values)}")

    @classmethod
    def parse(cls, where: str, table: object) -> Distribution:
        """A distribution from its spec table (`{uniform = [1, 2]}`); `where` names it in errors.

        Parameters
        ----------
        where : str
            The spec key the table is the value of (e.g. "random.speed_kmh"), named in a message.
        table : dict
            A one-entry table: a kind of `KINDS` -> its list.

        Returns
        -------
        Distribution
            The checked distribution.

        Raises
        ------
        WorkbenchInputError
            Not a one-entry table, an unknown kind, or a list the kind refuses (`KINDS` says what each holds).

        Examples
        --------
        >>> from workbench.apps.studies.distributions import Distribution, key_rng
        >>> speed = Distribution.parse("random.speed_kmh", {"integers": [20, 60]})
        >>> speed.draw(key_rng(0, "speed_kmh"), 3)
        [47, 22, 45]
        """
        if not isinstance(table, dict) or len(table) != 1:
            raise WorkbenchInputError(
                f"{where} must be a one-entry table naming a distribution, e.g. {{uniform = [1, 2]}}; allowed: "
                + "; ".join(f"{k} = {v}" for k, v in KINDS.items())
                + f"; got {table!r}"
            )
        ((kind, values),) = table.items()
        if not isinstance(values, list):
            raise WorkbenchInputError(f"{where}: {kind} needs a list {KINDS.get(kind, '')}; got {values!r}")
        try:
            return cls(kind, tuple(values))
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(f"{where}: {exc}") from None

    @property
    def produces(self) -> str:
        """What the draws are: "float", "int" or "choice"."""
        return {"integers": "int", "choice": "choice"}.get(self.kind, "float")

    def draw(self, rng: np.random.Generator, n: int) -> list[Any]:
        """n values drawn with rng, as Python values (float, int, or the choices themselves).

        Parameters
        ----------
        rng : numpy.random.Generator
            The generator (`key_rng`: one per key, so that a key's draws do not depend on the others).
        n : int
            How many values, at least 0.

        Returns
        -------
        list
            n floats, whole numbers or choices.
        """
        a, b = self.values[0], self.values[-1]
        if self.kind == "uniform":
            return [float(v) for v in rng.uniform(a, b, n)]
        if self.kind == "log_uniform":
            return [float(v) for v in np.exp(rng.uniform(math.log(a), math.log(b), n))]
        if self.kind == "normal":
            return [float(v) for v in rng.normal(a, b, n)]
        if self.kind == "integers":
            return [int(v) for v in rng.integers(a, b, n, endpoint=True)]
        return [self.values[int(i)] for i in rng.integers(0, len(self.values), n)]

    def to_optuna(self) -> optuna.distributions.BaseDistribution:
        """The same distribution as an optuna search-space entry (bounded kinds only).

        Returns
        -------
        optuna.distributions.BaseDistribution
            A FloatDistribution (log for log_uniform), IntDistribution or CategoricalDistribution.

        Raises
        ------
        WorkbenchInputError
            The kind is not bounded (normal): not one of `SEARCHABLE`.
        """
        from optuna import distributions

        a, b = self.values[0], self.values[-1]
        if self.kind in ("uniform", "log_uniform"):
            return distributions.FloatDistribution(float(a), float(b), log=self.kind == "log_uniform")
        if self.kind == "integers":
            return distributions.IntDistribution(int(a), int(b))
        if self.kind == "choice":
            return distributions.CategoricalDistribution(self.values)
        raise WorkbenchInputError(
            f"an optimiser needs a bounded distribution ({', '.join(SEARCHABLE)}); got {self.kind}"
        )


def key_rng(seed: int, key: str) -> np.random.Generator:
    """The generator of one key's draws: seeded by the study's seed and a stable hash of the key's name.

    Parameters
    ----------
    seed : int
        The study's seed, at least 0.
    key : str
        The drawn parameter's name ("<controller>.<option>" for a controller's option).

    Returns
    -------
    numpy.random.Generator
        The same generator for the same seed and key, in any process.
    """
    digest = int.from_bytes(hashlib.sha256(key.encode()).digest()[:8], "little")
    return np.random.default_rng([seed, digest])


__all__ = ["KINDS", "SEARCHABLE", "Distribution", "key_rng"]
