"""The workbench: reference paths, vehicle models, scenarios, the closed-loop simulator, and the applications."""

from workbench.base.compiled_cache import use_versioned_numba_cache

use_versioned_numba_cache()  # before any module imports numba (workbench/base/compiled_cache.py)
