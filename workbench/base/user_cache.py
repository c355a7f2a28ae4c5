"""Where the workbench caches what it makes once and reuses (compiled MPC code, generated vehicle tunings): a
directory named by an environment variable, else `$XDG_CACHE_HOME/lateral-workbench/<name>` (`~/.cache/...`)."""

from __future__ import annotations

import os
from pathlib import Path


def user_cache_dir(env_var: str, name: str) -> Path:
    """$env_var if set, else $XDG_CACHE_HOME (or ~/.cache)/lateral-workbench/name."""
    env = os.environ.get(env_var)
    if env:
        return Path(env)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "lateral-workbench" / name
