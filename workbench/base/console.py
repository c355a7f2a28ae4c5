"""What the console scripts share: their warnings on stderr, and their exit, a command's `main` then the
interpreter's exit without its last garbage collections over everything the command loaded.

At exit CPython collects cycles over every object still alive: after a run that is numba's, LLVM's, matplotlib's,
pandas' and scipy's millions of objects, ~0.3-0.4 s of a command's wall time for memory the process hands back
anyway. `gc.freeze()` moves them out of the collector's reach; refcounting, `atexit` and every finaliser still
run. Only the console scripts do this: `main` itself stays a plain function that tests call many times.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Callable


def warn_on_stderr(message: str) -> None:
    """Print a warning as the CLI does: `workbench: warning: ...` on stderr."""
    print(f"workbench: warning: {message}", file=sys.stderr, flush=True)


def console_exit(main: Callable[[], int]) -> int:
    """Run `main` and return its exit code, the collector frozen behind it."""
    code = main()
    gc.freeze()
    return code
