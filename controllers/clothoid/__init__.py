"""The clothoid-based lateral controller of Shaju, Southward & Ahmadian (2024): per-step hyper-clothoid
(`clothoid_fit`), Fréchet-distance adaptive lookahead (`frechet`, `lookahead`), curvature limits
(`curvature_limits`) and lead filter (`lead_filter`; against speed, `filter_schedule`), put together in
`controller`.

The names below load their module when first used (PEP 562), so that importing one light module of the package
(a filter schedule, say) does not load the compiled step and its numba cache.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: Each public name and the module that defines it.
_HOMES = {
    "ClothoidFit": "clothoid_fit",
    "fit_hyper_clothoid": "clothoid_fit",
    "ClothoidConfig": "controller",
    "ClothoidController": "controller",
    "CurvatureLimits": "curvature_limits",
    "DEFAULT_FILTER": "filter_schedule",
    "FilterSchedule": "filter_schedule",
    "discrete_frechet": "frechet",
    "DiscreteLeadFilter": "lead_filter",
    "LeadFilterParams": "lead_filter",
}

__all__ = [
    "DEFAULT_FILTER",
    "ClothoidConfig",
    "ClothoidController",
    "ClothoidFit",
    "CurvatureLimits",
    "DiscreteLeadFilter",
    "FilterSchedule",
    "LeadFilterParams",
    "discrete_frechet",
    "fit_hyper_clothoid",
]

if TYPE_CHECKING:
    from controllers.clothoid.clothoid_fit import ClothoidFit, fit_hyper_clothoid
    from controllers.clothoid.controller import ClothoidConfig, ClothoidController
    from controllers.clothoid.curvature_limits import CurvatureLimits
    from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
    from controllers.clothoid.frechet import discrete_frechet
    from controllers.clothoid.lead_filter import DiscreteLeadFilter, LeadFilterParams


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value
    return value
