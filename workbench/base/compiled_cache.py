"""Where numba keeps the compiled kernels: one folder per version of the compiled code.

numba checks a cached kernel against the time stamp of its own source file only. A kernel that calls kernels of
other modules (the clothoid step calls a dozen, the simulator's step the path searches) has their code compiled
into it, so after one of those files changes, an in-place update (`git pull`, an edited checkout) would run the
old code from the cache, silently. Each version of the sources that use numba (their contents, hashed) therefore
gets its own cache folder, `$XDG_CACHE_HOME/lateral-workbench/numba/<digest>` (or under
$WORKBENCH_NUMBA_CACHE): a changed file means a fresh compile (tens of seconds, once), never a stale kernel.

`use_versioned_numba_cache` sets NUMBA_CACHE_DIR to that folder; the packages call it before anything imports
numba. It leaves an explicit NUMBA_CACHE_DIR alone, does nothing when numba is already imported (its settings are
read then), and leaves numba's own default (`__pycache__` beside the sources) when the folder cannot be written.
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from pathlib import Path

from workbench.base.user_cache import user_cache_dir

#: The packages whose modules may hold compiled kernels, relative to the folder holding this project's packages.
PACKAGES = ("workbench", "controllers")
#: Environment variable naming the folder that holds the versioned cache folders.
CACHE_ENV = "WORKBENCH_NUMBA_CACHE"
_SOURCE_ROOT = Path(__file__).resolve().parents[2]


def compiled_sources_digest(root: Path = _SOURCE_ROOT) -> str:
    """sha256 (hex) of the path and contents of every module of PACKAGES under `root` that mentions numba."""
    digest = hashlib.sha256()
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            content = path.read_bytes()
            if b"numba" in content:
                digest.update(path.relative_to(root).as_posix().encode())
                digest.update(content)
    return digest.hexdigest()


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def use_versioned_numba_cache() -> None:
    """Point NUMBA_CACHE_DIR at this version's folder (module docstring), unless set, numba already imported, or
    the folder not writable."""
    if os.environ.get("NUMBA_CACHE_DIR") or "numba" in sys.modules:
        return
    folder = user_cache_dir(CACHE_ENV, "numba") / compiled_sources_digest()[:16]
    if _writable(folder):
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
