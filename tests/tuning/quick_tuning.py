"""The shortened tuning chain the tuning tests generate a user vehicle's tuning with: the lag identified and the lead
filter designed at one speed, 40 km/h, and the limits at three, so that it takes seconds."""

from __future__ import annotations

import dataclasses

from tuning.preset_tuning import PRESET_TUNING_OPTIONS

QUICK = dataclasses.replace(PRESET_TUNING_OPTIONS, schedule_speeds_kmh=(40.0,), limits_speeds_kmh=(10.0, 50.0, 100.0))
