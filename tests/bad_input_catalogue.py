"""A catalogue of bad inputs over every entry point and file kind of the two command lines.

Each `Case` is one command line (`workbench ...` or `tuning ...`) run in a folder holding the catalogue's files
(`FILES`: a valid file of every kind, and broken ones made from them). Bad command-line values are crossed with every
option that takes them; bad files with every option that reads their kind. A case expects either a clean refusal
(exit 2, a `... error: ...` line, no traceback) or, where the input is unusual but meaningful, acceptance.

The cases are data: `tests/test_bad_input_catalogue.py` runs them. Adding a command or a file kind means adding its
baseline and readers here.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass

#: A case's expectation: refused cleanly, or accepted (it reaches the work: a simulation, a study, a fit).
REFUSED = "refused"
ACCEPTED = "accepted"


@dataclass(frozen=True)
class Case:
    """program: "workbench" or "tuning"; argv: its arguments (file names relative to the case's folder);
    expect: REFUSED or ACCEPTED; id: unique and readable."""

    id: str
    program: str
    argv: tuple[str, ...]
    expect: str = REFUSED


# ---- the files ---------------------------------------------------------------------------------------------------


def _circle_csv(radius_m: float, n: int = 60) -> str:
    rows = [
        f"{radius_m * math.cos(2 * math.pi * i / n):.4f},{radius_m * math.sin(2 * math.pi * i / n):.4f}"
        for i in range(n)
    ]
    return "x_m,y_m\n" + "\n".join([*rows, rows[0]]) + "\n"


GOOD_WAYPOINTS = "x_m,y_m\n" + "".join(f"{x},{0.02 * x:.3f}\n" for x in range(0, 61, 5))
GOOD_TRACK = "# x_m,y_m,w_tr_right_m,w_tr_left_m\n" + "".join(
    f"{60 * math.cos(2 * math.pi * i / 80):.3f},{40 * math.sin(2 * math.pi * i / 80):.3f},5.0,5.0\n" for i in range(80)
)


def _turning_log(duration_s: float = 20.0, step_s: float = 0.02, speed_mps: float = 8.33) -> str:
    """A kinematic car (wheelbase 2.579 m, ratio 15) weaving at 0.5 rad/s: a log `fit-lag` can fit."""
    rows, x, y, yaw = [], 0.0, 0.0, 0.0
    for i in range(round(duration_s / step_s)):
        steer_deg = 30.0 * math.sin(0.5 * i * step_s)
        rows.append(f"{i * step_s:.2f},{steer_deg:.4f},{speed_mps},{x:.4f},{y:.4f}\n")
        yaw += speed_mps * math.tan(math.radians(steer_deg) / 15.0) / 2.579 * step_s
        x, y = x + speed_mps * math.cos(yaw) * step_s, y + speed_mps * math.sin(yaw) * step_s
    return "t_s,steer_wheel_deg,speed_mps,x_m,y_m\n" + "".join(rows)


GOOD_LOG = _turning_log()
GOOD_LAG = {"format": "steering-lag/1", "omega_n_rad_s": 4.44, "zeta": 0.8, "delay_s": 0.0, "steady_state_gain": 0.94}
GOOD_LEAD = {"format": "lead-filter/1", "omega_z_rad_s": 4.44, "psi": 0.8, "omega_p_rad_s": 13.3}
GOOD_LIMITS = "speed_kmh,max_curvature_1pm,max_curvature_rate_1pm_s\n10,0.2,0.1\n50,0.05,0.05\n100,0.02,0.02\n"
GOOD_SPEC = """[study]
scenarios = ["dlc"]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle"]

[grid]
speed_kmh = [20, 30]
"""
GOOD_OPTIMISE = GOOD_SPEC + """
[optimise]
trials = 2

[optimise.objective]
rms_cte_m = 1.0

[optimise.search]
lookahead_gain_s = { uniform = [0.3, 1.5] }
"""
GOOD_TOURNAMENT = """[tournament]
controllers = ["pure-pursuit", "stanley"]
vehicles = ["kinematic-bicycle"]
trials = 2

[train]
scenarios = ["dlc"]
speeds_kmh = [20, 30]

[test]
scenarios = ["fig17"]
speeds_kmh = [30]
"""
GOOD_CONTROLLER_CONFIG = "[pure-pursuit]\nlookahead_gain_s = 0.8\n\n[stanley]\ngain_per_s = 4.0\n"


def _vehicle_toml() -> str:
    from workbench.vehicles import preset_text

    return preset_text("kinematic-bicycle")


def _conditions_toml() -> str:
    from workbench.simulation.conditions import conditions_to_toml, load_conditions

    return conditions_to_toml(load_conditions("automotive"))


def files() -> dict[str, str | bytes | None]:
    """name -> content (None: a folder of that name). Every case's folder holds all of them."""
    vehicle = _vehicle_toml()
    conditions = _conditions_toml()
    made: dict[str, str | bytes | None] = {
        "good.csv": GOOD_WAYPOINTS,
        "loop.csv": _circle_csv(30.0),
        "track.csv": GOOD_TRACK,
        "log.csv": GOOD_LOG,
        "lag.json": json.dumps(GOOD_LAG),
        "lead.json": json.dumps(GOOD_LEAD),
        "limits.csv": GOOD_LIMITS,
        "spec.toml": GOOD_SPEC,
        "optimise.toml": GOOD_OPTIMISE,
        "tournament.toml": GOOD_TOURNAMENT,
        "controllers.toml": GOOD_CONTROLLER_CONFIG,
        "vehicle.toml": vehicle,
        "conditions.toml": conditions,
        "folder": None,
        "occupied/file.txt": "not the workbench's",
        # file-level breakage, the same for every kind
        "empty.any": "",
        "binary.any": bytes(range(256)) * 4,
        "latin1.any": "x_m,y_m\n0,0\nstra\xdfe,1\n".encode("latin-1"),
        "deep.toml": "a = " + "[" * 5000 + "]" * 5000 + "\n",
        "deep.json": "[" * 5000 + "]" * 5000,
        "not-toml.toml": "[study\nscenarios = \n",
        "not-json.json": '{"format": "lead-filter/1", ',
        # waypoints
        "nan.csv": "x_m,y_m\n0,0\n10,nan\n20,0\n",
        "inf.csv": "x_m,y_m\n0,0\n10,inf\n20,0\n",
        "text.csv": "x_m,y_m\n0,0\n10,ten\n20,0\n",
        "one-point.csv": "x_m,y_m\n0,0\n",
        "two-same.csv": "x_m,y_m\n0,0\n0,0\n0,0\n",
        "no-y.csv": "x_m,z_m\n0,0\n10,0\n20,0\n",
        "no-header.csv": "0,0\n10,0\n20,0\n",
        "dup-col.csv": "x_m,y_m,x_m\n0,0,1\n10,0,1\n20,0,1\n",
        "doubles-back.csv": "x_m,y_m\n0,0\n10,0\n0,0.1\n",
        "zigzag.csv": "x_m,y_m\n" + "".join(f"{0.3 * i},{0.3 * (i % 2)}\n" for i in range(40)),
        "far.csv": "x_m,y_m\n0,0\n1e9,0\n2e9,0\n",
        "neg-speed.csv": "x_m,y_m,v_mps\n0,0,5\n10,0,-5\n20,0,5\n",
        "zero-speed.csv": "x_m,y_m,v_mps\n0,0,0\n10,0,0\n20,0,0\n",
        "unknown-speed.csv": "x_m,y_m,speed\n0,0,5\n10,0,5\n20,0,5\n",
        "bad-gps.csv": "lat,lon\n91,0\n92,0\n93,0\n",
        "sharp-turns.csv": "x_m,y_m\n0,0\n20,0\n20,0.5\n40,0.5\n",
        "tight-radius.csv": _circle_csv(3.0),
        "short-rows.csv": "x_m,y_m\n0,0\n10\n20,0\n",
        # track files
        "track-neg-width.csv": GOOD_TRACK.replace(",5.0,5.0\n", ",-5.0,5.0\n", 1),
        "track-nan-width.csv": GOOD_TRACK.replace(",5.0,5.0\n", ",nan,5.0\n", 1),
        "track-one-width.csv": "# x_m,y_m,w_tr_right_m\n0,0,5\n10,0,5\n20,5,5\n",
        "track-huge-width.csv": GOOD_TRACK.replace(",5.0,5.0\n", ",500.0,5.0\n", 1),
        # logs
        "log-nan.csv": GOOD_LOG.replace("8.33,", "nan,", 1),
        "log-text.csv": GOOD_LOG.replace("8.33,", "fast,", 1),
        "log-backwards.csv": GOOD_LOG.replace("\n0.02,", "\n-0.02,", 1),
        "log-no-steer.csv": GOOD_LOG.replace("steer_wheel_deg", "wheel"),
        "log-dup-col.csv": GOOD_LOG.replace("speed_mps,x_m", "speed_mps,SPEED_MPS", 1),
        "log-short.csv": "t_s,steer_wheel_deg,speed_mps,x_m,y_m\n0,0,8,0,0\n0.02,0,8,0.16,0\n",
        "log-gap.csv": GOOD_LOG.replace("\n1.00,", "\n9.00,", 1),
        "log-slow.csv": "t_s,steer_wheel_deg,speed_mps,x_m,y_m\n" + "".join(f"{i},0,8,{8 * i},0\n" for i in range(50)),
        # lag files
        **{f"lag-{k}.json": json.dumps({**GOOD_LAG, k: v}) for k, v in _bad_values(GOOD_LAG)},
        "lag-unknown.json": json.dumps({**GOOD_LAG, "omega_n": 4.0}),
        "lag-missing.json": json.dumps({"format": "steering-lag/1", "zeta": 0.8}),
        "lag-format.json": json.dumps({**GOOD_LAG, "format": "steering-lag/9"}),
        "lag-list.json": json.dumps([GOOD_LAG]),
        # lead files
        **{f"lead-{k}.json": json.dumps({**GOOD_LEAD, k: v}) for k, v in _bad_values(GOOD_LEAD)},
        "lead-unknown.json": json.dumps({**GOOD_LEAD, "omega_z": 4.0}),
        "lead-missing.json": json.dumps({"format": "lead-filter/1", "psi": 0.8}),
        "lead-dc.json": json.dumps({**GOOD_LEAD, "dc_gain": 2.0}),
        "lead-schedule.json": json.dumps({**GOOD_LEAD, "schedule": [
            {"speed_kmh": 50, "omega_z_rad_s": 4.4, "psi": 0.8, "omega_p_rad_s": 13.0},
            {"speed_kmh": 30, "omega_z_rad_s": 4.4, "psi": 0.8, "omega_p_rad_s": 13.0},
        ]}),
        "lead-pole-below-zero.json": json.dumps({**GOOD_LEAD, "omega_p_rad_s": 1.0}),
        # limits files
        "limits-nan.csv": GOOD_LIMITS.replace("0.05,0.05", "nan,0.05"),
        "limits-neg.csv": GOOD_LIMITS.replace("0.05,0.05", "-0.05,0.05"),
        "limits-order.csv": "speed_kmh,max_curvature_1pm,max_curvature_rate_1pm_s\n50,0.05,0.05\n10,0.2,0.1\n",
        "limits-cols.csv": "speed,kappa\n10,0.2\n50,0.05\n",
        "limits-dup.csv": "speed_kmh,max_curvature_1pm,max_curvature_1pm\n10,0.2,0.2\n50,0.05,0.05\n",
        "limits-text.csv": GOOD_LIMITS.replace("0.05,0.05", "wide,0.05"),
        # vehicle files
        **{f"vehicle-{name}.toml": text for name, text in _vehicle_mutations(vehicle)},
        # conditions files
        **{f"conditions-{name}.toml": text for name, text in _toml_mutations(conditions, "conditions")},
        # controller configs
        "ctl-typo-table.toml": "[stanly]\ngain_per_s = 4.0\n",
        "ctl-case-table.toml": "[Clothoid]\nfrechet_threshold_m = 0.1\n",
        "ctl-top-key.toml": "gain_per_s = 4.0\n",
        "ctl-unknown-key.toml": "[pure-pursuit]\nlookahead_gain = 0.8\n",
        "ctl-string-number.toml": '[pure-pursuit]\nlookahead_gain_s = "0.8"\n',
        "ctl-string-bool.toml": '[clothoid]\ntwo_degree_of_freedom = "false"\n',
        "ctl-nan.toml": "[pure-pursuit]\nlookahead_gain_s = nan\n",
        "ctl-inf.toml": "[pure-pursuit]\nlookahead_gain_s = inf\n",
        "ctl-neg.toml": "[pure-pursuit]\nlookahead_gain_s = -0.8\n",
        "ctl-huge.toml": "[pure-pursuit]\nmax_lookahead_m = 1e308\n",
        "ctl-array.toml": "[pure-pursuit]\nlookahead_gain_s = [0.8]\n",
        "ctl-table-value.toml": "pure-pursuit = 3\n",
        "ctl-min-max.toml": "[pure-pursuit]\nmin_lookahead_m = 20.0\nmax_lookahead_m = 5.0\n",
        "ctl-missing-file.toml": '[clothoid]\nfilter_file = "no-such-lead.json"\n',
        "ctl-bad-file.toml": '[clothoid]\nfilter_file = "lead-psi-nan.json"\n',
        "ctl-bad-limits.toml": '[clothoid]\nlimits_file = "limits-nan.csv"\n',
        "ctl-bad-lag.toml": '[nmpc]\nlag_file = "lag-zeta-neg.json"\n',
        # study specs
        **{f"spec-{name}.toml": text for name, text in _spec_mutations()},
        **{f"tournament-{name}.toml": text for name, text in _tournament_mutations()},
    }
    return made


def _bad_values(good: dict) -> Iterator[tuple[str, object]]:
    """(key-and-kind, value) pairs: each numeric field of `good` made NaN-like, negative, zero, huge, a string, null."""
    for key, value in good.items():
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        for kind, bad in (("nan", "NaN"), ("neg", -abs(value) - 1.0), ("huge", 1e308), ("str", str(value)),
                          ("null", None), ("bool", True), ("list", [value])):  # fmt: skip
            yield f"{key}-{kind}".replace("_", "-").replace("-nan", "-nan"), bad if kind != "nan" else float("nan")


def _toml_mutations(text: str, what: str) -> Iterator[tuple[str, str]]:
    """Broken versions of a TOML file: each numeric line NaN, negative, a string; an unknown key; a duplicate key."""
    lines = text.splitlines()
    numeric = [i for i, line in enumerate(lines) if "=" in line and _is_number(line.split("=", 1)[1])]
    for n, i in enumerate(numeric[:12]):
        key, value = (part.strip() for part in lines[i].split("=", 1))
        for kind, bad in (("nan", "nan"), ("neg", f"-{abs(float(value)) + 1e6}"), ("str", f'"{value}"')):
            changed = list(lines)
            changed[i] = f"{key} = {bad}"
            yield f"{n}-{key}-{kind}", "\n".join(changed) + "\n"
    tables = [i for i, line in enumerate(lines) if line.startswith("[")]
    where = tables[-1] if tables else 0
    yield "unknown-key", "\n".join([*lines[: where + 1], "no_such_key = 1", *lines[where + 1 :]]) + "\n"
    if numeric:
        yield "dup-key", "\n".join([*lines[: numeric[0] + 1], lines[numeric[0]], *lines[numeric[0] + 1 :]]) + "\n"
    yield "no-tables", "\n".join(line for line in lines if not line.startswith("[")) + "\n"


def _vehicle_mutations(text: str) -> Iterator[tuple[str, str]]:
    yield from _toml_mutations(text, "vehicle")
    yield "unknown-type", text.replace('type = "kinematic-bicycle"', 'type = "hovercraft"')
    yield "missing-field", "\n".join(line for line in text.splitlines() if not line.startswith("wheelbase_m")) + "\n"
    yield "zero-wheelbase", "\n".join(
        "wheelbase_m = 0.0" if line.startswith("wheelbase_m") else line for line in text.splitlines()
    ) + "\n"


def _spec_mutations() -> Iterator[tuple[str, str]]:
    base = GOOD_SPEC
    grid = base.replace("speed_kmh = [20, 30]\n", "")
    for key, values in (
        ("speed_kmh", ["[0]", "[-30]", "[nan]", "[1e308]", '["30"]', "[]", "30", "[0.001]", "[true]"]),
        ("laps", ["[0]", "[-1]", "[1.5]", "[100000]", '["2"]']),
        ("initial_offset_m", ["[1000]", "[nan]", "[-1e9]", '["0.5"]']),
        ("controller_rate_hz", ["[0]", "[-50]", "[nan]", "[1e9]"]),
        ("plant_rate_hz", ["[0]", "[333.3]", "[nan]"]),
        ("max_time_s", ["[0]", "[-1]", "[nan]"]),
        ("lat_accel_g", ["[0]", "[-0.3]", "[50]"]),
        ("no_such_parameter", ["[1]"]),
    ):
        for n, value in enumerate(values):
            yield f"{key}-{n}", grid + f"{key} = {value}\n"
    for key, value in (
        ("controllers", '["stanly"]'),
        ("controllers", "[]"),
        ("vehicles", '["hovercraft"]'),
        ("vehicles", "[]"),
        ("scenarios", '["moon"]'),
        ("scenarios", "[]"),
        ("controllers", '"pure-pursuit"'),
    ):
        label = value.strip('[]"') or "empty"
        yield f"{key}-{label}", base.replace(
            next(line for line in base.splitlines() if line.startswith(key)), f"{key} = {value}"
        )
    yield "no-study", base.replace("[study]\n", "")
    yield "unknown-table", base + "\n[gird]\nspeed_kmh = [10]\n"
    yield "unknown-study-key", base.replace("[study]\n", "[study]\nsamples_per_run = 3\n")
    yield "bad-controller-option", base + "\n[grid.pure-pursuit]\nlookahead_gain_s = [-1.0]\n"
    yield "unknown-controller-option", base + "\n[grid.pure-pursuit]\nlookahead_gain = [1.0]\n"
    yield "option-of-other-controller", base + "\n[grid.stanley]\ngain_per_s = [1.0]\n"
    yield "random-without-samples", base + "\n[random]\nspeed_kmh = { uniform = [20, 30] }\n"
    yield "random-bad-range", base + '\n[study]\nsamples = 3\n[random]\nspeed_kmh = { uniform = [30, 20] }\n'
    yield "max-runs-zero", base.replace("[study]\n", "[study]\nmax_runs = 0\n")
    yield "huge", base.replace("speed_kmh = [20, 30]", "speed_kmh = [" + ", ".join(str(20 + i * 1e-3) for i in range(
        3000)) + "]").replace("[study]\n", "[study]\nmax_runs = 100\n")  # fmt: skip
    searched = "\n[optimise.objective]\nrms_cte_m = 1.0\n"
    searched += "[optimise.search]\nlookahead_gain_s = { uniform = [0.3, 1.5] }\n"
    yield "optimise-no-trials", base + "\n[optimise]" + searched
    yield "optimise-zero-trials", base + "\n[optimise]\ntrials = 0" + searched
    yield "optimise-bad-range", base + "\n[optimise]\ntrials = 2" + searched.replace("[0.3, 1.5]", "[1.5, 0.3]")
    yield "optimise-unknown-option", base + "\n[optimise]\ntrials = 2" + searched.replace("lookahead_gain_s", "gain")
    yield "optimise-unknown-draw", base + "\n[optimise]\ntrials = 2" + searched.replace("uniform", "gaussian")
    yield "optimise-bad-objective", base + '\n[optimise]\ntrials = 2\nobjective = "fastest"\n'
    yield "optimise-unknown-metric", base + "\n[optimise]\ntrials = 2\n[optimise.objective]\nspeed = 1.0\n"


def _tournament_mutations() -> Iterator[tuple[str, str]]:
    base = GOOD_TOURNAMENT
    head = "trials = 2\n"
    for name, line in (
        ("trials-0", "trials = 0"),
        ("trials-float", "trials = 1.5"),
        ("trials-text", 'trials = "2"'),
        ("batch-size-0", "trials = 2\nbatch_size = 0"),
        ("front-points-6", "trials = 2\nfront_points = 6"),
        ("seed-negative", "trials = 2\nseed = -1"),
        ("objectives-unknown", 'trials = 2\nobjectives = ["speed"]'),
        ("objectives-empty", "trials = 2\nobjectives = []"),
        ("selection-not-an-objective", "trials = 2\nselection = {max_ltr = 1.0}"),
        ("selection-negative", "trials = 2\nselection = {max_abs_cte_m = -1.0}"),
        ("selection-zero", "trials = 2\nselection = {max_abs_cte_m = 0.0}"),
        ("ranking-nan", "trials = 2\nranking = {max_abs_cte_m = nan}"),
        ("failure-score-text", 'trials = 2\nfailure_score = "high"'),
        ("inform-delays-text", 'trials = 2\ninform_delays = "yes"'),
        ("max-runs-0", "trials = 2\nmax_runs = 0"),
        ("max-runs-exceeded", "trials = 2\nmax_runs = 5"),
        ("unknown-key", "trials = 2\nbudget = 2"),
    ):
        yield name, base.replace(head, line + "\n")
    yield "no-trials", base.replace(head, "")
    yield "no-test", base.split("[test]")[0]
    yield "unknown-table", base + "\n[study]\nscenarios = []\n"
    yield "controllers-unknown", base.replace('"stanley"]', '"stanly"]')
    yield "controllers-empty", base.replace('["pure-pursuit", "stanley"]', "[]")
    yield "vehicles-unknown", base.replace('["kinematic-bicycle"]', '["hovercraft"]')
    yield "set-unknown-key", base.replace("speeds_kmh = [30]", "speeds_kmh = [30]\nlaps = 2")
    yield "speed-zero", base.replace("speeds_kmh = [30]", "speeds_kmh = [0]")
    yield "speed-empty", base.replace("speeds_kmh = [30]", "speeds_kmh = []")
    yield "seeds-negative", base.replace("speeds_kmh = [30]", "speeds_kmh = [30]\nseeds = [-1]")
    yield "conditions-unknown", base.replace("speeds_kmh = [30]", 'speeds_kmh = [30]\nconditions = ["foggy"]')
    yield "scenario-unknown", base.replace('["fig17"]', '["moon"]')
    yield "case-in-both-sets", base.replace('["fig17"]', '["fig17", "dlc"]')
    yield "search-default-outside", base + "\n[search.stanley]\ngain_per_s = {uniform = [2.0, 3.0]}\n"
    yield "search-unknown-option", base + "\n[search.stanley]\ngain = {uniform = [1.0, 3.0]}\n"
    yield "search-unbounded", base + "\n[search.stanley]\ngain_per_s = {normal = [1.5, 0.5]}\n"
    yield "search-other-controller", base + "\n[search.clothoid]\nprediction_time_s = {uniform = [0.1, 0.3]}\n"
    yield "fixed-bad-value", base + "\n[fixed.stanley]\ngain_per_s = -1.0\n"
    searched = "\n[search.stanley]\ngain_per_s = {uniform = [1.0, 3.0]}\n"
    yield "fixed-and-searched", base + searched + "[fixed.stanley]\ngain_per_s = 2.0\n"


def _is_number(text: str) -> bool:
    try:
        float(text.strip())
    except ValueError:
        return False
    return True


# ---- the cases ---------------------------------------------------------------------------------------------------

#: Bad values of a number option, each refused wherever a positive number is asked.
BAD_NUMBERS = ("nan", "inf", "-inf", "-1", "0", "1e308", "abc", "", "1e-300", "0x10")
#: File-level breakage of any input file.
BROKEN_FILES = ("no-such-file.any", "folder", "empty.any", "binary.any", "latin1.any")

WB_BASE = {
    "run": ("run", "good.csv", "--controller", "pure-pursuit", "--out", "out", "--no-plots"),
    "compare": ("compare", "good.csv", "--controllers", "pure-pursuit,stanley", "--vehicle", "kinematic-bicycle",
                "--out", "out", "--no-plots"),
    "fig17": ("fig17", "--out", "out"),
    "paper": ("paper", "--out", "out"),
    "robustness": ("robustness", "good.csv", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--out",
                   "out"),
    "sweep": ("sweep", "spec.toml", "--out", "out", "--no-plots"),
    "optimise": ("optimise", "optimise.toml", "--out", "out"),
    "tournament": ("tournament", "tournament.toml", "--out", "out"),
    "export-fmu": ("export-fmu", "pure-pursuit", "--path", "good.csv", "--out", "controller.fmu"),
}
TUNING_BASE = {
    "generate-data": ("generate-data", "--vehicle", "kinematic-bicycle", "--maneuver", "step", "--speed", "30", "--out",
                      "new-log.csv"),
    "fit-lag": ("fit-lag", "log.csv", "--vehicle", "kinematic-bicycle", "--out", "new-lag.json"),
    "design-lead": ("design-lead", "--lag", "lag.json", "--out", "new-lead.json"),
    "rollover-limits": ("rollover-limits", "--vehicle", "tractor-semitrailer", "--speeds", "30,60", "--out",
                        "new-limits.csv"),
    "steering-limits": ("steering-limits", "--vehicle", "kinematic-bicycle", "--speeds", "30,60", "--out",
                        "new-limits.csv"),
    "schedule": ("schedule", "--vehicle", "dynamic-bicycle", "--speeds", "30", "--out", "new-lead.json"),
    "margins": ("margins", "--lag", "lag.json", "--lead", "lead.json", "--vehicle", "kinematic-bicycle", "--speeds",
                "30", "--out", "margins.csv"),
}

#: Number options: (programs' commands having it, option, the bad values that do not apply to it, i.e. are valid).
NUMBER_OPTIONS: tuple[tuple[str, tuple[str, ...], str, frozenset[str]], ...] = (
    ("workbench", ("run", "compare", "fig17", "robustness", "export-fmu"), "--speed", frozenset()),
    ("workbench", ("run", "compare", "export-fmu"), "--payload-kg", frozenset({"0"})),
    ("workbench", ("run", "compare"), "--laps", frozenset()),
    ("workbench", ("run", "compare", "export-fmu"), "--controller-rate-hz", frozenset()),
    ("workbench", ("run", "compare"), "--plant-rate-hz", frozenset()),
    ("workbench", ("run", "compare", "export-fmu"), "--lat-accel-g", frozenset()),
    ("workbench", ("run", "compare"), "--max-time-s", frozenset()),
    ("workbench", ("run", "compare", "fig17", "robustness"), "--seed", frozenset({"0"})),
    ("workbench", ("robustness",), "--max-cte", frozenset()),
    ("workbench", ("robustness", "sweep", "optimise", "tournament"), "--workers", frozenset()),
    ("workbench", ("robustness", "sweep", "optimise", "tournament"), "--max-runs", frozenset()),
    ("tuning", ("generate-data",), "--speed", frozenset()),
    ("tuning", ("generate-data",), "--amplitude-deg", frozenset()),
    ("tuning", ("generate-data",), "--duration-s", frozenset()),
    ("tuning", ("generate-data",), "--max-rate-deg-s", frozenset()),
    ("tuning", ("generate-data",), "--sample-rate-hz", frozenset()),
    ("tuning", ("generate-data", "steering-limits", "schedule"), "--lat-accel-g", frozenset()),
    ("tuning", ("generate-data", "rollover-limits"), "--payload-kg", frozenset({"0"})),
    ("tuning", ("fit-lag",), "--smooth-s", frozenset({"0"})),
    ("tuning", ("fit-lag",), "--max-speed-variation", frozenset()),
    ("tuning", ("design-lead", "schedule"), "--max-lead-gain", frozenset()),
    ("tuning", ("design-lead", "schedule"), "--max-cascade-peak-db", frozenset()),
    ("tuning", ("schedule", "margins"), "--controller-rate-hz", frozenset()),
    ("tuning", ("schedule", "margins"), "--prediction-time-s", frozenset({"0"})),
    ("tuning", ("schedule",), "--nominal-speed", frozenset()),
    ("tuning", ("schedule",), "--preview-past-s", frozenset({"0"})),
    ("tuning", ("schedule",), "--preview-future-s", frozenset({"0"})),
    ("tuning", ("margins",), "--phase-margin-deg", frozenset()),
    ("tuning", ("margins",), "--gain-margin-db", frozenset()),
)

#: Input-file options: (program, commands, option, the kind's own broken files besides BROKEN_FILES).
FILE_OPTIONS: tuple[tuple[str, tuple[str, ...], str, tuple[str, ...]], ...] = (
    ("workbench", ("run", "compare", "export-fmu"), "--vehicle-file", ()),
    ("workbench", ("run", "compare", "export-fmu"), "--controller-config", ("deep.toml", "not-toml.toml")),
    ("workbench", ("run", "compare", "fig17", "robustness"), "--conditions", ("deep.toml", "not-toml.toml")),
    ("workbench", ("paper", "run", "compare", "robustness", "export-fmu"), "--track", ()),
    ("workbench", ("run", "compare", "robustness", "export-fmu"), "--circuit-ranges", ("deep.toml", "not-toml.toml")),
    ("tuning", ("generate-data", "fit-lag", "rollover-limits", "steering-limits", "schedule"), "--vehicle-file", ()),
    ("tuning", ("design-lead", "margins"), "--lag", ("deep.json", "not-json.json")),
    ("tuning", ("margins",), "--lead", ("deep.json", "not-json.json")),
    ("tuning", ("margins",), "--measured-lag", ("deep.json", "not-json.json")),
    ("tuning", ("design-lead",), "--validate", ()),
)


#: Unusual inputs that mean something, accepted: case id -> what they mean.
MEANINGFUL = {
    "tuning-design-lead---max-cascade-peak-db=0": "a cascade without any resonance peak",
    "tuning-design-lead---max-cascade-peak-db=1e-300": "as 0 dB",
    "tuning-schedule---max-cascade-peak-db=0": "a cascade without any resonance peak",
    "tuning-schedule---max-cascade-peak-db=1e-300": "as 0 dB",
    "tuning-generate-data---amplitude-deg=-1": "a step to the right",
    "tuning-generate-data---amplitude-deg=1e-300": "the plant driven straight: a log's noise floor",
    "tuning-generate-data---lat-accel-g=1e-300": "as an amplitude of (nearly) zero",
    "tuning-generate-data---max-rate-deg-s=1e-300": "the steering held: the plant driven straight",
    "tuning-margins---gain-margin-db=0": "stability alone, no gain margin asked",
    "tuning-margins---gain-margin-db=1e-300": "as 0 dB",
    "tuning-margins---phase-margin-deg=0": "stability alone, no phase margin asked",
    "tuning-margins---phase-margin-deg=1e-300": "as 0 deg",
    "tuning-margins---prediction-time-s=1e-300": "no prediction, as 0 s",
    "tuning-schedule---prediction-time-s=1e-300": "no prediction, as 0 s",
    "tuning-schedule---preview-past-s=1e-300": "no past taps, as 0 s",
    "tuning-schedule---preview-future-s=1e-300": "no future taps, as 0 s",
    "tuning-rollover-limits---payload-kg=1e-300": "an empty trailer",
    "tuning-fit-lag---max-speed-variation=0": "a log held at exactly one speed (this one is)",
    "tuning-fit-lag---max-speed-variation=1e-300": "as 0",
    "tuning-fit-lag---smooth-s=1e-300": "no smoothing, as 0 s",
    "tuning-generate-data---max-rate-deg-s=1e308": "no steering-rate limit",
    "workbench-robustness---max-cte=1e308": "every run that completes passes",
    "workbench-robustness---max-cte=1e-300": "no run passes: a strict judge",
    "workbench-run---conditions=empty.any": "a conditions file giving no key: every default (ideal)",
    "workbench-compare---conditions=empty.any": "as for run",
    "workbench-fig17---conditions=empty.any": "as for run",
    "workbench-robustness---conditions=empty.any": "as for run",
    "workbench-run---controller-config=empty.any": "no table: the defaults, with a warning naming none",
    "workbench-compare---controller-config=empty.any": "as for run",
    "workbench-export-fmu---controller-config=empty.any": "as for run",
    "workbench-compare-controller-config=ctl-bad-file.toml": "a table for another controller only: not read",
    "workbench-compare-controller-config=ctl-bad-lag.toml": "a table for another controller only: not read",
    "workbench-compare-controller-config=ctl-bad-limits.toml": "a table for another controller only: not read",
    "workbench-compare-controller-config=ctl-missing-file.toml": "a table for another controller only: not read",
    "workbench-compare-controller-config=ctl-string-bool.toml": "a table for another controller only: not read",
    "workbench-sweep-spec=spec-controllers-pure-pursuit.toml": "one name for a list of names",
    "workbench-sweep-spec=spec-speed_kmh-6.toml": "one value for a grid of values",
    "workbench-run-zandvoort-track=good.csv": "another track for the zandvoort scenario: named by its file, no verdict",
}


def _with(base: tuple[str, ...], option: str, value: str) -> tuple[str, ...]:
    """`base` with `option` set to `value` (replacing the option's value when `base` has it)."""
    args = list(base)
    if option in args:
        args[args.index(option) + 1] = value
        return tuple(args)
    return (*args, option, value)


def _positional(base: tuple[str, ...], index: int, value: str) -> tuple[str, ...]:
    args = list(base)
    args[index] = value
    return tuple(args)


def cases() -> list[Case]:
    """Every case of the catalogue."""
    made: list[Case] = []
    add = made.append
    names = files()
    bases = {"workbench": WB_BASE, "tuning": TUNING_BASE}

    # every baseline is itself accepted, so that each refusal below is the mutation's
    for program, commands in bases.items():
        for command, base in commands.items():
            add(Case(f"{program}-{command}-baseline", program, base, ACCEPTED))

    # bad numbers on every number option
    for program, commands, option, valid in NUMBER_OPTIONS:
        for command in commands:
            base = bases[program][command]
            for value in BAD_NUMBERS:
                if value in valid:
                    continue
                add(Case(f"{program}-{command}-{option}={value or 'empty'}", program, _with(base, option, value)))

    # broken files on every file option
    for program, commands, option, own in FILE_OPTIONS:
        for command in commands:
            base = bases[program][command]
            for name in (*BROKEN_FILES, *own):
                add(Case(f"{program}-{command}-{option}={name}", program, _with(base, option, name)))

    # waypoint files as the scenario of run, compare and robustness
    waypoints = [n for n in names if n.endswith(".csv") and not n.startswith(("log", "limits", "track"))]
    waypoints = [n for n in waypoints if n not in ("good.csv", "loop.csv")] + list(BROKEN_FILES)
    for command in ("run", "compare", "robustness"):
        for name in waypoints:
            add(Case(f"workbench-{command}-scenario={name}", "workbench", _positional(WB_BASE[command], 1, name)))
        for name in ("moon", "DLC", ""):
            add(Case(f"workbench-{command}-scenario-name={name or 'empty'}", "workbench",
                     _positional(WB_BASE[command], 1, name)))  # fmt: skip
    for name in [*waypoints, "moon", "DLC", ""]:  # export-fmu's --path takes what a scenario takes
        add(Case(f"workbench-export-fmu-path={name or 'empty'}", "workbench",
                 _with(WB_BASE["export-fmu"], "--path", name)))  # fmt: skip
    for name in ("stanly", "", "clothoid,stanley"):
        add(Case(f"workbench-export-fmu-controller={name or 'empty'}", "workbench",
                 _positional(WB_BASE["export-fmu"], 1, name)))  # fmt: skip
    for name in ("controller.zip", "folder", "no-such-folder/controller.fmu"):
        add(Case(f"workbench-export-fmu-out={name}", "workbench", _with(WB_BASE["export-fmu"], "--out", name)))

    # track files for the zandvoort scenario and the paper
    tracks = [n for n in names if n.startswith("track-")] + ["good.csv"]
    for name in tracks:
        add(Case(f"workbench-run-zandvoort-track={name}", "workbench",
                 (*_positional(WB_BASE["run"], 1, "zandvoort"), "--track", name)))  # fmt: skip
    for name in [n for n in names if n.startswith("track-")]:
        add(Case(f"workbench-paper-track={name}", "workbench", _with(WB_BASE["paper"], "--track", name)))
        add(Case(f"workbench-scenarios-track={name}", "workbench", ("scenarios", "--track", name)))

    # vehicle files
    for name in [n for n in names if n.startswith("vehicle-")]:
        add(Case(f"workbench-run-vehicle-file={name}", "workbench", _with(WB_BASE["run"], "--vehicle-file", name)))
        add(Case(f"tuning-steering-limits-vehicle-file={name}", "tuning",
                 _with(TUNING_BASE["steering-limits"][:1] + TUNING_BASE["steering-limits"][3:], "--vehicle-file",
                       name)))  # fmt: skip

    # conditions files
    for name in [n for n in names if n.startswith("conditions-")]:
        add(Case(f"workbench-run-conditions={name}", "workbench", _with(WB_BASE["run"], "--conditions", name)))

    # controller configs: run (with the controller they would configure) and compare
    for name in [n for n in names if n.startswith("ctl-")]:
        content = str(names[name])
        controller = "clothoid" if "[clothoid]" in content else "nmpc" if "[nmpc]" in content else "pure-pursuit"
        run = _with(_with(WB_BASE["run"], "--controller", controller), "--controller-config", name)
        add(Case(f"workbench-run-controller-config={name}", "workbench", run))
        add(Case(f"workbench-compare-controller-config={name}", "workbench",
                 _with(WB_BASE["compare"], "--controller-config", name)))  # fmt: skip

    # lag, lead and limits files through the controllers' file options and the tuning commands
    for name in [n for n in names if n.startswith("lead-")]:
        add(Case(f"workbench-run-set-filter-file={name}", "workbench",
                 (*_with(WB_BASE["run"], "--controller", "clothoid"), "--set", f"filter_file={name}")))  # fmt: skip
        add(Case(f"tuning-margins-lead={name}", "tuning", _with(TUNING_BASE["margins"], "--lead", name)))
    for name in [n for n in names if n.startswith("lag-")]:
        add(Case(f"tuning-design-lead-lag={name}", "tuning", _with(TUNING_BASE["design-lead"], "--lag", name)))
        add(Case(f"workbench-run-set-lag-file={name}", "workbench",
                 (*_with(WB_BASE["run"], "--controller", "nmpc"), "--set", f"lag_file={name}")))  # fmt: skip
    for name in [n for n in names if n.startswith("limits-")]:
        add(Case(f"workbench-run-set-limits-file={name}", "workbench",
                 (*_with(WB_BASE["run"], "--controller", "clothoid"), "--set", f"limits_file={name}")))  # fmt: skip

    # vehicle logs
    for name in [n for n in names if n.startswith("log-")]:
        add(Case(f"tuning-fit-lag-log={name}", "tuning", _positional(TUNING_BASE["fit-lag"], 1, name)))
    for name in BROKEN_FILES:
        add(Case(f"tuning-fit-lag-log={name}", "tuning", _positional(TUNING_BASE["fit-lag"], 1, name)))

    # study specs
    for name in [n for n in names if n.startswith("spec-")] + list(BROKEN_FILES) + ["deep.toml", "not-toml.toml"]:
        command = "optimise" if "optimise" in name else "sweep"
        add(Case(f"workbench-{command}-spec={name}", "workbench", _positional(WB_BASE[command], 1, name)))

    # tournament specs
    for name in [n for n in names if n.startswith("tournament-")] + list(BROKEN_FILES) + ["deep.toml", "not-toml.toml"]:
        add(Case(f"workbench-tournament-spec={name}", "workbench", _positional(WB_BASE["tournament"], 1, name)))

    # --set text
    for text in ("lookahead_gain_s", "lookahead_gain_s=", "=0.8", "lookahead_gain=0.8", "lookahead_gain_s=abc",
                 "lookahead_gain_s=nan", "lookahead_gain_s=-1", "lookahead_gain_s=1e999", "filter_file=lead.json",
                 "max_lookahead_m=1e308"):  # fmt: skip
        add(Case(f"workbench-run-set={text}", "workbench", (*WB_BASE["run"], "--set", text)))
    for text in ("stanly:gain_per_s=4", "pure-pursuit:gain_per_s=4", "gain_per_s=4", ":gain_per_s=4",
                 "stanley:gain_per_s=nan"):  # fmt: skip
        add(Case(f"workbench-compare-set={text}", "workbench", (*WB_BASE["compare"], "--set", text)))

    # names
    for command, option, values in (
        ("run", "--controller", ("stanly", "Clothoid", "", "pure_pursuit")),
        ("run", "--vehicle", ("hovercraft", "Kinematic-Bicycle", "")),
        ("compare", "--controllers", ("stanly", ",", "pure-pursuit,,stanly", "")),
        ("compare", "--vehicle", ("hovercraft", ",", "")),
        ("robustness", "--controllers", ("stanly", ",")),
        ("robustness", "--vehicle", ("hovercraft", "")),
        ("run", "--conditions", ("foggy", "")),
        ("fig17", "--conditions", ("foggy",)),
        ("robustness", "--backend", ("spark",)),
        ("sweep", "--backend", ("spark",)),
        ("sweep", "--scheduler", ("not a url", "tcp://", "http://[::1")),
    ):
        for value in values:
            args = _with(WB_BASE[command], option, value)
            if option == "--scheduler":
                args = (*args, "--backend", "dask")
            add(Case(f"workbench-{command}-{option}={value or 'empty'}", "workbench", args))
    for command, option, values in (
        ("generate-data", "--vehicle", ("hovercraft", "")),
        ("generate-data", "--maneuver", ("loop-the-loop",)),
        ("generate-data", "--chirp-hz", ("abc", "0.1", "5,0.1", "nan,1", "-1,2")),
        ("schedule", "--speeds", ("", "abc", "30,nan", "-30", "0", "30,30", "1e308")),
        ("steering-limits", "--speeds", ("", "abc", "30,nan", "-30", "60,30")),
        ("rollover-limits", "--speeds", ("", "abc", "-30")),
        ("margins", "--speeds", ("", "abc", "-30")),
        ("margins", "--lookahead", ("abc", "-5", "0", "5:2", "nan")),
        ("schedule", "--design", ("magic",)),
        ("fit-lag", "--curvature-from", ("gyro",)),
        ("design-lead", "--format", ("yaml",)),
    ):
        for value in values:
            add(Case(f"tuning-{command}-{option}={value or 'empty'}", "tuning",
                     _with(TUNING_BASE[command], option, value)))  # fmt: skip

    # outputs: a file where a folder is wanted, a folder under a file, a non-empty folder
    for command, base in WB_BASE.items():
        for value in ("good.csv", "good.csv/out", "occupied"):
            if command in ("robustness", "sweep", "optimise") and value == "occupied":
                continue  # a study's folder may hold other files: it resumes there
            add(Case(f"workbench-{command}-out={value}", "workbench", _with(base, "--out", value)))
    for command, base in TUNING_BASE.items():
        for value in ("folder", "good.csv/x.csv", "good.csv"):
            add(Case(f"tuning-{command}-out={value}", "tuning", _with(base, "--out", value)))

    # issue-named cases that are not covered above
    add(Case("workbench-run-open-path-laps=2", "workbench", (*WB_BASE["run"], "--laps", "2")))
    add(Case("workbench-run-open-path-laps=1e9", "workbench", (*WB_BASE["run"], "--laps", "1000000000")))
    add(Case("workbench-run-loop-laps=100000", "workbench", _with(_positional(WB_BASE["run"], 1, "loop.csv"),
                                                                  "--laps", "100000")))  # fmt: skip
    add(Case("workbench-run-speed=0.001", "workbench", _with(WB_BASE["run"], "--speed", "0.001")))
    add(Case("workbench-run-loop-laps=2", "workbench", _with(_positional(WB_BASE["run"], 1, "loop.csv"), "--laps", "2"),
             ACCEPTED))  # fmt: skip
    add(Case("workbench-run-good", "workbench", WB_BASE["run"], ACCEPTED))
    add(Case("workbench-run-plant-rate-not-multiple", "workbench", _with(WB_BASE["run"], "--plant-rate-hz", "1001")))
    add(Case("workbench-run-payload-on-car", "workbench", (*WB_BASE["run"], "--payload-kg", "1000")))
    add(Case("workbench-run-vehicle-and-mismatched-file", "workbench",
             (*WB_BASE["run"], "--vehicle", "tractor-semitrailer", "--vehicle-file", "vehicle.toml")))  # fmt: skip
    add(Case("workbench-controllers-show-unknown", "workbench", ("controllers", "--show", "stanly")))
    add(Case("workbench-controllers-search-space-without-show", "workbench", ("controllers", "--search-space")))
    add(Case("workbench-controllers-search-space-unknown", "workbench", ("controllers", "--show", "stanly",
             "--search-space")))  # fmt: skip
    add(Case("workbench-vehicles-show-unknown", "workbench", ("vehicles", "--show", "hovercraft")))
    add(Case("workbench-conditions-show-unknown", "workbench", ("conditions", "--show", "foggy")))
    add(Case("workbench-no-command", "workbench", ()))
    add(Case("workbench-unknown-command", "workbench", ("fly",)))
    add(Case("tuning-no-command", "tuning", ()))
    add(Case("tuning-fit-lag-no-geometry", "tuning", ("fit-lag", "log.csv", "--out", "new-lag.json")))
    add(Case("tuning-generate-data-duration=1e9", "tuning", _with(TUNING_BASE["generate-data"], "--duration-s", "1e9")))

    made = [Case(c.id, c.program, c.argv, ACCEPTED) if c.id in MEANINGFUL else c for c in made]
    ids = [c.id for c in made]
    unknown = MEANINGFUL.keys() - set(ids)
    if unknown:
        raise ValueError(f"MEANINGFUL names cases the catalogue does not have: {sorted(unknown)}")
    duplicated = {i for i in ids if ids.count(i) > 1}
    if duplicated:
        raise ValueError(f"catalogue ids are not unique: {sorted(duplicated)[:5]}")
    return made
