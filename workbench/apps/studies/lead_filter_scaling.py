"""Lead-filter scaling for studies: the clothoid controller's lead filter (Eq. 6) with its zero and pole frequencies
multiplied by factors: a `FilterSchedule` the run's config holds (`ClothoidConfig.lead_filter`), no file.

lead_filter_zero_scale multiplies omega_z (the zeros, placed on the steering lag's poles: > 1 assumes a faster lag)
and lead_filter_pole_scale multiplies omega_p (the triple pole: > 1 more lead, more high-frequency gain); both by
the same factor scale the filter along the frequency axis. Every entry of a speed schedule is scaled alike; psi is
kept. The base is the run's configured filter (`filter_file`), or without one the steered vehicle's own schedule
(the filter the controller would use), or DEFAULT_FILTER when neither is known. A scaled filter that
Eq. 6 does not allow (omega_p / omega_z outside [1, 100], a frequency outside [0.01, 1000] rad/s) is refused with
WorkbenchInputError, which makes that run an error.
"""

from __future__ import annotations

import dataclasses

from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from workbench.base.errors import WorkbenchInputError, require_positive, value_text


def scale_schedule(schedule: FilterSchedule, zero_scale: float = 1.0, pole_scale: float = 1.0) -> FilterSchedule:
    """The schedule with every filter's omega_z times zero_scale and omega_p times pole_scale.

    Parameters
    ----------
    schedule : FilterSchedule
        The lead filter per speed.
    zero_scale : float
        Factor on every filter's omega_z (the zeros), positive.
    pole_scale : float
        Factor on every filter's omega_p (the triple pole), positive.

    Returns
    -------
    FilterSchedule
        The same speeds and psi, the frequencies scaled.

    Raises
    ------
    WorkbenchInputError
        A scale not positive, or a scaled filter Eq. 6 does not allow (omega_p / omega_z outside [1, 100], a
        frequency outside [0.01, 1000] rad/s).
    """
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


def scaled_filter(
    configured: FilterSchedule | None,
    zero_scale: float = 1.0,
    pole_scale: float = 1.0,
    vehicle_schedule: FilterSchedule | None = None,
) -> FilterSchedule:
    """The run's lead filter (`configured`, else the vehicle's own `vehicle_schedule`, else DEFAULT_FILTER) scaled
    as `scale_schedule` does, its source saying so.

    Parameters
    ----------
    configured : FilterSchedule or None
        The run's configured lead filter (`ClothoidConfig.lead_filter`; None: none).
    zero_scale : float
        Factor on every filter's omega_z (the zeros), positive.
    pole_scale : float
        Factor on every filter's omega_p (the triple pole), positive.
    vehicle_schedule : FilterSchedule or None
        The steered vehicle's own schedule, the base without a configured filter (None: DEFAULT_FILTER).

    Returns
    -------
    FilterSchedule
        The scaled filter, its source naming the base and the factors.

    Raises
    ------
    WorkbenchInputError
        A scale not positive, or a scaled filter Eq. 6 does not allow (omega_p / omega_z outside [1, 100], a
        frequency outside [0.01, 1000] rad/s).
    """
    if configured is not None:
        base, name = configured, f"the configured lead filter ({configured.source or 'a filter file'})"
    elif vehicle_schedule is not None:
        base, name = vehicle_schedule, f"the vehicle's own lead filter ({vehicle_schedule.source or 'its tuning'})"
    else:
        base, name = FilterSchedule.single(DEFAULT_FILTER), "the default lead filter"
    scaled = scale_schedule(base, zero_scale, pole_scale)
    source = f"{name} with omega_z x {zero_scale!r} and omega_p x {pole_scale!r} (workbench studies)"
    return dataclasses.replace(scaled, source=source)


__all__ = ["scale_schedule", "scaled_filter"]
