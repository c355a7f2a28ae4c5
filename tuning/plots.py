"""The tuning figures: Figure 6 (rollover curvature limits), Figure 8 (lag fit), Figure 9 (time-domain validation of
the lead filter), Figure 10 (Bode of plant, compensator and cascade), the schedule against speed, and the clothoid
loop's margins against lookahead (`tuning margins`).

Each function draws one figure, writes it to `path` (PNG, or any format matplotlib knows by suffix) and returns
the path. Axis labels give their unit in parentheses, "time (s)", as the run figures do (`workbench.simulation.plots`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from tuning.lag_fit import LagFit
from tuning.lead_design import LeadDesign, ValidationTrace
from tuning.margins import MarginResult
from tuning.rollover import RolloverLimit
from tuning.schedule import ScheduleResult
from workbench.base.errors import WorkbenchInputError


def _save(fig: plt.Figure, path: str | Path) -> Path:
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=120)
    except (OSError, ValueError) as exc:
        raise WorkbenchInputError(f"cannot write the plot {str(path)!r}: {exc}") from None
    finally:
        plt.close(fig)
    return path


def lag_fit_figure(fit: LagFit, path: str | Path) -> Path:
    """Figure 8: per log, the kinematic, the actual (measured) and the kinematic-with-lag curvature against time."""
    n = len(fit.logs)
    fig, axes = plt.subplots(n, 1, figsize=(9, 3.2 * n), layout="constrained", squeeze=False)
    lag = fit.lag
    label = f"kinematic with lag (ωn {lag.omega_n_rad_s:.2f} rad/s, ζ {lag.zeta:.2f}"
    label += f", delay {lag.delay_s:.3f} s" if lag.delay_s > 0 else ""
    label += f", K {fit.gain:.3f})" if abs(fit.gain - 1.0) > 1e-12 else ")"
    for ax, log in zip(axes[:, 0], fit.logs, strict=True):
        ax.plot(log.t_s, log.kinematic_1pm, "k--", lw=1.0, label="kinematic (Ackermann)")
        ax.plot(log.t_s, log.measured_1pm, lw=1.6, label=f"actual (from {log.curvature_from})")
        ax.plot(log.t_s, log.modelled_1pm, ":", lw=2.0, label=label)
        ax.set_title(f"{log.name}: NRMSE {log.nrmse:.4f}")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("curvature (1/m)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)


def bode_figure(design: LeadDesign, path: str | Path) -> Path:
    """Figure 10: magnitude and phase of the plant (Eq. 5), the compensator (Eq. 6) and the cascade."""
    wn = design.lag.omega_n_rad_s
    omega = np.logspace(np.log10(wn) - 2.0, np.log10(design.params.omega_p_rad_s) + 1.5, 800)
    response = design.frequency_response(omega)
    fig, (mag_ax, phase_ax) = plt.subplots(2, 1, figsize=(8, 7), sharex=True, layout="constrained")
    styles = {"plant": ("C0", "-"), "compensator": ("C1", "--"), "cascade": ("C2", "-")}
    for name, (mag, phase) in response.items():
        color, style = styles[name]
        mag_ax.semilogx(omega, 20 * np.log10(mag), style, color=color, label=name)
        phase_ax.semilogx(omega, phase, style, color=color, label=name)
    for bw, color, name in (
        (design.plant_bandwidth_rad_s, "C0", "plant"),
        (design.cascade_bandwidth_rad_s, "C2", "cascade"),
    ):
        mag_ax.axvline(bw, color=color, lw=0.8, ls=":")
        mag_ax.annotate(f"{name} bandwidth {bw:.2f} rad/s", (bw, -3.0), fontsize=8, rotation=90, va="top")
    mag_ax.axhline(-3.0, color="grey", lw=0.6, ls=":")
    phase_ax.axvline(design.phase_frequency_rad_s, color="grey", lw=0.8, ls=":")
    phase_ax.annotate(
        f"{design.plant_phase_deg:.0f}° -> {design.cascade_phase_deg:.0f}° at {design.phase_frequency_rad_s:.2f} rad/s",
        (design.phase_frequency_rad_s, design.cascade_phase_deg),
        fontsize=8,
    )
    mag_ax.set_ylabel("magnitude (dB)")
    phase_ax.set_ylabel("phase (deg)")
    phase_ax.set_xlabel("frequency (rad/s)")
    p = design.params
    mag_ax.set_title(
        f"lead filter ωz {p.omega_z_rad_s:.2f} rad/s, ψ {p.psi:.2f}, ωp {p.omega_p_rad_s:.2f} rad/s "
        f"(peak gain {design.lead_peak_gain:.2g})"
    )
    for ax in (mag_ax, phase_ax):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)


def validation_figure(traces: Sequence[ValidationTrace], path: str | Path) -> Path:
    """Figure 9: per log, the kinematic, kinematic-with-lag and compensated curvature (and the measured one)."""
    n = len(traces)
    fig, axes = plt.subplots(n, 1, figsize=(9, 3.2 * n), layout="constrained", squeeze=False)
    for ax, tr in zip(axes[:, 0], traces, strict=True):
        ax.plot(tr.t_s, tr.kinematic_1pm, "k-", lw=1.2, label="kinematic")
        if tr.measured_1pm is not None:
            ax.plot(tr.t_s, tr.measured_1pm, color="C7", lw=1.0, alpha=0.8, label="actual (from the log)")
        ax.plot(tr.t_s, tr.lagged_1pm, "C0--", lw=1.4, label=f"kinematic with lag (NRMSE {tr.nrmse_lagged:.3f})")
        ax.plot(
            tr.t_s, tr.compensated_1pm, ":", color="m", lw=2.0, label=f"compensated (NRMSE {tr.nrmse_compensated:.3f})"
        )
        ax.set_title(tr.name)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("curvature (1/m)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)


def rollover_figure(limits: Sequence[RolloverLimit], path: str | Path, vehicle: str = "") -> Path:
    """Figure 6: the curvature limit against speed, marking the speeds limited by the steering lock."""
    fig, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    speeds = np.array([lim.speed_kmh for lim in limits])
    curv = np.array([lim.path_curvature_1pm for lim in limits])
    ax.plot(speeds, curv, "o-", label="path curvature at LTR = 1")
    lock = np.array([lim.limited_by == "steering lock" for lim in limits])
    if lock.any():
        ax.plot(speeds[lock], curv[lock], "s", color="C3", label="LTR < 1 at the steering lock (lock limit)")
    ax.set_xlabel("speed (km/h)")
    ax.set_ylabel("curvature limit (1/m)")
    ax.set_title(f"curvature saturation limits from step steers{f' ({vehicle})' if vehicle else ''}")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return _save(fig, path)


def schedule_figure(result: ScheduleResult, path: str | Path) -> Path:
    """The identified lag and the designed filter against speed."""
    rows = [e.row() for e in result.entries]
    speeds = [r["speed_kmh"] for r in rows]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, layout="constrained")
    a1.plot(speeds, [r["omega_n_rad_s"] for r in rows], "o-", label="ωn (lag)")
    a1.plot(speeds, [r["omega_z_rad_s"] for r in rows], "x:", label="ωz (filter)")
    a1.plot(speeds, [r["omega_p_rad_s"] for r in rows], "s-", label="ωp (filter)")
    a1.plot(speeds, [r["plant_bandwidth_rad_s"] for r in rows], "^--", label="plant bandwidth")
    a1.plot(speeds, [r["cascade_bandwidth_rad_s"] for r in rows], "v--", label="cascade bandwidth")
    a1.set_ylabel("frequency (rad/s)")
    a2.plot(speeds, [r["zeta"] for r in rows], "o-", label="ζ (lag)")
    a2.plot(speeds, [r["psi"] for r in rows], "x:", label="ψ (filter)")
    a2.plot(speeds, [r["steady_state_gain"] for r in rows], "s-", label="steady-state gain K")
    a2.set_xlabel("speed (km/h)")
    for ax in (a1, a2):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    a1.set_title(f"lead-filter schedule ({result.vehicle})")
    return _save(fig, path)


def margins_figure(result: MarginResult, path: str | Path) -> Path:
    """The clothoid loop's margins against lookahead per speed, the lookaheads the controller may use shaded
    (`MarginResult.plot`)."""
    fig = plt.figure(figsize=(9, 7), layout="constrained")
    result.plot(fig)
    return _save(fig, path)
