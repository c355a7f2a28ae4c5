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

numba loads its index files with pickle, so a file in that folder is code the run executes: the folder is made
private to the user, and a folder, or a file in it, that another user owns or others may write is not used
(`workbench.base.user_cache.check_private`). Then a warning on stderr says which and why, and the kernels are
compiled into a fresh private temporary folder instead, removed at exit: slower, never foreign code.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import shutil
import sys
import tempfile
from pathlib import Path

from workbench.base.user_cache import UnsafeCacheError, check_private_tree, private_cache_dir

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
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def _private_temporary_folder() -> Path:
    """A fresh folder of this user's alone (mkdtemp: 0700), removed when the process that made it exits."""
    folder = Path(tempfile.mkdtemp(prefix="lateral-workbench-numba-"))
    maker = os.getpid()

    def remove() -> None:
        if os.getpid() == maker:  # not in a forked child, which inherits the hook
            shutil.rmtree(folder, ignore_errors=True)

    atexit.register(remove)
    return folder


def use_versioned_numba_cache() -> None:
    """Point NUMBA_CACHE_DIR at this version's folder (module docstring), unless set, numba already imported, or
    the folder not writable; at a private temporary folder, with a warning on stderr, when the cache is not the
    user's own."""
    if os.environ.get("NUMBA_CACHE_DIR") or "numba" in sys.modules:
        return
    try:
        folder = private_cache_dir(CACHE_ENV, "numba", compiled_sources_digest()[:16])
        check_private_tree(folder, CACHE_ENV)
    except UnsafeCacheError as exc:
        folder = _private_temporary_folder()
        print(f"lateral-workbench: warning: {exc}; compiling into {folder} instead", file=sys.stderr, flush=True)
    except OSError:
        return
    if _writable(folder):
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
