"""Cache folders are the user's own: made private (0700), and a folder or file another user owns, or others may
write, is refused with a message naming the path and why."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.base.user_cache import UnsafeCacheError, check_private, check_private_tree, private_cache_dir

ENV = "WORKBENCH_TEST_CACHE"
AS_ROOT = os.getuid() == 0


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_missing_folders_are_made_private_whatever_the_umask(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv(ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    previous = os.umask(0o002)  # a group-writable default, as on systems with user private groups
    try:
        folder = private_cache_dir(ENV, "casadi", "sub")
    finally:
        os.umask(previous)
    assert folder == tmp_path / "xdg" / "lateral-workbench" / "casadi" / "sub"
    for path in (folder, folder.parent, folder.parent.parent, tmp_path / "xdg"):
        assert _mode(path) == 0o700, path


def test_an_existing_private_folder_is_kept_as_it_is(tmp_path: Path, monkeypatch) -> None:
    mine = tmp_path / "mine"
    mine.mkdir(mode=0o755)
    mine.chmod(0o755)  # readable by others is fine: only writing matters
    monkeypatch.setenv(ENV, str(mine))
    assert private_cache_dir(ENV, "ignored") == mine and _mode(mine) == 0o755


@pytest.mark.parametrize("mode", [0o775, 0o757, 0o777])
def test_a_folder_others_may_write_is_refused(tmp_path: Path, monkeypatch, mode: int) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(mode)
    monkeypatch.setenv(ENV, str(shared))
    with pytest.raises(UnsafeCacheError, match=rf"cache folder '{shared}' is writable by others \(mode 0{mode:o}\)"):
        private_cache_dir(ENV, "casadi")


def test_a_writable_cache_root_is_refused_even_when_the_sub_folder_is_private(tmp_path: Path, monkeypatch) -> None:
    root = tmp_path / "root"
    (root / "v1").mkdir(parents=True, mode=0o700)
    root.chmod(0o777)  # anyone could rename v1 away and put their own in its place
    monkeypatch.setenv(ENV, str(root))
    with pytest.raises(UnsafeCacheError, match="is writable by others"):
        private_cache_dir(ENV, "numba", "v1")


def test_a_file_others_may_write_is_refused_and_the_error_is_an_input_error(tmp_path: Path) -> None:
    planted = tmp_path / "index.nbi"
    planted.write_bytes(b"x")
    planted.chmod(0o666)
    with pytest.raises(WorkbenchInputError, match=r"cache file .*index\.nbi' is writable by others \(mode 0666\)"):
        check_private_tree(tmp_path, ENV)
    planted.chmod(0o644)
    check_private_tree(tmp_path, ENV)  # the user's own: accepted


@pytest.mark.skipif(not AS_ROOT, reason="giving a file to another user needs root")
def test_a_folder_of_another_user_is_refused(tmp_path: Path) -> None:
    other = tmp_path / "other"
    other.mkdir(mode=0o700)
    os.chown(other, 12345, -1)
    with pytest.raises(UnsafeCacheError, match=r"is owned by user id 12345, not by you \(user id 0\)"):
        check_private(other, ENV)


def test_the_advice_names_the_variable_that_chooses_the_cache(tmp_path: Path) -> None:
    tmp_path.chmod(0o777)
    try:
        with pytest.raises(UnsafeCacheError, match=rf"chmod go-w.*point \${ENV} at a folder of your own"):
            check_private(tmp_path, ENV)
    finally:
        tmp_path.chmod(0o700)
