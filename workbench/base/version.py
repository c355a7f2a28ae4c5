"""The version the command lines print (`workbench --version`, `tuning --version`): the installed distribution's,
and the git commit when the code runs from a checkout (an editable install), so that a run's report can be traced
to the code that made it."""

from __future__ import annotations

import argparse
import subprocess
from collections.abc import Sequence
from pathlib import Path

#: The distribution the console scripts come with (pyproject.toml's project name): its version is theirs.
DISTRIBUTION = "lateral-workbench"
#: The folder holding the project's packages (`tuning`, `workbench`, `controllers`): a checkout's root when the code
#: runs from one (an editable install), else site-packages.
SOURCE_ROOT = Path(__file__).resolve().parents[2]
#: This module's path under SOURCE_ROOT, tracked by git in a checkout.
THIS_MODULE = Path(__file__).resolve().relative_to(SOURCE_ROOT).as_posix()


def _git(root: Path, *args: str) -> str | None:
    """The output of `git -C root args...`, stripped; None when git is absent, fails or takes over 5 s. Read-only:
    `--no-optional-locks` keeps `git status` from writing its refreshed index, which would take the index lock
    beside whoever is working in the checkout."""
    try:
        done = subprocess.run(
            ["git", "--no-optional-locks", "-C", str(root), *args],
            capture_output=True,
            text=True,
            timeout=5.0,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def checkout_commit(root: Path = SOURCE_ROOT) -> str | None:
    """The commit of the git checkout the code runs from (its packages in `root`): the short hash, with "+dirty"
    when tracked files differ from it (untracked ones do not count, as with `git describe --dirty`); None when
    git is absent, `root` is no checkout of this project (this module not tracked there: an installed copy, even
    in a virtual environment inside a checkout) or git fails."""
    if _git(root, "ls-files", "--error-unmatch", "--", THIS_MODULE) is None:
        return None
    commit = _git(root, "rev-parse", "--short", "HEAD")
    if not commit:
        return None
    changes = _git(root, "status", "--porcelain", "--untracked-files=no")  # None (it failed): not called dirty
    return commit + ("+dirty" if changes else "")


def installed_version() -> str | None:
    """The installed distribution's version (importlib.metadata), None when it is not installed."""
    import importlib.metadata

    try:
        return importlib.metadata.version(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        return None


def version_text(prog: str) -> str:
    """What `PROG --version` prints: the program, the distribution and its installed version and, from a git
    checkout, the commit (`checkout_commit`)."""
    version = installed_version() or "(version unknown: not installed; run `pip install -e .` in the checkout)"
    commit = checkout_commit()
    return f"{prog} ({DISTRIBUTION}) {version}" + (f", commit {commit}" if commit else "")


class VersionAction(argparse.Action):
    """`--version`: print `version_text` on stdout and exit 0. Unlike argparse's "version" action the text is made
    only when asked (importlib.metadata and git take tens of milliseconds), so that `--help` stays fast."""

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str = argparse.SUPPRESS,
        help: str = "print the version (and the git commit, run from a checkout) and exit",
    ) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help=help)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print(version_text(parser.prog))
        parser.exit()
