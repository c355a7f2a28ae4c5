"""Output folders and files: checked before any work starts, and a command's output written whole, never mixed
with an earlier run's.

Checks (`check_output_dir`, `check_output_file`), made before anything is simulated: the path is not a file where
a folder is wanted (or a folder where a file is wanted), none of its parents is a file, and the folder that will
hold it (the nearest one that exists) is writable. A problem is a WorkbenchInputError naming the option, the path
and the problem.

The output of `workbench run`, `compare`, `fig17` and `paper` (`OutputDir`): a non-empty folder is refused unless
`--overwrite` is given, so that a new run never lands beside files of an earlier one (the PNGs of a run with plots
beside the trace of one without). Every such folder gets a manifest, `.workbench-manifest.json`, listing the files
the command wrote; with `--overwrite` exactly those files are removed before the new ones are written, and files
the workbench did not write (the user's own) are kept, and named. A sweep's or optimisation's folder is a resumable
store instead (`check_study_dir`): it may hold the study's earlier runs, but not another command's output or
unrelated files.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path, PurePosixPath

from workbench.base.errors import WorkbenchInputError
from workbench.base.input_files import parse_json

#: The manifest of the files a command wrote into its output folder.
MANIFEST = ".workbench-manifest.json"
MANIFEST_FORMAT = "workbench-output/1"
#: What marks a study's folder: the copy of the spec `workbench sweep`/`optimise` write first, and the folder of
#: its runs' rows (`workbench.apps.studies.store`).
STUDY_SPEC = "spec.toml"
STUDY_RUNS = "runs"


def _first_non_folder(path: Path) -> Path | None:
    """The first of path's parents (outermost first) that exists and is not a folder; None if there is none."""
    for parent in reversed(path.parents):
        try:
            if parent.exists() and not parent.is_dir():
                return parent
        except OSError:
            return None
    return None


def _nearest_existing(path: Path) -> Path:
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return Path.cwd()


def _writable(folder: Path) -> bool:
    return os.access(folder, os.W_OK | os.X_OK)


def check_output_dir(path: str | os.PathLike[str], label: str = "--out") -> Path:
    """`path` as a Path if it can be an output folder: an existing writable folder, or one that can be created
    (no parent is a file, the nearest existing parent is writable). Creates nothing."""
    path = Path(path)
    where = f"{label} {str(path)!r}"
    try:
        blocker = _first_non_folder(path)
        if blocker is not None:
            raise WorkbenchInputError(f"{where}: {str(blocker)!r} is a file, not a folder; choose another folder")
        if path.exists() and not path.is_dir():
            raise WorkbenchInputError(f"{where} is a file, not a folder; give a folder for the output")
        holder = _nearest_existing(path)
        if not _writable(holder):
            what = "the folder" if holder == path else f"its parent {str(holder)!r}"
            raise WorkbenchInputError(f"{where}: {what} is not writable (permission denied)")
    except OSError as exc:
        raise WorkbenchInputError(f"{where}: cannot be used as a folder ({exc.strerror or exc})") from None
    return path


def check_output_file(path: str | os.PathLike[str], label: str = "--out", overwrite: bool = True) -> Path:
    """`path` as a Path if a file can be written there: not a folder, no parent a file, the file (if it exists) or
    the nearest existing parent writable; with overwrite False, no file (or link) there at all, so that a command's
    output never replaces an earlier file unasked (its `--overwrite` allows it). Creates nothing."""
    path = Path(path)
    where = f"{label} {str(path)!r}"
    try:
        blocker = _first_non_folder(path)
        if blocker is not None:
            raise WorkbenchInputError(f"{where}: {str(blocker)!r} is a file, not a folder")
        if path.is_dir():
            raise WorkbenchInputError(f"{where} is a folder, not a file; give the name of the file to write")
        if not overwrite and os.path.lexists(path):
            raise WorkbenchInputError(f"{where} exists; give --overwrite to replace it, or choose another file name")
        if path.exists():
            if not os.access(path, os.W_OK):
                raise WorkbenchInputError(f"{where}: the file is not writable (permission denied)")
        else:
            holder = _nearest_existing(path.parent)
            if not _writable(holder):
                raise WorkbenchInputError(f"{where}: the folder {str(holder)!r} is not writable (permission denied)")
    except OSError as exc:
        raise WorkbenchInputError(f"{where}: cannot be written ({exc.strerror or exc})") from None
    return path


def make_output_dir(path: Path, label: str = "--out") -> Path:
    """Create the folder (and its parents); WorkbenchInputError instead of an OSError."""
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WorkbenchInputError(f"{label} {str(path)!r}: cannot create the folder ({exc.strerror or exc})") from None
    return path


def _entries(path: Path) -> list[str]:
    """The names in the folder (none if it does not exist)."""
    if not path.is_dir():
        return []
    return sorted(entry.name for entry in path.iterdir())


def _entries_text(names: list[str]) -> str:
    """How many entries, and the first names: e.g. `1 entry: a.txt`, `5 entries: a, b, c and 2 more`."""
    return f"{len(names)} {'entry' if len(names) == 1 else 'entries'}: {_examples(names)}"


def _examples(names: Iterable[str], count: int = 3) -> str:
    names = list(names)
    shown = ", ".join(names[:count])
    return shown + (f" and {len(names) - count} more" if len(names) > count else "")


def read_manifest(folder: Path) -> dict | None:
    """The folder's manifest ({"format", "command", "written", "files"}), or None without a readable one."""
    path = folder / MANIFEST
    if not path.is_file():
        return None
    try:
        document = parse_json(path.read_text(encoding="utf-8"), f"manifest {path}")
    except (OSError, UnicodeDecodeError, WorkbenchInputError):
        return None
    if (
        not isinstance(document, dict)
        or document.get("format") != MANIFEST_FORMAT
        or not isinstance(document.get("files"), list)
        or not all(isinstance(f, str) for f in document["files"])
    ):
        return None
    return document


def _safe_relative(name: str) -> PurePosixPath | None:
    """A manifest entry as a relative path inside the folder, or None if it could point outside it."""
    rel = PurePosixPath(name)
    if rel.is_absolute() or not rel.parts or any(p in ("", ".", "..") for p in rel.parts):
        return None
    return rel


def _files_under(folder: Path) -> set[str]:
    """Every file (and symlink) under the folder, as POSIX paths relative to it, the manifest excluded."""
    found = set()
    for root, dirs, files in os.walk(folder):
        base = Path(root)
        names = list(files) + [d for d in dirs if (base / d).is_symlink()]
        for name in names:
            rel = (base / name).relative_to(folder).as_posix()
            if rel != MANIFEST:
                found.add(rel)
    return found


class OutputDir:
    """The output folder of a command that writes its result once (`workbench run`, `compare`, `fig17`,
    `paper`). Constructing it checks the folder (`check_output_dir`) and the overwrite policy (module docstring),
    before any work; `writing()` then removes the previous output (with overwrite) and records what is written."""

    def __init__(self, path: str | os.PathLike[str], command: str, overwrite: bool = False, label: str = "--out"):
        self.path = check_output_dir(path, label)
        self.command = command
        self.overwrite = overwrite
        self.label = label
        self.previous = read_manifest(self.path)
        entries = [e for e in _entries(self.path) if e != MANIFEST]
        ours = {rel.parts[0] for f in (self.previous or {}).get("files", []) if (rel := _safe_relative(f))}
        #: Top-level entries the workbench did not write (kept, even with overwrite).
        self.foreign = [e for e in entries if e not in ours]
        if entries and not overwrite:
            where = f"{label} {str(self.path)!r}"
            if self.previous is not None:
                raise WorkbenchInputError(
                    f"{where} holds the output of an earlier `workbench {self.previous.get('command', '?')}` "
                    f"({len(self.previous['files'])} files, written {self.previous.get('written', '?')}); give "
                    "--overwrite to replace it (its files are removed first; files the workbench did not write are "
                    "kept), or choose another folder"
                )
            raise WorkbenchInputError(
                f"{where} is not empty ({_entries_text(entries)}) and holds no workbench "
                "output; choose a new or empty folder, or give --overwrite to write into it (files of the same "
                "names are replaced, the others kept)"
            )

    def remove_previous(self) -> list[Path]:
        """Remove the files the previous output's manifest lists (only those, only inside the folder), and the
        folders that leaves empty; return the removed files."""
        if self.previous is None:
            return []
        root = self.path.resolve()
        removed = []
        for name in self.previous["files"]:
            rel = _safe_relative(name)
            if rel is None:
                continue
            target = self.path.joinpath(*rel.parts)
            if not target.parent.resolve().is_relative_to(root):  # a symlinked folder pointing elsewhere
                continue
            if target.is_symlink() or target.is_file():
                target.unlink()
                removed.append(target)
                parent = target.parent
                while parent != self.path and parent.resolve().is_relative_to(root) and not any(parent.iterdir()):
                    parent.rmdir()
                    parent = parent.parent
        (self.path / MANIFEST).unlink(missing_ok=True)
        self.previous = None
        return removed

    @contextmanager
    def writing(self) -> Iterator[None]:
        """Around writing the output: removes the previous output, creates the folder, and afterwards (also when
        writing fails part-way) writes the manifest of every file that appeared or was rewritten."""
        try:
            self.remove_previous()
        except OSError as exc:
            raise WorkbenchInputError(
                f"{self.label} {str(self.path)!r}: cannot remove the earlier output ({exc.strerror or exc})"
            ) from None
        make_output_dir(self.path, self.label)
        before = {f: _stamp(self.path / f) for f in _files_under(self.path)}
        failed = False
        try:
            yield
        except BaseException:
            failed = True
            raise
        finally:
            after = {f: _stamp(self.path / f) for f in _files_under(self.path)}
            written = sorted(f for f, stamp in after.items() if before.get(f) != stamp)
            try:
                self._write_manifest(written)
            except OSError:
                if not failed:
                    raise

    def _write_manifest(self, files: list[str]) -> None:
        document = {
            "format": MANIFEST_FORMAT,
            "command": self.command,
            "written": datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "files": files,
        }
        final = self.path / MANIFEST
        tmp = final.with_name(f"{MANIFEST}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(document, indent=1) + "\n", encoding="utf-8")
        os.replace(tmp, final)


def _stamp(path: Path) -> tuple[int, int, int] | None:
    """What tells a rewritten file from an untouched one: (inode, size, modification time in ns)."""
    try:
        st = path.lstat()
    except OSError:
        return None
    return (st.st_ino, st.st_size, st.st_mtime_ns)


def check_study_dir(path: str | os.PathLike[str], label: str = "--out") -> Path:
    """`path` as a Path if it can hold a sweep or an optimisation: `check_output_dir`, and an existing folder must
    be empty or a study's (it has the spec's copy or the runs' folder, STUDY_SPEC or STUDY_RUNS; runs/ a writable
    folder), not another command's output (a manifest) nor a folder of unrelated files. Creates nothing."""
    path = check_output_dir(path, label)
    where = f"{label} {str(path)!r}"
    entries = _entries(path)
    manifest = read_manifest(path)
    if manifest is not None:
        raise WorkbenchInputError(
            f"{where} holds the output of `workbench {manifest.get('command', '?')}`, not a study's; choose another "
            "folder"
        )
    if entries and STUDY_SPEC not in entries and STUDY_RUNS not in entries:
        raise WorkbenchInputError(
            f"{where} is not empty ({_entries_text(entries)}) and not a study's folder (no "
            f"{STUDY_SPEC} or {STUDY_RUNS}/); a sweep or optimisation resumes in its own folder only: choose a new or "
            "empty folder, or the folder of the same study"
        )
    runs = path / STUDY_RUNS
    if runs.exists() or runs.is_symlink():
        if not runs.is_dir():
            raise WorkbenchInputError(f"{where}: {str(runs)!r} is not a folder (it should hold the study's runs)")
        if not _writable(runs):
            raise WorkbenchInputError(f"{where}: {str(runs)!r} is not writable (permission denied)")
    spec = path / STUDY_SPEC
    if spec.exists() and (not spec.is_file() or not os.access(spec, os.W_OK)):
        raise WorkbenchInputError(f"{where}: {str(spec)!r} is not a writable file (the copy of the study's spec)")
    return path


__all__ = [
    "MANIFEST",
    "STUDY_SPEC",
    "OutputDir",
    "check_output_dir",
    "check_output_file",
    "check_study_dir",
    "make_output_dir",
    "read_manifest",
]
