"""Closed circuits drawn from a seed: scenarios `circuit:SEED` that training and test sets can draw without end.

A circuit is a closed chain of straights and turns, each turn a clothoid from zero curvature to its peak, an arc
(absent when the turn is too short for one at its curvature rate) and a clothoid back to zero
(`workbench.base.clothoid_chain`, evaluated with Bertolazzi's Clothoids through pyclothoids). Every piece starts
at the curvature the previous one ends at, so the curvature is continuous everywhere, the seam included (it lies
in the middle of the longest straight, where the run starts).

How a circuit is drawn from its seed (`generate_circuit`), within `CircuitRanges`:

1. the number of turns; which of them turn against the loop's sense (chicanes and S-bends, each with probability
   `reverse_turn_share`); the loop's sense (clockwise or not); each turn's angle, the angles turning with the
   loop summing to 360 degrees plus those turning against it, so the heading closes exactly;
2. each turn's radius and curvature rate; a turn whose angle leaves no room for an arc at that rate becomes a
   clothoid pair, its rate raised (up to the largest allowed) or its radius widened until the pair turns the
   angle;
3. the straights' lengths: target lengths drawn, then moved the least (alternating projections between the
   closure's two linear equations and the allowed lengths) so that the chain ends exactly where it starts. The
   closure is linear in the straights' lengths, so every turn keeps the curvature and rate it was drawn with; a
   G2 Hermite closing piece (pyclothoids' `SolveG2`, three clothoids) would close any chain but with curvature
   rates nobody chose;
4. the circuit qualifies when its straights and its length are within the ranges and it never comes near itself:
   points of the centre line farther apart along it than half a circle of diameter `clearance_m` (pi/2 times
   `clearance_m`, measured the short way round) are at least `clearance_m` apart (checked on samples every
   `CLEARANCE_SPACING_M`). Otherwise it is drawn again from the same random stream, at most `MAX_ATTEMPTS` times.

The random stream is Python's `random.Random(seed)`, of which only `random()` is used: the one sequence Python
promises to keep across versions, so a seed names the same circuit, bit for bit, wherever the same pyclothoids
and numpy evaluate it.

The track is the same width all round: each side, half the vehicle's width, `side_margin_m`, and the steady-state
off-tracking of a semitrailer at the tightest radius the ranges allow (`CircuitRanges.side_width_m`), so that a
run's `left_track` and `min_track_margin_m` (`workbench.simulation.track_margin`) measure the controller.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workbench.base.errors import WorkbenchInputError, value_text
from workbench.simulation.circuit_ranges import CircuitRanges
from workbench.simulation.scenario import Scenario, ScenarioOptions

if TYPE_CHECKING:
    from workbench.base.clothoid_chain import ClothoidChain

#: The scenario name's prefix: "circuit:SEED".
CIRCUIT_PREFIX = "circuit:"
#: Seeds allowed: whole numbers in [0, MAX_SEED] (the range of a run's seed).
MAX_SEED = 2**63 - 1
#: Draws per seed before `draw_circuit` gives up (with the default ranges a seed took 4.7 draws on average over
#: seeds 0-999, 36 at most).
MAX_ATTEMPTS = 400
#: The centre line is sampled every this (m) for the self-approach check: between two stretches d apart the samples
#: overstate the least distance by at most h^2 / (8 d) (2 mm at 20 m), and two stretches that cross show a pair of
#: samples within h of each other.
CLEARANCE_SPACING_M = 0.5
#: The straights are kept this far (m) inside their allowed lengths while the closure is solved, so that the
#: exact closing step after the last projection cannot push one outside.
_STRAIGHT_SLACK_M = 1e-6
#: Alternating projections per draw between the closure's equations and the allowed straight lengths.
_PROJECTIONS = 200
#: The ranges a circuit is drawn within unless others are given.
DEFAULT_RANGES = CircuitRanges()


@dataclass(frozen=True)
class Turn:
    """One turn of a circuit: its signed angle (rad, left positive), peak curvature (1/m, signed as the angle),
    the length of each of its two clothoids (m) and of its arc (m, 0 for a clothoid pair)."""

    angle_rad: float
    curvature_1pm: float
    clothoid_m: float
    arc_m: float

    @property
    def length_m(self) -> float:
        return 2.0 * self.clothoid_m + self.arc_m

    def append_to(self, chain: ClothoidChain) -> ClothoidChain:
        chain.clothoid_to(self.curvature_1pm, self.clothoid_m)
        if self.arc_m > 0.0:
            chain.arc(self.arc_m)
        return chain.clothoid_to(0.0, self.clothoid_m)


@dataclass(frozen=True)
class Circuit:
    """A drawn circuit: its seed, the straights' lengths (m; straight i precedes turn i, the first is split at the
    seam), its turns, and how many draws it took."""

    seed: int
    straights_m: tuple[float, ...]
    turns: tuple[Turn, ...]
    attempts: int

    @property
    def length_m(self) -> float:
        return float(sum(self.straights_m) + sum(t.length_m for t in self.turns))

    def chain(self) -> ClothoidChain:
        """The centre line from the middle of the first straight, heading along +x, round to the same point."""
        from workbench.base.clothoid_chain import ClothoidChain

        chain = ClothoidChain().straight(0.5 * self.straights_m[0])
        for k, turn in enumerate(self.turns):
            turn.append_to(chain)
            chain.straight(self.straights_m[k + 1] if k + 1 < len(self.turns) else 0.5 * self.straights_m[0])
        return chain


def circuit_seed(name: str) -> int | None:
    """The seed of a generated circuit's name ("circuit:12" -> 12), None for any other name. A name that starts
    with "circuit:" but does not end in a seed (a whole number 0 to 2**63 - 1, written without sign, spaces or
    leading zeros, so that each circuit has one name) is refused naming it."""
    if not isinstance(name, str) or not name.startswith(CIRCUIT_PREFIX):
        return None
    text = name[len(CIRCUIT_PREFIX) :]
    if text.isascii() and text.isdigit() and str(int(text)) == text and int(text) <= MAX_SEED:
        return int(text)
    raise WorkbenchInputError(
        f"scenario {name!r}: a generated circuit is named circuit:SEED, SEED a whole number from 0 to 2**63 - 1 "
        f"written without sign, spaces or leading zeros (e.g. circuit:7); got SEED = {text!r}"
    )


def circuit_name(seed: int) -> str:
    """The scenario name of the circuit drawn from this seed ("circuit:SEED")."""
    return f"{CIRCUIT_PREFIX}{_checked_seed(seed)}"


def _checked_seed(seed: int) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or not 0 <= seed <= MAX_SEED:
        raise WorkbenchInputError(f"circuit seed must be a whole number in [0, 2**63 - 1]; got {value_text(seed)}")
    return int(seed)


def draw_circuit(seed: int, ranges: CircuitRanges = DEFAULT_RANGES) -> Circuit:
    """The circuit of this seed within the ranges (module docstring): the first of its draws that qualifies.
    WorkbenchInputError naming the seed, the ranges' limits most often missed and what to widen when none of
    MAX_ATTEMPTS does."""
    seed = _checked_seed(seed)
    if not isinstance(ranges, CircuitRanges):
        raise WorkbenchInputError(f"ranges must be a CircuitRanges; got {type(ranges).__name__}")
    stream = random.Random(seed)
    missed: dict[str, int] = {}
    for attempt in range(1, MAX_ATTEMPTS + 1):
        circuit, why = _draw(stream, ranges, seed, attempt)
        if circuit is not None:
            return circuit
        missed[why] = missed.get(why, 0) + 1
    reasons = ", ".join(f"{why} ({count} times)" for why, count in sorted(missed.items(), key=lambda kv: -kv[1]))
    raise WorkbenchInputError(
        f"{circuit_name(seed)}: none of {MAX_ATTEMPTS} circuits drawn from this seed fits the ranges: {reasons}; "
        "widen the straights' or the lap's lengths, or lower clearance_m"
    )


def _uniform(stream: random.Random, low: float, high: float) -> float:
    return low + (high - low) * stream.random()


def _draw(stream: random.Random, ranges: CircuitRanges, seed: int, attempt: int) -> tuple[Circuit | None, str]:
    """One draw: the circuit, or None and which limit it missed."""
    count = ranges.min_turns + min(
        int(stream.random() * (ranges.max_turns - ranges.min_turns + 1)), ranges.max_turns - ranges.min_turns
    )
    sense = 1.0 if stream.random() < 0.5 else -1.0
    reverse = [stream.random() < ranges.reverse_turn_share for _ in range(count)]
    low, high = math.radians(ranges.min_turn_deg), math.radians(ranges.max_turn_deg)
    against = [_uniform(stream, low, math.radians(ranges.max_reverse_turn_deg)) if r else 0.0 for r in reverse]
    weights = [0.5 + stream.random() for _ in range(count)]
    forward = count - sum(reverse)
    total = 2.0 * math.pi + sum(against)
    spare = total - forward * low
    if forward == 0 or spare < 0.0:
        return None, "turn angles below min_turn_deg"
    weight_sum = sum(w for w, r in zip(weights, reverse, strict=True) if not r) or 1.0
    angles = [-a if r else low + spare * w / weight_sum for a, w, r in zip(against, weights, reverse, strict=True)]
    if max(abs(a) for a in angles) > high:
        return None, "turn angles above max_turn_deg"
    turns = tuple(_turn(stream, ranges, sense * a) for a in angles)
    targets = [_uniform(stream, ranges.min_straight_m, ranges.max_straight_m) for _ in range(count)]
    straights = _closing_straights(turns, targets, ranges)
    if straights is None:
        return None, "straights outside their lengths"
    # Start in the middle of the longest straight: turn the order round so that it comes first.
    first = int(np.argmax(straights))
    straights = straights[first:] + straights[:first]
    turns = turns[first:] + turns[:first]
    circuit = Circuit(seed, tuple(straights), turns, attempt)
    if not ranges.min_length_m <= circuit.length_m <= ranges.max_length_m:
        return None, "lap length outside its range"
    if least_clearance_m(circuit.chain(), ranges.clearance_m) < ranges.clearance_m:
        return None, "the centre line coming near itself"
    return circuit, ""


def _turn(stream: random.Random, ranges: CircuitRanges, angle_rad: float) -> Turn:
    """A turn of this signed angle with a radius and a curvature rate drawn; a clothoid pair (no arc) when the
    angle leaves no room for an arc: its rate raised to the pair's, at most the largest allowed, its radius
    widened when even that is not enough."""
    kappa = 1.0 / _uniform(stream, ranges.min_radius_m, ranges.max_radius_m)
    rate = _uniform(stream, ranges.min_curvature_rate_1pm2, ranges.max_curvature_rate_1pm2)
    theta = abs(angle_rad)
    if kappa * kappa > rate * theta:  # the two clothoids alone would turn more than theta
        rate = min(kappa * kappa / theta, ranges.max_curvature_rate_1pm2)
        kappa = math.sqrt(rate * theta)
        return Turn(angle_rad, math.copysign(kappa, angle_rad), kappa / rate, 0.0)
    clothoid = kappa / rate
    return Turn(angle_rad, math.copysign(kappa, angle_rad), clothoid, theta / kappa - clothoid)


def _closing_straights(turns: tuple[Turn, ...], targets: list[float], ranges: CircuitRanges) -> list[float] | None:
    """The straights' lengths nearest the targets (alternating projections) that close the loop exactly, each
    within the allowed lengths; None when the projections find none."""
    from workbench.base.clothoid_chain import ClothoidChain

    heading, rows, rest = 0.0, [], np.zeros(2)
    for turn in turns:  # straight k runs along `heading`, then turn k moves the end by its rotated displacement
        direction = np.array([math.cos(heading), math.sin(heading)])
        rows.append(direction)
        x, y, _ = turn.append_to(ClothoidChain()).end_pose()
        rest += x * direction + y * np.array([-direction[1], direction[0]])
        heading += turn.angle_rad
    a = np.array(rows).T  # (2, n): the closure is a @ lengths + rest = 0
    gram = a @ a.T
    if np.linalg.cond(gram) > 1e8:  # all the straights (anti)parallel: their lengths cannot close the loop
        return None
    projector = a.T @ np.linalg.inv(gram)
    low, high = ranges.min_straight_m + _STRAIGHT_SLACK_M, ranges.max_straight_m - _STRAIGHT_SLACK_M
    lengths = np.array(targets)
    for _ in range(_PROJECTIONS):
        lengths = lengths - projector @ (a @ lengths + rest)
        if np.all((lengths >= low) & (lengths <= high)):
            break
        lengths = np.clip(lengths, low, high)
    lengths = lengths - projector @ (a @ lengths + rest)
    if not np.all((lengths >= ranges.min_straight_m) & (lengths <= ranges.max_straight_m)):
        return None
    return [float(v) for v in lengths]


def least_clearance_m(chain: ClothoidChain, clearance_m: float) -> float:
    """The least distance (m) between points of the closed chain's centre line that are more than pi/2 times
    clearance_m apart along it (the short way round), sampled every CLEARANCE_SPACING_M; clearance_m itself when
    every such pair is at least that far apart (only closer pairs are looked at)."""
    from scipy.spatial import cKDTree

    path = chain.to_path("clearance", closed=True, spacing_m=CLEARANCE_SPACING_M)
    points = np.column_stack((path.x_m[:-1], path.y_m[:-1]))
    s = path.s_m[:-1]
    pairs = cKDTree(points).query_pairs(clearance_m, output_type="ndarray")
    if pairs.size == 0:
        return clearance_m
    along = np.abs(s[pairs[:, 0]] - s[pairs[:, 1]])
    along = np.minimum(along, path.length_m - along)
    apart = pairs[along > 0.5 * math.pi * clearance_m]
    if apart.size == 0:
        return clearance_m
    return float(np.min(np.linalg.norm(points[apart[:, 0]] - points[apart[:, 1]], axis=1)))


def generate_circuit(
    seed: int, ranges: CircuitRanges = DEFAULT_RANGES, vehicle_width_m: float | None = None
) -> Scenario:
    """The scenario `circuit:SEED`: the circuit drawn from the seed (`draw_circuit`) as a closed, curvature-
    continuous path, started in the middle of its longest straight, with the track's widths for a vehicle
    vehicle_width_m wide (m, within the scenarios' range; `CircuitRanges.side_width_m` each side), or no track
    widths when it is None. The same seed and ranges give the same path, bit for bit."""
    circuit = draw_circuit(seed, ranges)
    name = circuit_name(seed)
    path = circuit.chain().to_path(name, closed=True)
    width = None
    if vehicle_width_m is not None:
        ScenarioOptions(vehicle_width_m=vehicle_width_m)  # the range the scenarios accept
        width = ranges.side_width_m(vehicle_width_m)
        sides = np.full(path.x_m.size, width)
        path = type(path)(
            path.x_m, path.y_m, path.heading_rad, path.curvature_1pm, path.spacing_m, True, name=name,
            width_right_m=sides, width_left_m=sides.copy(),
        )  # fmt: skip
    radius = 1.0 / max(abs(t.curvature_1pm) for t in circuit.turns)
    track = f", track {width:.2f} m each side" if width is not None else ", no track widths"
    description = (
        f"circuit drawn from seed {circuit.seed}: {circuit.length_m:.0f} m closed loop, {len(circuit.turns)} turns, "
        f"tightest radius {radius:.1f} m{track}"
    )
    return Scenario(name, path, description)


def circuit_family_description(ranges: CircuitRanges = DEFAULT_RANGES) -> str:
    """One line on the circuits `circuit:SEED` names, for `workbench scenarios`."""
    return (
        f"a closed circuit drawn from SEED (0 to 2**63 - 1): {ranges.min_length_m:g}-{ranges.max_length_m:g} m of "
        f"{ranges.min_turns}-{ranges.max_turns} turns (radius {ranges.min_radius_m:g}-{ranges.max_radius_m:g} m, "
        f"clothoid transitions) and straights, track sized for the vehicle"
    )


def write_circuit_file(
    path: str | Path, seed: int, ranges: CircuitRanges = DEFAULT_RANGES, vehicle_width_m: float | None = None
) -> Path:
    """Write the circuit of this seed as a TUMFTM racetrack CSV (`# x_m,y_m,w_tr_right_m,w_tr_left_m`, the loop's
    samples without the repeated last one, every value as Python's shortest exact repr) that `make_scenario` and
    every command read as a waypoint file; returns the path. The track widths need the vehicle's width (m)."""
    if vehicle_width_m is None:
        raise WorkbenchInputError(
            "write_circuit_file: a TUMFTM track file carries the track's widths, which are sized for the vehicle: "
            "give vehicle_width_m (m); got None"
        )
    ref = generate_circuit(seed, ranges, vehicle_width_m).path
    width = repr(float(ranges.side_width_m(vehicle_width_m)))
    text = "# x_m,y_m,w_tr_right_m,w_tr_left_m\n" + "".join(
        f"{float(x)!r},{float(y)!r},{width},{width}\n" for x, y in zip(ref.x_m[:-1], ref.y_m[:-1], strict=True)
    )
    out = Path(path)
    try:
        out.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise WorkbenchInputError(f"write_circuit_file: cannot write {str(out)!r} ({exc})") from None
    return out


__all__ = [
    "CIRCUIT_PREFIX",
    "DEFAULT_RANGES",
    "Circuit",
    "CircuitRanges",
    "circuit_family_description",
    "circuit_name",
    "circuit_seed",
    "draw_circuit",
    "generate_circuit",
    "least_clearance_m",
    "write_circuit_file",
]
