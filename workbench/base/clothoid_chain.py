"""Curvature-continuous paths built from straights, clothoids and arcs, evaluated exactly.

Each piece is one clothoid (curvature linear in arc length; straights and arcs are the cases dk/ds = 0) evaluated
with Bertolazzi's Clothoids library through pyclothoids, so positions are exact to machine precision rather than
integrated numerically. Heading and curvature are known in closed form: theta(s) = theta0 + k0 s + dk s^2 / 2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pyclothoids import Clothoid

from workbench.base.errors import WorkbenchInputError, require_finite, require_positive
from workbench.base.path import DEFAULT_SAMPLE_SPACING_M, ReferencePath


@dataclass(frozen=True)
class ChainPiece:
    """One piece of a chain: length (m), curvature at its start and end (1/m, left turn positive)."""

    length_m: float
    start_curvature_1pm: float
    end_curvature_1pm: float

    @property
    def curvature_rate_1pm2(self) -> float:
        return (self.end_curvature_1pm - self.start_curvature_1pm) / self.length_m


class ClothoidChain:
    """A builder: start at a pose and curvature, then append straights, clothoids and arcs.

    >>> path = ClothoidChain().straight(40).clothoid_to(1 / 30, 20).arc(30).to_path("demo")
    """

    def __init__(self, x_m: float = 0.0, y_m: float = 0.0, heading_rad: float = 0.0, curvature_1pm: float = 0.0):
        require_finite("chain start", [x_m, y_m, heading_rad, curvature_1pm])
        self.start = (float(x_m), float(y_m), float(heading_rad))
        self.start_curvature_1pm = float(curvature_1pm)
        self.pieces: list[ChainPiece] = []

    @property
    def end_curvature_1pm(self) -> float:
        return self.pieces[-1].end_curvature_1pm if self.pieces else self.start_curvature_1pm

    def clothoid_to(self, curvature_1pm: float, length_m: float) -> ClothoidChain:
        """Append a clothoid that takes the curvature linearly from its current value to `curvature_1pm`."""
        require_positive("clothoid length_m", length_m)
        require_finite("clothoid end curvature", [curvature_1pm])
        self.pieces.append(ChainPiece(float(length_m), self.end_curvature_1pm, float(curvature_1pm)))
        return self

    def arc(self, length_m: float) -> ClothoidChain:
        """Append a piece of constant curvature (the current one) of the given length."""
        return self.clothoid_to(self.end_curvature_1pm, length_m)

    def straight(self, length_m: float) -> ClothoidChain:
        """Append a straight; the curvature must already be zero (a jump would break curvature continuity)."""
        if abs(self.end_curvature_1pm) > 1e-12:
            raise WorkbenchInputError(
                f"a straight must follow zero curvature; the chain ends at {self.end_curvature_1pm} 1/m "
                "(add a clothoid_to(0, L) first)"
            )
        return self.clothoid_to(0.0, length_m)

    def _clothoids(self) -> list[Clothoid]:
        x, y, th = self.start
        out = []
        for piece in self.pieces:
            c = Clothoid.StandardParams(x, y, th, piece.start_curvature_1pm, piece.curvature_rate_1pm2, piece.length_m)
            out.append(c)
            x, y, th = c.XEnd, c.YEnd, c.ThetaEnd
        return out

    def end_pose(self) -> tuple[float, float, float]:
        """(x, y, heading) at the end of the chain."""
        if not self.pieces:
            return self.start
        last = self._clothoids()[-1]
        return last.XEnd, last.YEnd, last.ThetaEnd

    @property
    def length_m(self) -> float:
        return float(sum(p.length_m for p in self.pieces))

    def to_path(
        self, name: str, closed: bool = False, spacing_m: float = DEFAULT_SAMPLE_SPACING_M, closure_tol_m: float = 1e-6
    ) -> ReferencePath:
        """Sample the chain uniformly in arc length into a ReferencePath.

        closed=True requires the chain to end where it started, with the same heading (mod 2 pi) and curvature.
        """
        if not self.pieces:
            raise WorkbenchInputError(f"{name}: the chain has no pieces")
        clothoids = self._clothoids()
        if closed:
            x_end, y_end, th_end = clothoids[-1].XEnd, clothoids[-1].YEnd, clothoids[-1].ThetaEnd
            gap = np.hypot(x_end - self.start[0], y_end - self.start[1])
            turn = (th_end - self.start[2] + np.pi) % (2 * np.pi) - np.pi
            if gap > closure_tol_m or abs(turn) > 1e-6 or abs(self.end_curvature_1pm - self.start_curvature_1pm) > 1e-9:
                raise WorkbenchInputError(
                    f"{name}: a closed chain must end at its start; the gap is {gap:.3g} m, the heading differs by "
                    f"{turn:.3g} rad and the curvature by {self.end_curvature_1pm - self.start_curvature_1pm:.3g} 1/m"
                )
        total = self.length_m
        n = max(2, int(np.ceil(total / spacing_m)))
        s = np.linspace(0.0, total, n + 1)
        bounds = np.concatenate(([0.0], np.cumsum([p.length_m for p in self.pieces])))
        which = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, len(self.pieces) - 1)
        x = np.empty_like(s)
        y = np.empty_like(s)
        heading = np.empty_like(s)
        curvature = np.empty_like(s)
        th0 = self.start[2]
        for k, (piece, c) in enumerate(zip(self.pieces, clothoids, strict=True)):
            mask = which == k
            local = np.clip(s[mask] - bounds[k], 0.0, piece.length_m)
            x[mask] = [c.X(v) for v in local]
            y[mask] = [c.Y(v) for v in local]
            k0, dk = piece.start_curvature_1pm, piece.curvature_rate_1pm2
            heading[mask] = th0 + k0 * local + 0.5 * dk * local**2
            curvature[mask] = k0 + dk * local
            th0 = th0 + k0 * piece.length_m + 0.5 * dk * piece.length_m**2
        if closed:
            x[-1], y[-1] = x[0], y[0]
        return ReferencePath(x, y, heading, curvature, total / n, closed, name=name)
