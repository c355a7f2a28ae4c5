"""Compiled CasADi functions: generate C, compile it once with the system C compiler, cache the library on disk.

Where it pays: the per-step linearisation of the prediction model over the horizon (N Jacobians of an RK4 step)
is the bulk of an RTI step. CasADi's SX virtual machine evaluates it in about 0.8 ms at N = 30 for the dynamic
bicycle; the compiled library in about 0.15 ms, and compiling takes about half a second, once: libraries are
cached under `cache_dir()` by a hash of the generated source, the compiler and its flags, so later builds of the
same problem (every test, every run) load them directly. Without a C compiler, or if compiling fails, the SX
function is used as it is (same results, slower) and `CompiledFunction.compiled` says so.

A cached library is code this process runs: the cache folder must be the user's own (`private_cache_dir`: made
0700, refused with `UnsafeCacheError` when another user owns it or others may write it), and each library is
loaded only when its SHA-256 is the one recorded beside it (`<library>.sha256`) when it was built here; a library
without that record, or differing from it, is built again.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np

from workbench.base.user_cache import check_private, private_cache_dir

#: Environment variable naming the directory compiled libraries are cached in.
CACHE_ENV = "WORKBENCH_MPC_CACHE"
COMPILE_FLAGS = ("-O2", "-fPIC", "-shared")
#: Longest a compilation may take (s) before it is abandoned (and the SX function used).
COMPILE_TIMEOUT_S = 120.0


@dataclass(frozen=True)
class CompiledFunction:
    """function: the callable (an external compiled library, or the original SX function); compiled: whether it
    is compiled; note: why not, when it is not."""

    function: ca.Function
    compiled: bool
    note: str = ""


def cache_dir() -> Path:
    """$WORKBENCH_MPC_CACHE, else $XDG_CACHE_HOME/lateral-workbench/casadi (~/.cache/...): made private when
    missing; UnsafeCacheError when it is not the user's own."""
    return private_cache_dir(CACHE_ENV, "casadi")


def file_sha256(path: Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _digest_file(library: Path) -> Path:
    return library.with_name(library.name + ".sha256")


def _verified(library: Path) -> bool:
    """Whether `library` is a file of the user's own whose SHA-256 is the one recorded when it was built here."""
    record = _digest_file(library)
    if not (library.is_file() and record.is_file()):
        return False
    check_private(library, CACHE_ENV)
    check_private(record, CACHE_ENV)
    return record.read_text(encoding="ascii").strip() == file_sha256(library)


def _write_atomically(path: Path, data: bytes, work: Path) -> None:
    tmp = work / (path.name + ".tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def find_compiler() -> str | None:
    """The C compiler to use: $CC if set and found, else gcc, cc or clang on PATH; None if there is none."""
    for name in (os.environ.get("CC"), "gcc", "cc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def compile_function(function: ca.Function, enabled: bool = True) -> CompiledFunction:
    """`function` compiled to a shared library (cached), or itself when disabled or when that is not possible."""
    if not enabled:
        return CompiledFunction(function, False, "code generation switched off")
    compiler = find_compiler()
    if compiler is None:
        return CompiledFunction(function, False, "no C compiler found (gcc, cc, clang or $CC)")
    generator = ca.CodeGenerator(f"{function.name()}.c", {"with_header": False})
    generator.add(function)
    source = generator.dump()
    version = ca.__version__  # type: ignore[attr-defined]  # (casadi's stubs omit it)
    key = hashlib.sha256("\n".join((source, compiler, " ".join(COMPILE_FLAGS), version)).encode()).hexdigest()[:20]
    try:
        directory = cache_dir()
    except OSError as exc:
        return CompiledFunction(function, False, f"no cache folder ({type(exc).__name__}: {exc})")
    library = directory / f"{function.name()}_{key}.so"
    if not _verified(library):
        try:
            with tempfile.TemporaryDirectory(dir=directory) as work:
                c_file = Path(work) / f"{function.name()}.c"
                c_file.write_text(source)
                tmp_library = Path(work) / library.name
                subprocess.run(
                    [compiler, *COMPILE_FLAGS, "-o", str(tmp_library), str(c_file), "-lm"],
                    check=True,
                    capture_output=True,
                    timeout=COMPILE_TIMEOUT_S,
                )
                digest = file_sha256(tmp_library)
                # the record first: a library is never there without the digest of what was built
                _write_atomically(_digest_file(library), digest.encode("ascii"), Path(work))
                os.replace(tmp_library, library)  # atomic: parallel builds never see a partial file
        except (OSError, subprocess.SubprocessError) as exc:
            return CompiledFunction(function, False, f"compiling failed ({type(exc).__name__}: {exc})")
    try:
        return CompiledFunction(ca.external(function.name(), str(library)), True)
    except RuntimeError as exc:  # pragma: no cover - a corrupt cache entry
        return CompiledFunction(function, False, f"loading {library} failed: {exc}")


class FastFunction:
    """A CasADi Function evaluated on preallocated numpy buffers (`Function.buffer`): no argument conversion,
    no allocation. Inputs must be dense; outputs are the flat nonzeros in column-major order (densify the outputs
    when building the function to get full matrices). Falls back to ordinary calls on CasADi builds without
    `Function.buffer`."""

    def __init__(self, function: ca.Function) -> None:
        self.function = function
        self.inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self.outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        self._evaluate = None
        if hasattr(function, "buffer"):
            self._buffer, self._evaluate = function.buffer()
            # (casadi's stubs ask a size and a Buffer: the binding takes both from the array's memoryview)
            for i, array in enumerate(self.inputs):
                self._buffer.set_arg(i, memoryview(array))  # type: ignore[call-arg, arg-type]
            for i, array in enumerate(self.outputs):
                self._buffer.set_res(i, memoryview(array))  # type: ignore[call-arg, arg-type]

    def __call__(self, *args: np.ndarray) -> list[np.ndarray]:
        for target, value in zip(self.inputs, args, strict=True):
            target[:] = value.ravel(order="F") if isinstance(value, np.ndarray) else np.ravel(value, order="F")
        if self._evaluate is None:  # pragma: no cover - CasADi < 3.6
            called = self.function(*[np.reshape(a, self.function.size_in(i), order="F") for i, a in enumerate(args)])
            results = called if isinstance(called, tuple) else (called,)
            for target, result in zip(self.outputs, results, strict=True):
                target[:] = np.ravel(np.asarray(result), order="F")
            return self.outputs
        self._evaluate()
        if self._buffer.ret() != 0:
            self.outputs[0][:] = np.nan  # reported as a numerical error by the caller
        return self.outputs
