"""Lead-filter scaling for studies: the clothoid controller's lead filter (Eq. 6) with its zero and pole frequencies
multiplied by factors, written as a lead-filter file the controller reads (`filter_file`).

lead_filter_zero_scale multiplies omega_z (the zeros, placed on the steering lag's poles: > 1 assumes a faster lag)
and lead_filter_pole_scale multiplies omega_p (the triple pole: > 1 more lead, more high-frequency gain); both by
the same factor scale the filter along the frequency axis. Every entry of a speed schedule is scaled alike; psi is
kept. The base is the run's `filter_file`, or without one the steered vehicle's own schedule (the filter the
controller would use), or DEFAULT_FILTER when neither is known. A scaled filter that
Eq. 6 does not allow (omega_p / omega_z outside [1, 100], a frequency outside [0.01, 1000] rad/s) is refused with
WorkbenchInputError, which makes that run an error.
"""

from __future__ import annotations

from pathlib import Path

from controllers.clothoid.filter_file import DEFAULT_FILTER, FilterSchedule, read_filter_file, write_filter_file
from controllers.clothoid.lead_filter import LeadFilterParams
from workbench.errors import WorkbenchInputError, require_positive, value_text


def scale_schedule(schedule: FilterSchedule, zero_scale: float = 1.0, pole_scale: float = 1.0) -> FilterSchedule:
    """The schedule with every filter's omega_z times zero_scale and omega_p times pole_scale."""
    require_positive("lead_filter_zero_scale", zero_scale)
    require_positive("lead_filter_pole_scale", pole_scale)
    try:
        params = tuple(
            LeadFilterParams(p.omega_z_rad_s * zero_scale, p.psi, p.omega_p_rad_s * pole_scale) for p in schedule.params
        )
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(
            f"lead_filter_zero_scale = {value_text(zero_scale)}, lead_filter_pole_scale = {value_text(pole_scale)} "
            f"give a filter Eq. 6 does not allow: {exc}"
        ) from None
    return FilterSchedule(schedule.speeds_kmh, params, schedule.source)


def write_scaled_filter(
    out_path: str | Path,
    base_file: Path | None,
    zero_scale: float = 1.0,
    pole_scale: float = 1.0,
    base_schedule: FilterSchedule | None = None,
) -> Path:
    """Write the filter of `base_file` (None: base_schedule, the vehicle's own; both None: DEFAULT_FILTER) scaled as
    `scale_schedule` does to out_path (.json or .toml); return the path."""
    if base_file is not None:
        base, name = read_filter_file(base_file), str(base_file)
    elif base_schedule is not None:
        base, name = base_schedule, f"the vehicle's own lead filter ({base_schedule.source or 'its tuning'})"
    else:
        base, name = FilterSchedule.single(DEFAULT_FILTER), "the default lead filter"
    scaled = scale_schedule(base, zero_scale, pole_scale)
    source = f"{name} with omega_z x {zero_scale!r} and omega_p x {pole_scale!r} (workbench studies)"
    if len(scaled.params) == 1:
        return write_filter_file(out_path, scaled.params[0], source=source)
    return write_filter_file(out_path, scaled, source=source)


__all__ = ["scale_schedule", "write_scaled_filter"]
