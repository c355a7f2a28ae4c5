"""Savitzky-Golay derivatives as sparse matrices, so that one log's x, y and many model paths are differentiated
by the same operator cheaply.

`savgol_matrix(n, window, deriv, dt)` @ y equals scipy.signal.savgol_filter(y, window, order, deriv=deriv,
delta=dt, mode="interp"): interior rows hold the convolution coefficients; the first and last window // 2 rows
evaluate the derivative of the polynomial fitted to the first / last `window` samples.
"""

from __future__ import annotations

import numpy as np
from scipy import signal, sparse

from workbench.base.errors import WorkbenchInputError


def savgol_matrix(n: int, window: int, deriv: int, dt_s: float, order: int = 3) -> sparse.csr_matrix:
    """The n x n operator of savgol_filter(..., window, order, deriv, delta=dt_s, mode="interp")."""
    if window % 2 == 0 or window <= order or window > n:
        raise WorkbenchInputError(f"Savitzky-Golay window must be odd, > {order} and <= {n}; got {window}")
    half = window // 2
    centre = signal.savgol_coeffs(window, order, deriv=deriv, delta=dt_s, use="dot")
    interior = np.arange(half, n - half)
    rows = [np.repeat(interior, window)]
    cols = [(interior[:, None] + np.arange(-half, half + 1)[None, :]).ravel()]
    vals = [np.tile(centre, interior.size)]
    # Edges: y ~ sum_k a_k t^k fitted over t = 0..window-1 (a = pinv(V) y); row = d^deriv/dt^deriv t^k at the
    # sample's position, times pinv(V).
    t = np.arange(window, dtype=float)
    powers = np.arange(order + 1)
    fit = np.linalg.pinv(t[:, None] ** powers[None, :])

    def derivative_row(position: float) -> np.ndarray:
        factor = np.ones(order + 1)
        for j in range(deriv):
            factor *= powers - j
        exponent = np.maximum(powers - deriv, 0)
        return (factor * position**exponent) @ fit / dt_s**deriv

    for i in range(half):
        rows += [np.full(window, i), np.full(window, n - half + i)]
        cols += [np.arange(window), np.arange(n - window, n)]
        vals += [derivative_row(t[i]), derivative_row(t[half + 1 + i])]
    return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
