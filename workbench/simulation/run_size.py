"""How much a run may simulate before it times out, and the bound a run or study is refused beyond (`RunSize`).

A run stops at its time-out at the latest: `SimulationConfig.max_time_s`, or by default TIMEOUT_FACTOR times the
planned time to cover the path (its laps included, at the planned speed profile's mean speed) plus
TIMEOUT_MARGIN_S. Its trace may then hold one row per controller step. A run whose time-out allows more than
MAX_RUN_STEPS controller steps, or a trace larger than MAX_TRACE_BYTES, is refused before it starts
(`check_run_size`) unless the caller's explicit allowance is given (`workbench run/compare --allow-long-run`,
`workbench robustness --allow-long-run`, a study's `study.allow_long_runs = true`): a speed of 0.001 km/h or
100 000 laps would otherwise simulate for days and fill the memory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.run_config import SimulationConfig

#: The most controller steps a run's time-out may allow without an explicit allowance (at 50 Hz 11 simulated
#: hours; a Zandvoort lap at 30 km/h allows about 79 000, a dlc at 30 km/h about 5 700).
MAX_RUN_STEPS = 2_000_000
#: The largest trace (bytes: rows x columns x BYTES_PER_VALUE) a run's time-out may allow without an explicit
#: allowance.
MAX_TRACE_BYTES = 1_000_000_000
#: Bytes of one trace value (float64).
BYTES_PER_VALUE = 8
#: Trace columns besides the vehicle's outputs, estimated generously: the simulator's 11 signals, up to 29
#: controller diagnostics (`ctrl_*`).
EXTRA_TRACE_COLUMNS = 40
#: The default time-out: this many times the planned time to cover the path ...
TIMEOUT_FACTOR = 3.0
#: ... plus this margin (s).
TIMEOUT_MARGIN_S = 30.0


@dataclass(frozen=True)
class RunSize:
    """The most a run may simulate: max_time_s, its time-out (s); steps, the controller steps before it (the
    trace's rows); columns, the trace's columns (estimated generously); controller_rate_hz (Hz)."""

    max_time_s: float
    steps: int
    columns: int
    controller_rate_hz: float

    @classmethod
    def of(cls, path: ReferencePath, config: SimulationConfig, output_count: int) -> RunSize:
        """The size of a run of `config` along `path` (carrying the planned speed, `simulator.plan_path_speed`) by a
        vehicle of `output_count` outputs."""
        if path.speed_mps is None:
            raise WorkbenchInputError(f"{path.name}: the path carries no planned speed (`plan_path_speed`)")
        length_m = path.length_m * (config.laps if path.closed else 1)
        mean_speed_mps = float(np.mean(path.speed_mps))
        max_time_s = config.max_time_s or TIMEOUT_FACTOR * length_m / mean_speed_mps + TIMEOUT_MARGIN_S
        steps = math.ceil(max_time_s * config.controller_rate_hz) + 1
        return cls(max_time_s, steps, output_count + EXTRA_TRACE_COLUMNS, config.controller_rate_hz)

    @property
    def trace_bytes(self) -> int:
        """The largest trace the run may write (bytes)."""
        return self.steps * self.columns * BYTES_PER_VALUE

    @property
    def too_large(self) -> bool:
        """More steps than MAX_RUN_STEPS or a trace larger than MAX_TRACE_BYTES."""
        return self.steps > MAX_RUN_STEPS or self.trace_bytes > MAX_TRACE_BYTES

    def describe(self) -> str:
        """The size in words: simulated time, steps at the rate, the trace's rows x columns and bytes."""
        return (
            f"up to {duration_text(self.max_time_s)} ({self.steps:,} controller steps at "
            f"{self.controller_rate_hz:g} Hz), a trace of up to {self.steps:,} rows x about {self.columns} columns "
            f"(about {bytes_text(self.trace_bytes)})"
        )


def check_run_size(size: RunSize, label: str, shorten: str, allow: str) -> None:
    """Refuse a run (or a study's longest run) larger than the bounds: a WorkbenchInputError naming `label`, the
    size, the bounds, what shortens it (`shorten`) and the explicit allowance that lets it run (`allow`)."""
    if not size.too_large:
        return
    raise WorkbenchInputError(
        f"{label} may simulate {size.describe()}, more than the bound of {MAX_RUN_STEPS:,} steps or "
        f"{bytes_text(MAX_TRACE_BYTES)}: {shorten}, or allow it with {allow}"
    )


def duration_text(seconds: float) -> str:
    """A duration in the unit a person reads it in: s, min, h or days."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 2 * 3600:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.0f} h"
    return f"{seconds / 86400:,.0f} days"


def bytes_text(size: float) -> str:
    """A size in MB or GB (decimal)."""
    return f"{size / 1e9:,.1f} GB" if size >= 1e9 else f"{size / 1e6:,.0f} MB"


__all__ = [
    "EXTRA_TRACE_COLUMNS",
    "MAX_RUN_STEPS",
    "MAX_TRACE_BYTES",
    "RunSize",
    "check_run_size",
]
