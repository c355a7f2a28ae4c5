"""The numba cache folder follows the compiled sources: any change to a module that uses numba gives another
folder (so no stale kernel is loaded after an update), an explicit NUMBA_CACHE_DIR is kept."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from workbench.base import compiled_cache
from workbench.base.compiled_cache import compiled_sources_digest, use_versioned_numba_cache


def _tree(root: Path, kernel: str) -> Path:
    for package in compiled_cache.PACKAGES:
        (root / package).mkdir(parents=True)
    (root / "workbench" / "kernel.py").write_text(f"from numba import njit\n{kernel}\n")
    (root / "controllers" / "plain.py").write_text("x = 1\n")
    return root


def test_the_digest_changes_with_a_compiled_source_and_only_with_one(tmp_path: Path) -> None:
    root = _tree(tmp_path / "a", "def f(): return 1")
    before = compiled_sources_digest(root)
    assert compiled_sources_digest(root) == before  # the same sources, the same folder
    (root / "controllers" / "plain.py").write_text("x = 2\n")  # no numba in it: no recompile
    assert compiled_sources_digest(root) == before
    (root / "workbench" / "kernel.py").write_text("from numba import njit\ndef f(): return 2\n")
    assert compiled_sources_digest(root) != before


def test_the_folder_is_set_unless_chosen_already_or_too_late(monkeypatch, tmp_path: Path) -> None:
    monkeypatch.setenv("WORKBENCH_NUMBA_CACHE", str(tmp_path / "versions"))
    monkeypatch.delitem(sys.modules, "numba", raising=False)  # as before anything imported numba
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    use_versioned_numba_cache()
    folder = Path(os.environ["NUMBA_CACHE_DIR"])
    assert folder == tmp_path / "versions" / compiled_sources_digest()[:16] and folder.is_dir()

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    use_versioned_numba_cache()
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")  # an explicit choice is kept

    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setitem(sys.modules, "numba", object())  # numba has read its settings: too late to change them
    use_versioned_numba_cache()
    assert "NUMBA_CACHE_DIR" not in os.environ


def test_a_folder_holding_a_file_others_may_write_is_not_used(monkeypatch, tmp_path: Path, capsys) -> None:
    """numba unpickles its index files: a planted one is code. The folder is refused, the kernels compiled into a
    private temporary folder instead, and a warning says which folder and why."""
    versions = tmp_path / "versions"
    monkeypatch.setenv("WORKBENCH_NUMBA_CACHE", str(versions))
    monkeypatch.delitem(sys.modules, "numba", raising=False)
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    use_versioned_numba_cache()
    folder = Path(os.environ["NUMBA_CACHE_DIR"])
    assert (folder.stat().st_mode & 0o777) == 0o700  # made private
    planted = folder / "kernel.step-1.py311.nbi"
    planted.write_bytes(b"not numba's")
    planted.chmod(0o666)
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    use_versioned_numba_cache()
    used = Path(os.environ["NUMBA_CACHE_DIR"])
    assert used != folder and not used.is_relative_to(versions) and (used.stat().st_mode & 0o777) == 0o700
    assert list(used.iterdir()) == []
    err = capsys.readouterr().err
    assert f"cache file '{planted}' is writable by others (mode 0666)" in err and f"compiling into {used}" in err
