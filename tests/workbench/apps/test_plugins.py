"""A controller and a vehicle written outside this repository, registered by an installed package's entry points
(examples/plugin/), are run by `workbench run` and `compare` by name; a broken registration is refused naming the
package; and the README's five-line simulation from Python runs as written.

The package is "installed" for a subprocess as pip would leave it: its source folder on the path and a
`.dist-info` folder holding its entry points (importlib.metadata reads nothing else).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
PLUGIN_SRC = ROOT / "examples" / "plugin" / "src"


def _install(site: Path, entry_points: str, name: str = "workbench_example_plugin") -> dict[str, str]:
    """An environment whose Python sees a distribution `name` with these entry points, and the example's code."""
    info = site / f"{name}-0.1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1.0\n")
    (info / "entry_points.txt").write_text(entry_points)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(PLUGIN_SRC), env.get("PYTHONPATH", "")])
    return env


def _entry_points_of_the_example() -> str:
    text = (ROOT / "examples" / "plugin" / "pyproject.toml").read_text()
    sections = re.findall(r'\[project\.entry-points\."([^"]+)"\]\n((?:[^\[\n].*\n)+)', text)
    return "".join(f"[{group}]\n{body.replace(chr(34), '')}\n" for group, body in sections)  # INI: no quotes


def _workbench(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "workbench.apps.cli", *args], env=env, capture_output=True, text=True, timeout=300
    )


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    return _install(tmp_path_factory.mktemp("site"), _entry_points_of_the_example())


def test_the_example_declares_a_controller_and_a_vehicle() -> None:
    points = _entry_points_of_the_example()
    assert "[lateral_workbench.controllers]\nlateral-pd = " in points
    assert "[lateral_workbench.vehicles]\nexample-kart = " in points


def test_the_plugins_are_listed_and_shown(plugin_env: dict[str, str]) -> None:
    listed = _workbench(plugin_env, "controllers")
    assert listed.returncode == 0 and re.search(r"^lateral-pd +Lateral PD: ", listed.stdout, re.M), listed.stderr
    shown_controller = _workbench(plugin_env, "controllers", "--show", "lateral-pd")
    assert shown_controller.returncode == 0 and "cte_gain_1pm2 = 0.1" in shown_controller.stdout
    assert "k_y, the feedback on the cross-track error" in shown_controller.stdout
    vehicles = _workbench(plugin_env, "vehicles")
    assert vehicles.returncode == 0 and "example-kart" in vehicles.stdout and "wheelbase 1.05" in vehicles.stdout
    shown = _workbench(plugin_env, "vehicles", "--show", "example-kart")
    assert shown.returncode == 0 and 'type = "example-kart"' in shown.stdout and "wheelbase_m = 1.05" in shown.stdout


def test_workbench_run_drives_the_plugin_controller_on_the_plugin_vehicle(
    plugin_env: dict[str, str], tmp_path: Path
) -> None:
    out = tmp_path / "run"
    args = ("run", "figure8", "--controller", "lateral-pd", "--vehicle", "example-kart", "--speed", "20")
    done = _workbench(plugin_env, *args, "--no-plots", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "figure8: lateral-pd on example-kart" in done.stdout
    metrics = json.loads((out / "metrics.json").read_text())
    # a damped error loop (damping 0.7 on a 20 m wavelength) on a 1.05 m kart holds the figure-8 within 0.15 m
    assert metrics["max_abs_cte_m"] < 0.15


def test_workbench_compare_runs_the_plugin_beside_the_built_in_controllers(
    plugin_env: dict[str, str], tmp_path: Path
) -> None:
    out = tmp_path / "cmp"
    done = _workbench(
        plugin_env, "compare", "figure8", "--controllers", "lateral-pd,stanley", "--vehicle",
        "example-kart,kinematic-bicycle", "--speed", "20", "--no-plots", "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = (out / "summary.csv").read_text()
    for run in ("lateral-pd,example-kart", "stanley,example-kart", "lateral-pd,kinematic-bicycle"):
        assert run in summary.replace('"', "")


def test_a_registration_that_cannot_be_imported_is_refused_naming_the_package(tmp_path: Path) -> None:
    env = _install(
        tmp_path / "site",
        "[lateral_workbench.controllers]\nbroken = no_such_module:Nothing\nclothoid = x:Y\n"
        "[lateral_workbench.vehicles]\nbroken-car = no_such_module:Car\n",
        name="broken_plugin",
    )
    done = _workbench(env, "run", "figure8", "--controller", "broken", "--out", str(tmp_path / "out"))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "controller 'broken' (registered by broken_plugin as no_such_module:Nothing) cannot be imported" in (
        done.stderr
    )
    assert "entry point of broken_plugin left out: the name 'clothoid' is taken" in done.stderr
    assert "vehicle 'broken-car' (registered by broken_plugin as no_such_module:Car) left out" in done.stderr


def test_the_readme_simulation_from_python_runs_as_written() -> None:
    readme = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- five-line simulation -->\n```python\n(.*?)```", readme, re.S)
    assert block is not None, "the README's five-line simulation block is missing"
    code = block.group(1)
    assert len([line for line in code.splitlines() if line.strip()]) <= 9  # imports and five lines
    namespace: dict[str, object] = {}
    exec(compile(code, "README.md", "exec"), namespace)
    result = namespace["result"]
    assert result.completed and result.metrics.max_abs_cte_m < 0.3
