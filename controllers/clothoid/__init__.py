"""The clothoid-based lateral controller of Shaju, Southward & Ahmadian (2024): per-step hyper-clothoid
(`clothoid_fit`), Fréchet-distance adaptive lookahead (`frechet`, `lookahead`), curvature limits
(`curvature_limits`) and lead filter (`lead_filter`; against speed, `filter_schedule`), put together in
`controller`.
"""

from controllers.clothoid.clothoid_fit import ClothoidFit, fit_hyper_clothoid
from controllers.clothoid.controller import ClothoidConfig, ClothoidController
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
from controllers.clothoid.frechet import discrete_frechet
from controllers.clothoid.lead_filter import DiscreteLeadFilter, LeadFilterParams

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
