"""Tests for workbench.base.clothoid_chain: positions against an independent numerical integration of the analytic
heading, curvature and heading continuity, closure, and the builder's input errors.

Measured when written: positions agree with scipy.integrate.quad of cos/sin(theta0 + k0 s + dk s^2 / 2) to
5e-14 m over 119-180 m chains (asserted: 1e-6 m).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError

# A chain is given as its start (x, y, heading, curvature) and its pieces (end curvature, length); the tests build
# the ClothoidChain from this spec and compute every reference value from the spec alone.
Spec = tuple[tuple[float, float, float, float], list[tuple[float, float]]]

CHAINS: dict[str, Spec] = {
    "s-bend": ((0.0, 0.0, 0.0, 0.0), [(0.0, 40.0), (1 / 30, 20.0), (1 / 30, 30.0), (-1 / 30, 40.0), (0.0, 20.0)]),
    "offset-start": (
        (12.5, -7.25, 2.1, 0.01),
        [(0.05, 20.0), (0.05, 15.0), (-0.04, 30.0), (0.0, 10.0), (0.0, 20.0), (0.08, 12.0), (0.0, 12.0)],
    ),
    "tight": ((-3.0, 4.0, -0.7, -0.1), [(0.1, 25.0), (0.1, 40.0), (-0.05, 10.0), (0.0, 5.0), (0.0, 100.0)]),
}


def build(spec: Spec) -> ClothoidChain:
    (x0, y0, th0, k0), pieces = spec
    chain = ClothoidChain(x0, y0, th0, k0)
    for k_end, length in pieces:
        chain.clothoid_to(k_end, length)
    return chain


def analytic_profile(spec: Spec, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Heading and curvature at arc lengths s from the spec: theta0 + k0 u + dk u^2 / 2 within each piece."""
    (_, _, th0, k0), pieces = spec
    heading = np.empty_like(s)
    curvature = np.empty_like(s)
    start, theta, kappa = 0.0, th0, k0
    for i, (k_end, length) in enumerate(pieces):
        dk = (k_end - kappa) / length
        last = i == len(pieces) - 1
        mask = (s >= start) & ((s <= start + length) if last else (s < start + length))
        u = s[mask] - start
        heading[mask] = theta + kappa * u + 0.5 * dk * u**2
        curvature[mask] = kappa + dk * u
        theta += kappa * length + 0.5 * dk * length**2
        start += length
        kappa = k_end
    return heading, curvature


def piece_displacement(theta: float, kappa: float, dk: float, length: float) -> tuple[float, float]:
    """(dx, dy) over `length` of a piece with heading theta + kappa u + dk u^2 / 2, by adaptive quadrature."""

    def heading(u: float) -> float:
        return theta + kappa * u + 0.5 * dk * u * u

    opts = {"epsabs": 1e-13, "epsrel": 1e-13, "limit": 200}
    dx = quad(lambda u: math.cos(heading(u)), 0.0, length, **opts)[0]
    dy = quad(lambda u: math.sin(heading(u)), 0.0, length, **opts)[0]
    return dx, dy


def integrated_position(spec: Spec, s_targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x(s), y(s) by adaptive quadrature of cos/sin of the analytic heading, piece by piece."""
    (x0, y0, th0, k0), pieces = spec
    out_x = np.empty_like(s_targets)
    out_y = np.empty_like(s_targets)
    x, y, theta, kappa, start = x0, y0, th0, k0, 0.0
    piece = 0
    for j in np.argsort(s_targets):
        s = s_targets[j]
        # Advance over whole pieces that end before s.
        while piece < len(pieces) - 1 and s > start + pieces[piece][1]:
            k_end, length = pieces[piece]
            dk = (k_end - kappa) / length
            dx, dy = piece_displacement(theta, kappa, dk, length)
            x, y = x + dx, y + dy
            theta += kappa * length + 0.5 * dk * length**2
            start += length
            kappa = k_end
            piece += 1
        k_end, length = pieces[piece]
        dx, dy = piece_displacement(theta, kappa, (k_end - kappa) / length, s - start)
        out_x[j], out_y[j] = x + dx, y + dy
    return out_x, out_y


@pytest.mark.parametrize("name", list(CHAINS))
def test_positions_match_numerical_integration(name: str) -> None:
    spec = CHAINS[name]
    path = build(spec).to_path(name)
    total = sum(length for _, length in spec[1])
    assert path.length_m == pytest.approx(total, abs=1e-9)
    picks = np.unique(np.concatenate((np.arange(0, path.x_m.size, 7), [path.x_m.size - 1])))
    x_ref, y_ref = integrated_position(spec, path.s_m[picks])
    err = np.hypot(path.x_m[picks] - x_ref, path.y_m[picks] - y_ref)
    assert err.max() < 1e-6, f"position error {err.max():.2e} m"


@pytest.mark.parametrize("name", list(CHAINS))
def test_end_pose_matches_integration(name: str) -> None:
    spec = CHAINS[name]
    chain = build(spec)
    total = sum(length for _, length in spec[1])
    x_ref, y_ref = integrated_position(spec, np.array([total]))
    heading_ref, _ = analytic_profile(spec, np.array([total]))
    x, y, theta = chain.end_pose()
    assert math.hypot(x - x_ref[0], y - y_ref[0]) < 1e-6
    assert theta == pytest.approx(heading_ref[0], abs=1e-9)
    assert chain.length_m == pytest.approx(total, abs=1e-12)


@pytest.mark.parametrize("name", list(CHAINS))
def test_heading_and_curvature_are_analytic_and_continuous(name: str) -> None:
    spec = CHAINS[name]
    path = build(spec).to_path(name)
    heading_ref, kappa_ref = analytic_profile(spec, path.s_m)
    assert np.abs(path.heading_rad - heading_ref).max() < 1e-9
    assert np.abs(path.curvature_1pm - kappa_ref).max() < 1e-12

    (_, _, _, k0), pieces = spec
    kappas = [k0] + [k for k, _ in pieces]
    max_rate = max(abs(kappas[i + 1] - kappas[i]) / pieces[i][1] for i in range(len(pieces)))
    max_kappa = max(abs(k) for k in kappas)
    ds = path.spacing_m
    assert np.abs(np.diff(path.curvature_1pm)).max() <= max_rate * ds + 1e-12
    assert np.abs(np.diff(path.heading_rad)).max() <= max_kappa * ds + 1e-12
    # The heading also agrees with the direction of travel between samples: on a clothoid the chord's direction
    # differs from the mean of the end headings by -dk ds^2 / 12.
    chord = np.arctan2(np.diff(path.y_m), np.diff(path.x_m))
    mid = 0.5 * (path.heading_rad[:-1] + path.heading_rad[1:])
    assert np.abs((chord - mid + math.pi) % (2 * math.pi) - math.pi).max() <= max_rate * ds**2 / 12 * 1.001 + 1e-10


def test_spacing_is_uniform_and_close_to_requested() -> None:
    path = build(CHAINS["s-bend"]).to_path("s-bend", spacing_m=0.25)
    assert path.spacing_m == pytest.approx(0.25, abs=1e-12)  # 150 m / 0.25 m
    steps = np.hypot(np.diff(path.x_m), np.diff(path.y_m))
    # Chords of 0.25 m arcs with |kappa| <= 1/30: shorter than the arc by at most kappa^2 ds^3 / 24.
    assert np.all(steps <= 0.25 + 1e-12) and np.all(steps >= 0.25 - (1 / 30) ** 2 * 0.25**3 / 24 - 1e-12)


def test_closed_circle_chain() -> None:
    radius = 20.0
    chain = ClothoidChain(radius, 0.0, math.pi / 2, 1 / radius).arc(2 * math.pi * radius)
    path = chain.to_path("circle", closed=True)
    assert path.closed
    assert np.abs(np.hypot(path.x_m, path.y_m) - radius).max() < 1e-9
    assert path.length_m == pytest.approx(2 * math.pi * radius, rel=1e-12)
    assert path.heading_rad[-1] - path.heading_rad[0] == pytest.approx(2 * math.pi, abs=1e-12)


# ---------------------------------------------------------------------------------------------- bad input
def test_closed_chain_that_does_not_close() -> None:
    chain = ClothoidChain().straight(10.0).clothoid_to(0.1, 10.0).clothoid_to(0.0, 10.0)
    x, y, _ = chain.end_pose()
    gap = math.hypot(x, y)
    assert gap > 20.0
    expected = rf"hook: a closed chain must end at its start; the gap is {gap:.3g} m"
    with pytest.raises(WorkbenchInputError, match=expected):
        chain.to_path("hook", closed=True)


def test_closed_chain_with_a_heading_mismatch() -> None:
    # A circle that stops 0.001 rad short ends 2 cm from the start: the message reports the gap and the heading.
    radius = 20.0
    chain = ClothoidChain(radius, 0.0, math.pi / 2, 1 / radius).arc(2 * math.pi * radius - 0.02)
    with pytest.raises(WorkbenchInputError, match=r"the gap is 0\.02 m, the heading differs by -0\.001 rad"):
        chain.to_path("short circle", closed=True)


def test_straight_after_nonzero_curvature() -> None:
    chain = ClothoidChain().straight(10.0).clothoid_to(0.02, 10.0)
    expected = r"a straight must follow zero curvature; the chain ends at 0\.02 1/m"
    with pytest.raises(WorkbenchInputError, match=expected):
        chain.straight(5.0)
    with pytest.raises(WorkbenchInputError, match=r"ends at -0\.5 1/m"):
        ClothoidChain(curvature_1pm=-0.5).straight(1.0)


@pytest.mark.parametrize("length", [0.0, -5.0, math.nan, math.inf])
def test_bad_piece_length(length: float) -> None:
    with pytest.raises(WorkbenchInputError, match=rf"clothoid length_m must be a finite number > 0; got {length!r}"):
        ClothoidChain().clothoid_to(0.1, length)


def test_bad_curvature_and_start() -> None:
    with pytest.raises(WorkbenchInputError, match=r"clothoid end curvature must be finite numbers; entry 0 is nan"):
        ClothoidChain().clothoid_to(math.nan, 10.0)
    with pytest.raises(WorkbenchInputError, match=r"chain start must be finite numbers; entry 2 is inf"):
        ClothoidChain(0.0, 0.0, math.inf)


def test_empty_chain() -> None:
    with pytest.raises(WorkbenchInputError, match=r"empty: the chain has no pieces"):
        ClothoidChain().to_path("empty")
