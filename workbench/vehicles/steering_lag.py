"""The identified lag between steering-wheel angle and path curvature (paper, section 5.1, Eq. 5), and its file.

    G_lag(s) = K wn^2 / (s^2 + 2 zeta wn s + wn^2) x exp(-s delay)

(Eq. 5 has K = 1. A real vehicle understeers or oversteers, so the realised curvature settles at K times the
kinematic (Ackermann) one, K depending on speed; `tuning fit-lag` fits K too unless told not to.)

`tuning fit-lag` writes it; the clothoid controller's lead filter is designed from it and the MPC's prediction
model takes it as its steering dynamics, so both controllers use the same identified data. The file is JSON:

    {"format": "steering-lag/1", "omega_n_rad_s": 4.44, "zeta": 0.80, "delay_s": 0.0,
     "steady_state_gain": 0.94, "nrmse": 0.03, "speed_range_mps": [8.2, 8.4], "source": "free text"}

Required: format, omega_n_rad_s, zeta. Optional: delay_s (default 0), steady_state_gain (K, default 1), nrmse (fit
quality: RMS error over the range of the measured curvature), speed_range_mps (the speeds the data covered),
source. Any other key is an error, so that a misspelt key is not silently ignored.
"""

from __future__ import annotations

import json
import math
from dataclasses import KW_ONLY, dataclass
from pathlib import Path

from workbench.errors import WorkbenchInputError, require_in_range
from workbench.input_files import read_json

FORMAT_TAG = "steering-lag/1"
_REQUIRED = ("format", "omega_n_rad_s", "zeta")
_OPTIONAL = ("delay_s", "steady_state_gain", "nrmse", "speed_range_mps", "source")


@dataclass(frozen=True)
class SteeringLag:
    """Eq. 5: omega_n_rad_s (natural frequency, 0.05-200 rad/s), zeta (damping, 0.05-10), delay_s (pure delay,
    0-2 s), steady_state_gain (K: realised / kinematic curvature in a steady turn, 0.05-20; Eq. 5 has 1); nrmse and
    speed_range_mps describe the identification (NaN / None when unknown)."""

    omega_n_rad_s: float
    zeta: float
    delay_s: float = 0.0
    _: KW_ONLY
    steady_state_gain: float = 1.0
    nrmse: float = math.nan
    speed_range_mps: tuple[float, float] | None = None
    source: str = ""

    def __post_init__(self) -> None:
        require_in_range("omega_n_rad_s", self.omega_n_rad_s, 0.05, 200.0, "rad/s")
        require_in_range("zeta", self.zeta, 0.05, 10.0)
        require_in_range("delay_s", self.delay_s, 0.0, 2.0, "s")
        require_in_range("steady_state_gain", self.steady_state_gain, 0.05, 20.0)
        if not (math.isnan(self.nrmse) or self.nrmse >= 0.0):
            raise WorkbenchInputError(f"nrmse must be >= 0 (or NaN when unknown); got {self.nrmse!r}")
        if self.speed_range_mps is not None:
            low, high = self.speed_range_mps
            require_in_range("speed_range_mps[0]", low, 0.0, 150.0, "m/s")
            require_in_range("speed_range_mps[1]", high, low, 150.0, "m/s")
            object.__setattr__(self, "speed_range_mps", (float(low), float(high)))
        for name in ("omega_n_rad_s", "zeta", "delay_s", "steady_state_gain", "nrmse"):
            object.__setattr__(self, name, float(getattr(self, name)))

    @property
    def group_delay_s(self) -> float:
        """The low-frequency delay of Eq. 5 (s), -d(phase)/d(omega) at omega = 0: the pure delay plus 2 zeta / wn."""
        return self.delay_s + 2.0 * self.zeta / self.omega_n_rad_s

    def to_dict(self) -> dict:
        out: dict = {
            "format": FORMAT_TAG,
            "omega_n_rad_s": self.omega_n_rad_s,
            "zeta": self.zeta,
            "delay_s": self.delay_s,
            "steady_state_gain": self.steady_state_gain,
        }
        if not math.isnan(self.nrmse):
            out["nrmse"] = self.nrmse
        if self.speed_range_mps is not None:
            out["speed_range_mps"] = list(self.speed_range_mps)
        if self.source:
            out["source"] = self.source
        return out


def write_lag_file(lag: SteeringLag, path: str | Path) -> Path:
    """Write `lag` as JSON; returns the path."""
    path = Path(path)
    path.write_text(json.dumps(lag.to_dict(), indent=2) + "\n")
    return path


def read_lag_file(path: str | Path) -> SteeringLag:
    """Read a steering-lag file, with an error naming the file and the offending key or value."""
    path = Path(path)
    data = read_json(path, f"steering-lag file {str(path)!r}")
    if not isinstance(data, dict):
        raise WorkbenchInputError(f"steering-lag file {str(path)!r} must hold a JSON object; got {type(data).__name__}")
    missing = [key for key in _REQUIRED if key not in data]
    unknown = sorted(set(data) - set(_REQUIRED) - set(_OPTIONAL))
    if missing or unknown:
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: missing keys {missing}, unknown keys {unknown}; "
            f"required {list(_REQUIRED)}, optional {list(_OPTIONAL)}"
        )
    if data["format"] != FORMAT_TAG:
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: format must be {FORMAT_TAG!r}; got {data['format']!r}"
        )
    speed_range = data.get("speed_range_mps")
    if speed_range is not None and (not isinstance(speed_range, list) or len(speed_range) != 2):
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: speed_range_mps must be [low, high]; got {speed_range!r}"
        )
    try:
        return SteeringLag(
            omega_n_rad_s=data["omega_n_rad_s"],
            zeta=data["zeta"],
            delay_s=data.get("delay_s", 0.0),
            steady_state_gain=data.get("steady_state_gain", 1.0),
            nrmse=data.get("nrmse", math.nan),
            speed_range_mps=tuple(speed_range) if speed_range is not None else None,
            source=str(data.get("source", "")),
        )
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"steering-lag file {str(path)!r}: {exc}") from None
