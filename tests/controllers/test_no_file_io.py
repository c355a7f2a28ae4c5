"""Controllers read no file (issue 17, item 2): their configs hold objects (lead filter, limits, lags, tunings),
and every file is read at the boundary (config loading, the CLIs, studies). The one exception is the MPC's cache of
compiled solver code (`controllers/mpc/codegen.py`): a build artefact of the solver, written and loaded by the
solver that made it, never an input."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: Calls and imports that read or write files.
FILE_CALLS = {
    "open",
    "read_text",
    "read_bytes",
    "write_text",
    "write_bytes",
    "read_json",
    "read_toml",
    "read_csv",
    "to_csv",
    "loadtxt",
    "savetxt",
    "read_parquet",
    "to_parquet",
    "check_input_file",
}
FILE_MODULES = {"tomllib", "workbench.base.input_files", "workbench.base.output_dir", "tuning"}
ALLOWED = {"controllers/mpc/codegen.py"}


def _file_io(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in FILE_CALLS or (name == "load" and isinstance(func, ast.Attribute)):
                found.append(f"line {node.lineno}: {name}()")
        elif isinstance(node, ast.Import | ast.ImportFrom):
            modules = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
            found += [
                f"line {node.lineno}: import {m}"
                for m in modules
                if m.split(".")[0] in FILE_MODULES or m in FILE_MODULES
            ]
    return found


def test_the_scan_sees_file_reading(tmp_path: Path) -> None:
    sample = tmp_path / "sample.py"
    sample.write_text("import tomllib\nfrom workbench.base.input_files import read_json\nx = open('f').read()\n")
    assert _file_io(sample) == ["line 1: import tomllib", "line 2: import workbench.base.input_files", "line 3: open()"]


def test_controllers_read_no_file() -> None:
    offenders = {
        str(path.relative_to(ROOT)): found
        for path in sorted((ROOT / "controllers").rglob("*.py"))
        if str(path.relative_to(ROOT)) not in ALLOWED and (found := _file_io(path))
    }
    assert offenders == {}
