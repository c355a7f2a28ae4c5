"""The console scripts' common exit: a command's `main`, then the interpreter's exit without its last garbage
collections over everything the command loaded.

At exit CPython collects cycles over every object still alive: after a run that is numba's, LLVM's, matplotlib's,
pandas' and scipy's millions of objects, ~0.3-0.4 s of a command's wall time for memory the process hands back
anyway. `gc.freeze()` moves them out of the collector's reach; refcounting, `atexit` and every finaliser still
run. Only the console scripts do this: `main` itself stays a plain function that tests call many times.
"""

from __future__ import annotations

import gc
from collections.abc import Callable


def console_exit(main: Callable[[], int]) -> int:
    """Run `main` and return its exit code, the collector frozen behind it."""
    code = main()
    gc.freeze()
    return code
