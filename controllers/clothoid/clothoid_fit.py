"""The per-step hyper-clothoid of the clothoid controller (paper, section 2, Eq. 3): one clothoid segment from the
vehicle's rear-axle pose to a target point, solved by a compiled, damped Newton iteration.

The curve: kappa(s) = kappa0 + kdot s, theta(s) = theta0 + kappa0 s + kdot s^2 / 2, points (x0, y0) + int_0^s
(cos theta, sin theta), from the rear axle with the vehicle's heading and curvature (Eq. 3's x(0), y(0), psi(0),
kappa(0)); the unknowns kdot (1/m^2) and L (m) put its end on the target. kdot is saturated at +-kdot_max; a
saturated clothoid ends as close as it can, and the controller checks the residual against Eq. 3's tolerances
(`ClothoidFit.end_error_m`).

The method, in the start frame: the end point and its Jacobian by Gauss-Legendre quadrature (the rule chosen so
that end points are exact to rounding); damped Newton from a small-angle guess (bounded heading change, L > 0,
Armijo backtracking), failing after 30 iterations, a line search that cannot descend, or 3 steps in a row that
barely reduce the residual (no clothoid through the target). A saturated kdot leaves a 1-D search for L.

Status codes (the fifth value `fit_kernel` returns, and `ClothoidFit.status`):
    FIT_OK = 0          converged: the end point is on the target and |kdot| <= kdot_max.
    FIT_SATURATED = 1   kdot = +-kdot_max exactly; L > 0 a local minimiser of the end point's distance to the target.
    FIT_UNREACHABLE = 2 the target is behind or beside the start (bearing |phi| > 100 deg), at the start, or
                        unreachable, or the saturated search failed: a finite fallback, kdot = sign(phi) kdot_max,
                        L = distance. Non-finite inputs give kdot = L = 0 and the start point.

Why not pyclothoids at run time: `pyclothoids.Clothoid.Forward` (Bertolazzi & Frego), the tests' reference for the
same boundary problem without the rate limit, cannot be called from the compiled lookahead search, is slower from
Python, and returns degenerate answers for targets behind or beside the start or that no clothoid reaches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError, value_text

FIT_OK = 0
FIT_SATURATED = 1
FIT_UNREACHABLE = 2

#: Targets at a bearing beyond this (in the start frame) are behind or beside the vehicle: no useful clothoid.
MAX_BEARING_RAD = math.radians(100.0)
#: Targets closer than this to the start are "at the start".
MIN_DISTANCE_M = 1e-6
#: Cap on panels per integral, so absurd inputs (kdot_max L^2 ~ 1e18) still cost bounded time (768 nodes); the
#: quadrature is exact up to a turn of 4 rad x MAX_PANELS = 256 rad (~40 full turns), and finite beyond.
MAX_PANELS = 64
#: Candidate clothoids turning more than this (the bound max |theta'| L; ~10 full turns) are rejected by both
#: searches: no vehicle follows them, and they would make each evaluation expensive.
MAX_FIT_TURN_RAD = 64.0
#: Newton: stop below TIGHT_TOL * max(1, d); accept as converged below ACCEPT_TOL * max(1, d).
TIGHT_TOL = 1e-12
ACCEPT_TOL = 1e-10
MAX_NEWTON_ITERATIONS = 30
MAX_LINE_SEARCH_HALVINGS = 10
#: Newton gives up after STALL_STEPS steps in a row that each cut the residual by less than 1 - STALL_RATIO: it is
#: sliding into a local minimum of |F - target| > 0 (no clothoid reaches the target; converging fits never do this).
STALL_RATIO = 0.9
STALL_STEPS = 3
#: Largest change of the end heading one Newton step may make (rad), so it stays on the branch it starts on.
MAX_STEP_TURN_RAD = 1.5


def _gauss_legendre_rules(sizes: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes and weights on [0, 1] of the Gauss-Legendre rules of these sizes, concatenated, and their offsets."""
    nodes, weights = zip(*(np.polynomial.legendre.leggauss(m) for m in sizes), strict=True)
    offsets = np.concatenate(([0], np.cumsum(sizes))).astype(np.int64)
    return 0.5 * (np.concatenate(nodes) + 1.0), 0.5 * np.concatenate(weights), offsets


#: Quadrature rules (node counts) and the largest heading change (rad) each integrates across one panel to a
#: relative error below ~1e-14 (measured for every heading whose rate |theta'| stays under turn / panel length).
#: The integrand exp(i theta(s)) is entire, so a rule's error falls super-exponentially as the turn shrinks.
RULE_SIZES = (4, 5, 6, 8, 10, 12)
RULE_MAX_TURN_RAD = (0.01, 0.05, 0.2, 1.0, 2.5, 4.0)
GL_NODES, GL_WEIGHTS, GL_OFFSETS = _gauss_legendre_rules(RULE_SIZES)
_RULE_TURNS = np.array(RULE_MAX_TURN_RAD)
#: Integrals turning up to this much are exact (MAX_PANELS panels of the largest rule); beyond, merely finite.
EXACT_TURN_RAD = RULE_MAX_TURN_RAD[-1] * MAX_PANELS
_N_RULES = len(RULE_SIZES)


#: Within a panel whose heading turns at most this (rad), a node's cos and sin relative to the panel's start come
#: from their Taylor series (to the 8th and 9th power: truncated below 3e-20), else from math.cos and math.sin.
SERIES_MAX_TURN_RAD = 0.05


@njit(cache=True)
def _cis_series(d: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos d, sin d) for |d| <= SERIES_MAX_TURN_RAD, by their Taylor series (Horner in d^2)."""
    d2 = d * d
    c = 1.0 + d2 * (-1.0 / 2.0 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))))
    sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 * (1.0 / 362880.0)))))
    return c, sn


@njit(cache=True)
def _rule(turn: float) -> int:  # pragma: no cover - compiled
    """The smallest quadrature rule exact for a panel turning `turn` (rad); the largest beyond them all."""
    rule = 0
    while rule < _N_RULES - 1 and not turn <= _RULE_TURNS[rule]:
        rule += 1
    return rule


@njit(cache=True)
def _panel(
    kappa0: float, kdot: float, a: float, h: float, rule: int, series: bool, with_jacobian: bool
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """One panel [a, a + h] of `_integrate` by rule `rule`: its start's direction (one cos and sin) turned by each
    node's heading change from there, which on a gently turning panel (`series`: at most SERIES_MAX_TURN_RAD)
    comes from `_cis_series`, not from a cos and sin."""
    th_a = a * (kappa0 + 0.5 * kdot * a)
    ca = math.cos(th_a)
    sa = math.sin(th_a)
    k_a = kappa0 + kdot * a
    pc = 0.0  # sums over the nodes in the panel's start frame: w (cos, sin) and w s^2 / 2 (cos, sin)
    ps = 0.0
    qc = 0.0
    qs = 0.0
    for j in range(GL_OFFSETS[rule], GL_OFFSETS[rule + 1]):
        u = h * GL_NODES[j]
        turned = u * (k_a + 0.5 * kdot * u)  # theta(a + u) - theta(a)
        if series:
            c, sn = _cis_series(turned)
        else:
            c = math.cos(turned)
            sn = math.sin(turned)
        w = GL_WEIGHTS[j]
        pc += w * c
        ps += w * sn
        if with_jacobian:
            s = a + u
            q = w * 0.5 * s * s
            qc += q * c
            qs += q * sn
    return (ca * pc - sa * ps) * h, (sa * pc + ca * ps) * h, -(sa * qc + ca * qs) * h, (ca * qc - sa * qs) * h


@njit(cache=True)
def _integrate(
    kappa0: float, kdot: float, a: float, b: float, with_jacobian: bool
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """int_a^b (cos, sin) theta(s) ds and, if asked, int_a^b (s^2 / 2) (-sin, cos) theta(s) ds (start frame).

    The heading turns at most `turn` = max |theta'| (b - a) across [a, b] (|theta'| is linear in s): the smallest
    rule that is exact for that turn, on one panel; beyond the largest rule's turn, panels of it (`_panel`)."""
    rate = max(abs(kappa0 + kdot * a), abs(kappa0 + kdot * b))
    turn = rate * (b - a)
    rule = _rule(turn)
    n_p = 1
    if not turn <= _RULE_TURNS[rule]:
        limit = _RULE_TURNS[rule] * MAX_PANELS
        n_p = math.ceil(turn / _RULE_TURNS[rule]) if turn < limit else MAX_PANELS  # also catches inf / NaN
    h = (b - a) / n_p
    series = turn / n_p <= SERIES_MAX_TURN_RAD  # a node's heading change from its panel's start is at most this
    fx = fy = gx = gy = 0.0
    for p in range(n_p):
        px, py, qx, qy = _panel(kappa0, kdot, a + p * h, h, rule, series, with_jacobian)
        fx += px
        fy += py
        gx += qx
        gy += qy
    return fx, fy, gx, gy


@njit(cache=True)
def _turn_bound(kappa0: float, kdot: float, length: float) -> float:  # pragma: no cover - compiled
    """max |theta'| L over [0, L]: a bound on how far the heading turns (rad)."""
    return max(abs(kappa0), abs(kappa0 + kdot * length)) * length


@njit(cache=True)
def _newton(
    kappa0: float, u: float, v: float, d: float, kdot: float, length: float
) -> tuple[float, float, float, float, bool]:  # pragma: no cover - compiled
    """Damped Newton for F(kdot, L) = (u, v): (kdot, L, Fx, Fy, converged)."""
    scale = max(1.0, d)
    if not _turn_bound(kappa0, kdot, length) <= MAX_FIT_TURN_RAD:
        return kdot, length, 0.0, 0.0, False
    fx, fy, gx, gy = _integrate(kappa0, kdot, 0.0, length, True)
    rx, ry = fx - u, fy - v
    r = math.hypot(rx, ry)
    stall = 0
    for _ in range(MAX_NEWTON_ITERATIONS):
        if r <= TIGHT_TOL * scale:
            return kdot, length, fx, fy, True
        th = length * (kappa0 + 0.5 * kdot * length)
        c = math.cos(th)
        sn = math.sin(th)
        # J = [[gx, c], [gy, sn]] acting on (d kdot, d L); solve J step = -r.
        det = gx * sn - gy * c
        if det == 0.0 or not math.isfinite(det):
            break
        dk = (-rx * sn + ry * c) / det
        dl = (-gx * ry + gy * rx) / det
        if not (math.isfinite(dk) and math.isfinite(dl)):
            break
        alpha = 1.0
        if length + dl <= 0.0:  # keep L > 0: at most halve it
            alpha = 0.5 * length / -dl
        kappa_end = abs(kappa0 + kdot * length)
        turn = abs(dk) * 0.5 * length * length + kappa_end * abs(dl)
        if alpha * turn > MAX_STEP_TURN_RAD:
            alpha = MAX_STEP_TURN_RAD / turn
        accepted = False
        for _ in range(MAX_LINE_SEARCH_HALVINGS):
            k_t = kdot + alpha * dk
            l_t = length + alpha * dl
            if not _turn_bound(kappa0, k_t, l_t) <= MAX_FIT_TURN_RAD:
                alpha *= 0.5
                continue
            fx_t, fy_t, gx_t, gy_t = _integrate(kappa0, k_t, 0.0, l_t, True)
            rx_t, ry_t = fx_t - u, fy_t - v
            r_t = math.hypot(rx_t, ry_t)
            if r_t <= (1.0 - 1e-4 * alpha) * r:
                stall = stall + 1 if r_t > STALL_RATIO * r else 0
                kdot, length = k_t, l_t
                fx, fy, gx, gy = fx_t, fy_t, gx_t, gy_t
                rx, ry, r = rx_t, ry_t, r_t
                accepted = True
                break
            if r <= ACCEPT_TOL * scale:  # at the rounding floor already: no need to search further
                break
            alpha *= 0.5
        if not accepted or stall >= STALL_STEPS:
            break
    return kdot, length, fx, fy, r <= ACCEPT_TOL * scale and length > 0.0


@njit(cache=True)
def _closest_length(
    kappa0: float, kdot: float, u: float, v: float, d: float, length: float
) -> tuple[float, float, float, bool]:  # pragma: no cover - compiled
    """With kdot fixed, a local minimiser L > 0 of |F(L) - (u, v)|, reached by descending from `length`:
    (L, Fx, Fy, converged)."""
    scale = max(1.0, d)
    if not _turn_bound(kappa0, kdot, length) <= MAX_FIT_TURN_RAD:
        return length, 0.0, 0.0, False
    fx, fy, _, _ = _integrate(kappa0, kdot, 0.0, length, False)
    ex, ey = fx - u, fy - v
    e2 = ex * ex + ey * ey
    for _ in range(MAX_NEWTON_ITERATIONS):
        th = length * (kappa0 + 0.5 * kdot * length)
        c = math.cos(th)
        sn = math.sin(th)
        h = ex * c + ey * sn  # (F - T) . t(L): half the derivative of the squared distance
        hp = 1.0 + (kappa0 + kdot * length) * (-ex * sn + ey * c)
        if abs(h) <= TIGHT_TOL * scale:
            return length, fx, fy, hp > 0.0
        dl = -h / max(hp, 1e-3)  # Newton where convex; else downhill, as far as the turn cap below allows
        alpha = 1.0
        if length + dl <= 0.0:
            alpha = 0.5 * length / -dl
        # The longest move x along the curve that turns it by at most MAX_STEP_TURN_RAD: |kappa| x + |kdot| x^2 / 2.
        kappa_abs = abs(kappa0 + kdot * length)
        denominator = kappa_abs + math.sqrt(kappa_abs**2 + 2.0 * abs(kdot) * MAX_STEP_TURN_RAD)
        if denominator > 0.0:  # (a straight line never turns)
            alpha = min(alpha, 2.0 * MAX_STEP_TURN_RAD / denominator / abs(dl))
        accepted = False
        for _ in range(MAX_LINE_SEARCH_HALVINGS):
            l_t = length + alpha * dl
            if not _turn_bound(kappa0, kdot, l_t) <= MAX_FIT_TURN_RAD:
                alpha *= 0.5
                continue
            fx_t, fy_t, _, _ = _integrate(kappa0, kdot, 0.0, l_t, False)
            ex_t, ey_t = fx_t - u, fy_t - v
            e2_t = ex_t * ex_t + ey_t * ey_t
            th_t = l_t * (kappa0 + 0.5 * kdot * l_t)
            h_t = ex_t * math.cos(th_t) + ey_t * math.sin(th_t)
            # Armijo on the squared distance (h dl < 0) or, where convex, a halving of the stationarity residual
            # (near the minimum the distance's decrease, ~h^2, drowns in its rounding).
            if e2_t <= e2 + 1e-4 * alpha * 2.0 * h * dl or (hp > 0.0 and abs(h_t) <= 0.5 * abs(h)):
                length, fx, fy, ex, ey, e2 = l_t, fx_t, fy_t, ex_t, ey_t, e2_t
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            # Rounding stalls the descent at a minimum: accept a stationary point that is small relative to d.
            return length, fx, fy, abs(h) <= ACCEPT_TOL * scale and hp > 0.0
    th = length * (kappa0 + 0.5 * kdot * length)
    h = ex * math.cos(th) + ey * math.sin(th)
    return length, fx, fy, abs(h) <= ACCEPT_TOL * scale


@njit(cache=True)
def _initial_guess(kappa0: float, d: float, phi: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """Small-angle (kdot, L) for a target at distance d and bearing phi: the end point of a gently turning curve
    lies at the bearing of its mean heading, kappa0 L / 2 + kdot L^2 / 6, and at the distance
    L (1 - var(theta) / 2), var over s uniform on [0, L]; two rounds of that fixed point."""
    length = d
    for _ in range(2):
        a = kappa0
        b = 3.0 * (phi - 0.5 * kappa0 * length) / (length * length)  # kdot / 2
        var = a * a * length**2 / 12.0 + a * b * length**3 / 6.0 + b * b * 4.0 * length**4 / 45.0
        length = d / max(1.0 - 0.5 * var, 0.5)
    return 6.0 * (phi - 0.5 * kappa0 * length) / (length * length), length


@njit(cache=True)
def fit_kernel(
    x0: float, y0: float, theta0: float, kappa0: float, x1: float, y1: float, kdot_max: float
) -> tuple[float, float, float, float, int]:  # pragma: no cover - compiled
    """The hyper-clothoid from (x0, y0, theta0, kappa0) to (x1, y1) with |kdot| <= kdot_max.

    Returns (kdot 1/m^2, length m, end_x m, end_y m, status FIT_OK / FIT_SATURATED / FIT_UNREACHABLE); finite for
    any finite input (non-finite inputs give status FIT_UNREACHABLE and kdot = length = 0)."""
    if not (
        math.isfinite(x0) and math.isfinite(y0) and math.isfinite(theta0) and math.isfinite(kappa0)
        and math.isfinite(x1) and math.isfinite(y1) and math.isfinite(kdot_max)
    ):  # fmt: skip
        return 0.0, 0.0, x0, y0, FIT_UNREACHABLE
    kdot_max = max(kdot_max, 0.0)
    c0 = math.cos(theta0)
    s0 = math.sin(theta0)
    dx = x1 - x0
    dy = y1 - y0
    u = c0 * dx + s0 * dy  # target in the start frame
    v = -s0 * dx + c0 * dy
    d = math.hypot(u, v)
    if not math.isfinite(d):  # the coordinates' difference overflows (|x1 - x0| > 1.8e308): nothing to fit
        return 0.0, 0.0, x0, y0, FIT_UNREACHABLE
    phi = math.atan2(v, u)
    sign_phi = 1.0 if phi > 0.0 else (-1.0 if phi < 0.0 else 0.0)

    status = FIT_UNREACHABLE
    kdot = sign_phi * kdot_max
    length = d
    fx = 0.0
    fy = 0.0
    if d >= MIN_DISTANCE_M and abs(phi) <= MAX_BEARING_RAD:
        k_guess, l_guess = _initial_guess(kappa0, d, phi)
        k_n, l_n, fx_n, fy_n, ok = _newton(kappa0, u, v, d, k_guess, l_guess)
        if ok and abs(k_n) <= kdot_max:
            kdot, length, fx, fy, status = k_n, l_n, fx_n, fy_n, FIT_OK
        elif ok:  # the exact solution needs more than kdot_max: clip it, get as close as the clipped rate allows
            k_s = kdot_max if k_n > 0.0 else -kdot_max
            l_s, fx_s, fy_s, ok_s = _closest_length(kappa0, k_s, u, v, d, d)
            if ok_s and l_s > 0.0:
                kdot, length, fx, fy, status = k_s, l_s, fx_s, fy_s, FIT_SATURATED
    # The fallback's own end point, where the quadrature is exact; for absurd clothoids (turning more than
    # EXACT_TURN_RAD, ~40 full turns) the start stands in for it, so coordinates near the float limit cannot overflow.
    if status == FIT_UNREACHABLE and length > 0.0 and _turn_bound(kappa0, kdot, length) <= EXACT_TURN_RAD:
        fx, fy, _, _ = _integrate(kappa0, kdot, 0.0, length, False)
    return kdot, length, x0 + c0 * fx - s0 * fy, y0 + s0 * fx + c0 * fy, status


@njit(cache=True)
def sample_kernel(
    x0: float,
    y0: float,
    theta0: float,
    kappa0: float,
    kdot: float,
    length: float,
    n: int,
    out_x: np.ndarray,
    out_y: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Write n points of the clothoid, evenly spaced in arc length from s = 0 to s = length inclusive, into
    out_x[:n], out_y[:n]: each interval integrated by the same panelled quadrature, accumulated."""
    if n <= 0:
        return
    out_x[0] = x0
    out_y[0] = y0
    if n == 1:
        return
    c0 = math.cos(theta0)
    s0 = math.sin(theta0)
    h = length / (n - 1)
    # No interval turns more than the whole curve's steepest heading rate over h: when that rule is exact on one
    # panel, every interval is one panel of it, chosen once.
    turn = max(abs(kappa0), abs(kappa0 + kdot * length)) * h
    rule = _rule(turn)
    one_panel = turn <= _RULE_TURNS[rule]
    series = turn <= SERIES_MAX_TURN_RAD
    fx = 0.0
    fy = 0.0
    for k in range(n - 1):
        a = k * h
        b = length if k == n - 2 else (k + 1) * h
        if one_panel:
            ix, iy, _, _ = _panel(kappa0, kdot, a, b - a, rule, series, False)
        else:
            ix, iy, _, _ = _integrate(kappa0, kdot, a, b, False)
        fx += ix
        fy += iy
        out_x[k + 1] = x0 + c0 * fx - s0 * fy
        out_y[k + 1] = y0 + s0 * fx + c0 * fy


@dataclass(frozen=True, slots=True)
class ClothoidFit:
    """One hyper-clothoid from a start pose towards a target (`fit_hyper_clothoid`), and how the fit ended."""

    curvature_rate_1pm2: float  # 1/m^2; kdot, the curvature's rate along the arc, within +-the bound fitted with
    length_m: float  # m, >= 0; the arc length
    end_x_m: float  # m; x of the end point, in the coordinates the start and the target were given in
    end_y_m: float  # m; y of the end point, in that frame
    status: int  # FIT_OK (0, on the target), FIT_SATURATED (1, kdot at its bound) or FIT_UNREACHABLE (2)

    @property
    def saturated(self) -> bool:
        """kdot was clipped to +-kdot_max: the end point misses the target by `end_error_m`."""
        return self.status == FIT_SATURATED

    @property
    def reachable(self) -> bool:
        """The target is ahead enough for a clothoid (status FIT_OK or FIT_SATURATED)."""
        return self.status != FIT_UNREACHABLE

    def end_error_m(self, x1: float, y1: float) -> float:
        """Distance (m) from the clothoid's end point to (x1, y1).

        Parameters
        ----------
        x1 : float, m
            The target's x, in the frame of the fit.
        y1 : float, m
            The target's y, in the frame of the fit.

        Returns
        -------
        float, m
            The distance, >= 0: zero to rounding for a converged fit, the residual of a saturated one.
        """
        return math.hypot(self.end_x_m - x1, self.end_y_m - y1)


def _finite(name: str, value: object) -> float:
    try:
        number = float(value)  # type: ignore[arg-type]  # any object: what float() refuses is caught below
    except (TypeError, ValueError):
        raise WorkbenchInputError(f"{name} must be a finite number; got {value_text(value)}") from None
    if isinstance(value, bool) or not math.isfinite(number):
        raise WorkbenchInputError(f"{name} must be a finite number; got {value_text(value)}")
    return number


def fit_hyper_clothoid(
    x0: float, y0: float, theta0: float, kappa0: float, x1: float, y1: float, max_curvature_rate_1pm2: float
) -> ClothoidFit:
    """Fit the hyper-clothoid from the pose (x0, y0, theta0 rad) with curvature kappa0 (1/m) to the target (x1, y1)
    under |kdot| <= max_curvature_rate_1pm2; see the module docstring.

    Parameters
    ----------
    x0 : float, m
        The start point's x (the rear axle), finite.
    y0 : float, m
        The start point's y, finite.
    theta0 : float, rad
        The heading at the start, finite; counter-clockwise from the x axis.
    kappa0 : float, 1/m
        The curvature at the start, finite; positive turning left.
    x1 : float, m
        The target's x, finite.
    y1 : float, m
        The target's y, finite.
    max_curvature_rate_1pm2 : float, 1/m^2
        The bound on |kdot|, the curvature's rate along the arc, finite and > 0.

    Returns
    -------
    ClothoidFit
        kdot (1/m^2), length (m), end point (m) and status: FIT_OK (on the target), FIT_SATURATED (kdot at its
        bound, the end as close as it gets) or FIT_UNREACHABLE (target behind, beside or at the start: a finite
        fallback).

    Raises
    ------
    WorkbenchInputError
        An argument that is not a finite number, or max_curvature_rate_1pm2 <= 0.

    Examples
    --------
    From the origin, heading along x on a straight, to a target 10 m ahead and 1 m to the left:

    >>> from controllers.clothoid import fit_hyper_clothoid
    >>> fit = fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, 10.0, 1.0, max_curvature_rate_1pm2=1.0)
    >>> fit.status, round(fit.curvature_rate_1pm2, 5), round(fit.length_m, 3)
    (0, 0.00588, 10.09)

    With the rate bounded at 0.001 1/m^2 the clothoid saturates and ends short of the target:

    >>> fit = fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, 10.0, 1.0, max_curvature_rate_1pm2=0.001)
    >>> fit.saturated, round(fit.end_error_m(10.0, 1.0), 3)
    (True, 0.832)
    """
    args = {"x0": x0, "y0": y0, "theta0": theta0, "kappa0": kappa0, "x1": x1, "y1": y1}
    x0, y0, theta0, kappa0, x1, y1 = (_finite(name, value) for name, value in args.items())
    rate = _finite("max_curvature_rate_1pm2", max_curvature_rate_1pm2)
    if rate <= 0.0:
        raise WorkbenchInputError(
            f"max_curvature_rate_1pm2 must be a finite number > 0; got {value_text(max_curvature_rate_1pm2)}"
        )
    kdot, length, ex, ey, status = fit_kernel(x0, y0, theta0, kappa0, x1, y1, rate)
    return ClothoidFit(float(kdot), float(length), float(ex), float(ey), int(status))


def clothoid_points(
    x0: float, y0: float, theta0: float, kappa0: float, kdot: float, length: float, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """n points (x, y) of the clothoid, evenly spaced in arc length over [0, length], both ends included."""
    args = {"x0": x0, "y0": y0, "theta0": theta0, "kappa0": kappa0, "kdot": kdot, "length": length}
    x0, y0, theta0, kappa0, kdot, arc_length = (_finite(name, value) for name, value in args.items())
    if arc_length < 0.0:
        raise WorkbenchInputError(f"length must be >= 0 m; got {value_text(length)}")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise WorkbenchInputError(f"n must be an integer >= 1; got {value_text(n)}")
    x = np.empty(int(n))
    y = np.empty(int(n))
    sample_kernel(x0, y0, theta0, kappa0, kdot, arc_length, int(n), x, y)
    return x, y
