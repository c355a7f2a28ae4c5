"""Mutation testing (mutmut) of the modules whose thresholds and limits the tests must tell from their neighbours.

    .venv/bin/pip install -e '.[mutation]'
    .venv/bin/python benchmarks/mutation.py [--module limit_cycle ...] [--max-children N]

For each module in MODULES, mutmut changes one thing at a time in its functions (a `<` to `<=`, a 5 to 6, an `and`
to `or`, ...) and runs the module's test files against each mutant; a mutant the tests do not notice "survived".
The goal is at least GOAL_KILLED_PERCENT of each module's mutants killed (timeouts count as killed: the mutant
hangs), counted without the EQUIVALENT survivors, mutants that change no behaviour (each listed with why). The
limit-cycle detector's three eligibility comparisons moved from strict to inclusive (or back) survive and are
counted as survivors: they differ only when a measured half amplitude or half-period equals its bound to the last
bit, which no sampled trace can be built to hit reliably; the thresholds themselves are pinned at +-1 %.

How it runs: the checkout's files (tracked and untracked, not ignored) are copied to WORK_DIR (under build/,
ignored by git), a `[tool.mutmut]` section naming the modules and their test files is added to the copy's
pyproject.toml, and `mutmut run` works there (it copies the packages once more into WORK_DIR/mutants/ and, per
mutant, runs only the listed tests that reach the mutated function). The checkout is never touched; `cd
build/mutation && mutmut browse` shows the last run's mutants. The summary is printed and written to
benchmarks/results/mutation.json (ignored by git); the exit code is 1 when a module misses the goal.

What mutmut (3.x) does not mutate: module-level constants and decorated functions (it skips them by design), so
the limit-cycle detector's thresholds (LIMIT_CYCLE_MIN_AMPLITUDE_DEG, LIMIT_CYCLE_FREQUENCY_RANGE_HZ,
AMPLITUDE_TOLERANCE, ...) and the numba-compiled `filtered_lookahead` are not among its mutants. Their tests pin
each threshold and rate limit just inside and just outside its boundary instead (tests/workbench/simulation/
test_limit_cycle.py, tests/controllers/clothoid/test_lookahead_filter.py).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WORK_DIR = ROOT / "build" / "mutation"
RESULT_FILE = ROOT / "benchmarks" / "results" / "mutation.json"
GOAL_KILLED_PERCENT = 90.0

#: Short name -> (module file, the test files run against its mutants).
MODULES: dict[str, tuple[str, tuple[str, ...]]] = {
    "metrics": (
        "workbench/simulation/metrics.py",
        ("tests/workbench/simulation/test_metrics.py", "tests/workbench/simulation/test_track_margin.py"),
    ),
    "limit_cycle": ("workbench/simulation/limit_cycle.py", ("tests/workbench/simulation/test_limit_cycle.py",)),
    "controller_screen": ("controllers/base.py", ("tests/controllers/test_base.py",)),
}

#: Surviving mutants that change no behaviour, by mutmut's name for them, with why. mutmut numbers the mutants of
#: a function in order, so an entry goes stale when its function changes: the run then lists it as unknown.
_LC = "workbench.simulation.limit_cycle."
_AS_FLOAT = "numeric input read only through NumPy arithmetic that promotes it: the same results without dtype=float"
EQUIVALENT: dict[str, str] = {
    # the run metrics
    "workbench.simulation.metrics.x_compute_metrics__mutmut_18": "the trapezoid of 0 or 1 samples is 0.0 anyway",
    "workbench.simulation.metrics.x_compute_metrics__mutmut_26": "the trapezoid of 1 sample is 0.0 anyway",
    "workbench.simulation.metrics.x_compute_metrics__mutmut_73": "track_margins computes the same trailer feet itself "
    "when not given them (they are passed to spare that work)",
    "workbench.simulation.metrics.x_compute_metrics__mutmut_77": "track_margins computes the same trailer feet itself "
    "when not given them (they are passed to spare that work)",
    "workbench.simulation.metrics.x_offtracking__mutmut_8": "trailer_feet converts its input to float arrays itself",
    "workbench.simulation.metrics.x_offtracking__mutmut_10": "trailer_feet converts its input to float arrays itself",
    "workbench.simulation.metrics.x_offtracking__mutmut_12": "trailer_feet converts its input to float arrays itself",
    "workbench.simulation.metrics.x_offtracking__mutmut_14": "trailer_feet converts its input to float arrays itself",
    # the limit-cycle detector
    _LC + "x__checked__mutmut_3": _AS_FLOAT,
    _LC + "x__checked__mutmut_5": _AS_FLOAT,
    _LC + "x__checked__mutmut_7": _AS_FLOAT,
    _LC + "x__checked__mutmut_9": _AS_FLOAT,
    _LC + "x_detect_limit_cycle__mutmut_62": _AS_FLOAT,
    _LC + "x_detect_limit_cycle__mutmut_64": _AS_FLOAT,
    _LC + "x__checked__mutmut_28": "one sample has no time step to check: np.all of none is True",
    _LC + "x_oscillation__mutmut_6": "under 2k + 1 samples (k >= 3) the next check returns None as well",
    _LC + "x_oscillation__mutmut_7": "under 2k + 1 samples (k >= 3) the next check returns None as well",
    _LC + "x_turning_points__mutmut_4": "'' is neither True nor False, as None: the `is not` tests read it alike",
    _LC + "x_turning_points__mutmut_7": "i = 0 compares the first sample with itself: nothing changes",
    _LC + "x__longest_cycle__mutmut_10": "raised to the first eligible index (or its stretch's end) at once",
    _LC + "x__longest_cycle__mutmut_22": "a weaker pruning test (a sum >= the difference): the same result, slower",
    _LC + "x__longest_cycle__mutmut_23": "ties are pruned or not: a tie never replaces the best (strict >)",
    _LC + "x__longest_cycle__mutmut_27": "2 values irregular => any 3 with them too (b(1-t) > a(1+t) either way); "
    "runs under 6 half-cycles are never taken",
    _LC + "x__longest_cycle__mutmut_52": "a tie is pruned before this test (<= best_s above): never reached",
    _LC + "x_detect_limit_cycle__mutmut_18": "2 turning points are one half-cycle: never 3 cycles",
    _LC + "x_detect_limit_cycle__mutmut_19": "2 turning points are one half-cycle: never 3 cycles",
    # the controllers' measurement screen
    "controllers.base.xǁControllerǁ_why_implausible__mutmut_5": "8 fields and 8 values: zip's strictness never acts",
    "controllers.base.xǁControllerǁ_why_implausible__mutmut_8": "8 fields and 8 values: zip's strictness never acts",
    "controllers.base.xǁControllerǁ_why_implausible__mutmut_9": "8 fields and 8 values: zip's strictness never acts",
    "controllers.base.xǁControllerǁ_clear_hold__mutmut_5": "no frame is earlier than -inf: the count is set to 0 "
    "by the first accepted frame before it is ever read",
    "controllers.base.xǁControllerǁ_clear_hold__mutmut_6": "no frame is earlier than -inf: the count is set to 0 "
    "by the first accepted frame before it is ever read",
}

_STATUS_LINE = re.compile(r"^\s*(?P<key>\S+): (?P<status>.+?)\s*$")
_KILLED = {"killed", "timeout", "segfault"}


def _copy_checkout(dest: Path) -> None:
    """The checkout's tracked and untracked (not ignored) files, as they are on disk, into dest."""
    listed = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
        cwd=ROOT,
        check=True,
        capture_output=True,
    ).stdout.decode()
    if dest.exists():
        shutil.rmtree(dest)
    for name in filter(None, listed.split("\0")):
        source = ROOT / name
        if source.is_file():
            target = dest / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)


def _toml_list(values: list[str]) -> str:
    return "[" + ", ".join(json.dumps(v) for v in values) + "]"


def _configure(dest: Path, names: list[str]) -> None:
    """The [tool.mutmut] section for these modules, added to the copy's pyproject.toml."""
    modules = [MODULES[n][0] for n in names]
    tests = sorted({t for n in names for t in MODULES[n][1]})
    packages = sorted({m.split("/")[0] for m in modules})
    section = (
        "\n[tool.mutmut]\n"
        f"source_paths = {_toml_list(packages)}\n"
        f"only_mutate = {_toml_list(modules)}\n"
        f"pytest_add_cli_args = {_toml_list(['-p', 'no:randomly', '-p', 'no:cacheprovider', '-q'])}\n"
        f"pytest_add_cli_args_test_selection = {_toml_list(tests)}\n"
    )
    with open(dest / "pyproject.toml", "a", encoding="utf-8") as f:
        f.write(section)


def _mutmut(*args: str, capture: bool = True) -> str:
    command = [str(Path(sys.executable).with_name("mutmut")), *args]
    done = subprocess.run(command, cwd=WORK_DIR, capture_output=capture, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"mutation: `mutmut {' '.join(args)}` failed ({done.returncode}):\n{done.stderr}")
    return done.stdout if capture else ""


def _summary(names: list[str]) -> dict[str, dict]:
    statuses = {}
    for line in _mutmut("results", "--all", "true").splitlines():
        match = _STATUS_LINE.match(line)
        if match:
            statuses[match["key"]] = match["status"]
    summary = {}
    for name in names:
        prefix = MODULES[name][0].removesuffix(".py").replace("/", ".") + "."
        mine = {k: s for k, s in statuses.items() if k.startswith(prefix)}
        killed = sorted(k for k, s in mine.items() if s in _KILLED)
        equivalent = {k: EQUIVALENT[k] for k, s in mine.items() if s not in _KILLED and k in EQUIVALENT}
        survived = sorted(k for k, s in mine.items() if s not in _KILLED and k not in EQUIVALENT)
        counted = len(mine) - len(equivalent)
        summary[name] = {
            "module": MODULES[name][0],
            "mutants": len(mine),
            "killed": len(killed),
            "equivalent": equivalent,
            "survived": {k: _mutmut("show", k).strip() for k in survived},
            "statuses": {s: sum(1 for v in mine.values() if v == s) for s in sorted(set(mine.values()))},
            "killed_percent": round(100.0 * len(killed) / counted, 1) if counted else 100.0,
        }
    stale = sorted(k for k in EQUIVALENT if k not in statuses or statuses[k] in _KILLED)
    if stale:
        summary["_stale_equivalents"] = {"unknown or killed": stale}
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--module", action="append", choices=sorted(MODULES), help="only these (repeatable)")
    parser.add_argument("--max-children", type=int, default=os.cpu_count() or 1, help="parallel mutants")
    args = parser.parse_args(argv)
    names = args.module or list(MODULES)
    if shutil.which("mutmut", path=str(Path(sys.executable).parent)) is None:
        raise SystemExit("mutation: mutmut is not installed here: pip install -e '.[mutation]'")
    start = time.perf_counter()
    _copy_checkout(WORK_DIR)
    _configure(WORK_DIR, names)
    print(f"mutation: mutating {', '.join(names)} in {WORK_DIR.relative_to(ROOT)} ...", flush=True)
    _mutmut("run", "--max-children", str(args.max_children))
    summary = _summary(names)
    elapsed = time.perf_counter() - start
    RESULT_FILE.parent.mkdir(parents=True, exist_ok=True)
    RESULT_FILE.write_text(json.dumps({"elapsed_s": round(elapsed), "modules": summary}, indent=2) + "\n")
    missed = []
    for name in names:
        s = summary[name]
        print(
            f"{s['module']}: {s['killed']} of {s['mutants'] - len(s['equivalent'])} mutants killed "
            f"({s['killed_percent']} %), {len(s['equivalent'])} equivalent, {len(s['survived'])} survived"
        )
        for key, why in s["equivalent"].items():
            print(f"  equivalent {key}: {why}")
        for key, diff in s["survived"].items():
            print(f"  survived {key}:\n" + "\n".join("    " + line for line in diff.splitlines()[1:]))
        if s["killed_percent"] < GOAL_KILLED_PERCENT:
            missed.append(name)
    for key in summary.get("_stale_equivalents", {}).get("unknown or killed", []):
        print(f"  EQUIVALENT entry {key} names no surviving mutant: remove or renumber it")
    print(f"mutation: {elapsed:.0f} s; written to {RESULT_FILE.relative_to(ROOT)}")
    if missed:
        print(f"mutation: below the goal of {GOAL_KILLED_PERCENT:g} % killed: {', '.join(missed)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
