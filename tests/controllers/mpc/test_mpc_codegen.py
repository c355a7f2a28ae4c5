"""Compiled CasADi functions: the same numbers as the SX function, cached on disk, and a clean fallback."""

from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np
import pytest

from controllers.mpc.codegen import CACHE_ENV, FastFunction, compile_function, find_compiler
from workbench.base.user_cache import UnsafeCacheError


def _function() -> ca.Function:
    x, p = ca.SX.sym("x", 3), ca.SX.sym("p", 2)
    y = ca.vertcat(ca.sin(x[0]) * p[0], x[1] * x[2] + p[1], ca.atan(x[2]))
    return ca.Function("probe", [x, p], [y, ca.densify(ca.jacobian(y, x))])


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")
def test_compiled_function_matches_and_is_cached(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    function = _function()
    compiled = compile_function(function)
    assert compiled.compiled, compiled.note
    libraries = list(tmp_path.glob("probe_*.so"))
    assert len(libraries) == 1
    stamp = libraries[0].stat().st_mtime_ns
    x, p = np.array([0.3, -1.2, 2.0]), np.array([1.5, 0.25])
    for expected, got in zip(function(x, p), compiled.function(x, p), strict=True):
        np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=1e-14)
    again = compile_function(function)
    assert again.compiled and libraries[0].stat().st_mtime_ns == stamp  # loaded from the cache


def test_falls_back_to_the_sx_function(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    assert not compile_function(_function(), enabled=False).compiled
    monkeypatch.setenv("CC", "/bin/false")  # a "compiler" that always fails
    failed = compile_function(_function())
    assert not failed.compiled and "compiling failed" in failed.note
    np.testing.assert_allclose(np.asarray(failed.function([0.1, 0.2, 0.3], [1.0, 2.0])[0]).ravel()[1], 2.06)


def test_fast_function_evaluates_on_buffers() -> None:
    fast = FastFunction(_function())
    x, p = np.array([[0.3], [-1.2], [2.0]]), np.array([1.5, 0.25])
    value, jacobian = fast(x, p)
    expected_value, expected_jacobian = _function()(x, p)
    np.testing.assert_allclose(value, np.asarray(expected_value).ravel())
    np.testing.assert_allclose(jacobian, np.asarray(expected_jacobian).ravel(order="F"))


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")
@pytest.mark.parametrize("record", ["none", "other"])
def test_a_library_planted_under_the_cached_name_is_never_loaded(tmp_path, monkeypatch, record: str) -> None:
    """A library whose SHA-256 is not the one recorded when it was built here is built again before loading."""
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    assert compile_function(_function()).compiled
    (library,) = tmp_path.glob("probe_*.so")
    built = library.read_bytes()
    digest_file = library.with_name(library.name + ".sha256")
    assert digest_file.read_text() == hashlib.sha256(built).hexdigest()
    library.write_bytes(b"\x7fELF planted")  # not loadable: loading it would fail, not silently compute
    if record == "none":
        digest_file.unlink()
    again = compile_function(_function())
    assert again.compiled, again.note
    assert library.read_bytes() == built and digest_file.read_text() == hashlib.sha256(built).hexdigest()


def test_a_cache_folder_others_may_write_is_refused(tmp_path, monkeypatch) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    monkeypatch.setenv(CACHE_ENV, str(shared))
    with pytest.raises(UnsafeCacheError, match=rf"cache folder '{shared}' is writable by others"):
        compile_function(_function())
