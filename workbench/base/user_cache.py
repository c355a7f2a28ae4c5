"""Where the workbench caches what it makes once and reuses (compiled MPC code, numba's kernels, generated vehicle
tunings), and the check that nobody else can have put anything there.

A cache is a directory named by an environment variable, else `$XDG_CACHE_HOME/lateral-workbench/<name>`
(`~/.cache/...`). What is in it is loaded as code (a shared library, numba's pickled index) or trusted as a design
(a tuning), so a cache folder must be the user's own: the folders the workbench creates are private (0700), and a
folder or file that another user owns, or that others (group or anyone) may write, is refused with
`UnsafeCacheError`, a `WorkbenchInputError` saying which path and why. The threat this answers is a shared or
group-writable cache folder; within the user's own account nothing more is claimed (the user can always change
their own files; the entries' recorded digests catch accidental edits).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path

from workbench.base.errors import WorkbenchInputError

#: Mode of the cache folders the workbench creates: the user's alone.
PRIVATE_FOLDER_MODE = 0o700
#: Permission bits that let someone other than the owner change a file or a folder's entries.
_WRITABLE_BY_OTHERS = stat.S_IWGRP | stat.S_IWOTH


class UnsafeCacheError(WorkbenchInputError):
    """A cache folder or file that someone other than the user owns or may write: not used."""


def user_cache_dir(env_var: str, name: str) -> Path:
    """$env_var if set, else $XDG_CACHE_HOME (or ~/.cache)/lateral-workbench/name (not created, not checked)."""
    env = os.environ.get(env_var)
    if env:
        return Path(env)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "lateral-workbench" / name


def check_private(path: Path, env_var: str) -> None:
    """Raise UnsafeCacheError unless `path` (a cache folder or a file in one; symlinks followed) is owned by this
    user and writable by nobody else. env_var: the variable that chooses the cache, named in the advice."""
    try:
        info = path.stat()
    except OSError as exc:
        raise UnsafeCacheError(f"cache {str(path)!r} cannot be checked ({exc.strerror})") from None
    kind = "folder" if stat.S_ISDIR(info.st_mode) else "file"
    mode = stat.S_IMODE(info.st_mode)
    if info.st_uid != os.getuid():
        why = f"is owned by user id {info.st_uid}, not by you (user id {os.getuid()})"
    elif mode & _WRITABLE_BY_OTHERS:
        why = f"is writable by others (mode {mode:04o})"
    else:
        return
    raise UnsafeCacheError(
        f"cache {kind} {str(path)!r} {why}: the workbench loads code and designs from its cache and uses only a "
        f"cache of your own; make it private (chmod go-w, or remove it to have it made again) or point ${env_var} "
        "at a folder of your own"
    )


def check_private_tree(folder: Path, env_var: str, entries: Iterable[Path] | None = None) -> None:
    """check_private on `folder` and on each of `entries` (default: everything directly in `folder`)."""
    check_private(folder, env_var)
    for entry in folder.iterdir() if entries is None else entries:
        check_private(entry, env_var)


def private_cache_dir(env_var: str, name: str, *sub: str) -> Path:
    """The cache folder `user_cache_dir(env_var, name)` / sub..., made (with any missing parent) private to the
    user when missing; the cache folder and each `sub` folder checked to be the user's own (`check_private`), so
    that nobody else can have renamed or replaced what lies below.

    Raises
    ------
    UnsafeCacheError
        A folder is another user's or writable by others.
    OSError
        A folder cannot be made.
    """
    root = user_cache_dir(env_var, name)
    folder = root.joinpath(*sub)
    missing = [p for p in (folder, *folder.parents) if not p.exists()]
    for path in reversed(missing):
        try:
            path.mkdir(mode=PRIVATE_FOLDER_MODE)
        except FileExistsError:  # made meanwhile by a parallel process
            continue
        path.chmod(PRIVATE_FOLDER_MODE)  # mkdir's mode is masked by the umask
    for level in range(len(sub) + 1):
        check_private(root.joinpath(*sub[:level]), env_var)
    return folder


__all__ = [
    "PRIVATE_FOLDER_MODE",
    "UnsafeCacheError",
    "check_private",
    "check_private_tree",
    "private_cache_dir",
    "user_cache_dir",
]
