"""Where the clothoid controller's cross-track error comes from: one factor switched at a time, in simulation and in
the loop analysis, on the loaded truck and the dynamic-bicycle car, against the NMPC on the same runs.

Switches (each against `nominal`, the shipped defaults on the preset vehicle):
  - no_actuator_lag: the plant's steering actuator without its first-order lag (time constant 1 ms instead of the
    preset's 0.1 s truck / 0.05 s car); the rest of the steering-to-curvature lag (tyre relaxation, yaw and
    sideslip dynamics) stays;
  - stiff_tyres: the plant's cornering coefficients at the top of their allowed range (truck 30 /rad, about 6 x;
    car 60 /rad, about 2.7 x) and a 0.05 m relaxation length: much less tyre slip and sideslip, in braking
    and cornering alike;
  - constant_speed: the speed profile's lateral bound lifted (2 g), so every run is at 30 km/h throughout: no
    braking or accelerating anywhere (corners are then taken faster than the profile's 0.3 g);
  - floor_lowered: the lookahead floor keeps 30 deg / 3 dB instead of 45 deg / 6 dB;
  - floor_off: no floor (the paper's 5 m lower end; margins not kept);
  - feedforward_off: Eq. 3 alone (`path_feedforward=false`);
  - feedforward_rate: the feed-forward's other form, the path's curvature rate (averaged over 6 m) at the lags'
    low-frequency delay ahead, integrated through the lead filter, and the reference pose a first-order lead ahead
    (`feedforward_inversion=false`, `feedforward_window_m=6`);
  - reference_lead: the lag inverted, the feedback's reference pose the first-order lead ahead instead of on the
    curvature the lags give (`lag_model_reference=false`; with the preview responses, which the truck uses by
    default, it changes nothing);
  - lag_model, preview_model: the feed-forward and the reference curvature from the lags of Eq. 5
    (`feedforward_model='lag'`) or from the preview responses identified from the same logs ('preview'); by default
    ('auto') the truck uses the preview responses and the car the lags, so on each one of the two is nominal;
  - handling_off: the preview responses' steering taps without their handling gain (`handling_gain=false`: linear
    at any lateral acceleration, as identified at 0.2 g; no change where the lags are used);
  - nmpc_identified_lag: the clothoid controller as by default against the NMPC predicting with the identified lag
    of Eq. 5 the clothoid controller is designed on (its `kinematic-lag` model, the lag at 30 km/h) instead of the
    vehicle's single-track equivalent: how much of the gap is the model each is given, not the control law.
  - ideal_plant: no_actuator_lag + stiff_tyres + constant_speed together (what the controller's geometry and floor
    leave);
  - perfect_prediction (automotive only, both controllers): each controller handed the plant's true state one
    actuation dead time ahead (`SimulationConfig.perfect_prediction`) and told only the sensing delays: what a
    perfect compensation of the dead time reaches, against each one's own predictor (the clothoid controller's
    lags of Eq. 5, `delay_predictor.py`; the NMPC's single-track model) in the nominal run.
Both controllers are built for the vehicle they drive: the clothoid controller with that plant's own tuning (its lags
identified, its lead filter designed and its floor computed by the tuning chain; about a minute per switched plant
the first time, cached after: `tuning/own_tuning.py`), the NMPC with that plant's model. So a plant switch shows what
the factor costs a controller designed for it, not a model mismatch. The NMPC runs every plant and speed switch too;
a controller switch is compared with the nominal NMPC run.

Loop analysis (30 km/h, `controllers/clothoid/loop_analysis.py`, about a straight): the floor, the margins at it and
the closed-loop bandwidth (|T| = |L / (1 + L)| falling to -3 dB, the loop broken at the steering sent) with the
identified lags and the lead filter of each switched plant's own tuning (no actuator lag, stiff tyres, both), and
with the nominal lags altered: the measured curvature without the sideslip's lead (the measured lag = the path
lag), no understeer (K = 1), the speeds a braking truck passes (20 and 25 km/h), the floor lowered or off.
The feed-forward does not enter the loop (its term depends on the path only), so it changes nothing there.

The clothoid controller's models of the vehicle, checked along the NMPC's nominal run in ideal conditions (which
keeps within a few centimetres of the path, so it stands for a vehicle following the path; `model_errors`), each
from the lags of Eq. 5 and (prefixed preview_) from the preview responses (`preview_model.preview_curvature`):
  - reference: the curvature the feedback's reference pose starts on (`step_kernel.reference_curvature`, the yaw
    rate / speed that a vehicle following the path measures, from the identified lags) against the yaw rate / speed
    measured on the run; the feedback reads any difference as an error of the vehicle's;
  - feedforward: the lag-inverting feed-forward (`path_feedforward.lag_inverse_curvature`) against the steering the
    NMPC sent, both as kinematic curvature tan(road wheel angle) / wheelbase.
Each as RMS and max (1/m) and the RMS over the path curvature's RMS on the run.

Prints the tables and writes benchmarks/results/cte_breakdown.json and one figure per vehicle
(benchmarks/results/cte_breakdown_<vehicle>.png: |CTE| against distance for each switch on the worst case, with the
path curvature and the longitudinal acceleration beneath). About 4-6 minutes on 2 shared cores, and once about a
minute per switched plant for its tuning (cached after).

    python benchmarks/cte_breakdown.py [--out benchmarks/results/cte_breakdown.json] [--vehicles a,b]
        [--scenarios dlc,figure8,circuit:1000,...] [--workers 2] [--no-automotive] [--figures-dir DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from benchmark_report import machine, write_results

from tuning.own_tuning import tuned_controller, tuning_for
from workbench.simulation.conditions import CONDITIONS
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

VEHICLES = ("tractor-semitrailer", "dynamic-bicycle")
#: dlc, figure8 and four circuits of the development set (seeds below 9000 only: 9000 and up are held out).
SCENARIOS = ("dlc", "figure8", "circuit:1000", "circuit:1001", "circuit:1002", "circuit:1003")
AUTOMOTIVE_SCENARIOS = ("dlc", "figure8")
#: Generated circuits from this seed up are the held-out set (`benchmarks/steering.py`): refused here.
HELD_OUT_FIRST_SEED = 9000
SPEED_KMH = 30.0
#: switch -> (plant changes, run-config changes, clothoid config changes).
PLANT_SWITCHES = ("no_actuator_lag", "stiff_tyres", "constant_speed", "ideal_plant")
CONTROLLER_SWITCHES = (
    "floor_lowered", "floor_off", "feedforward_off", "feedforward_rate", "reference_lead", "lag_model",
    "preview_model", "handling_off",
)  # fmt: skip
#: The feed-forward's curvature-rate window (m) in its rate form (the feedforward_rate switch).
RATE_FEEDFORWARD_WINDOW_M = 6.0
#: Switches of the NMPC's model (the clothoid controller runs as nominal).
MODEL_SWITCHES = ("nmpc_identified_lag",)
#: Switches of the conditions, run under automotive only, by both controllers.
DELAY_SWITCHES = ("perfect_prediction",)
SWITCHES = ("nominal", *PLANT_SWITCHES, *CONTROLLER_SWITCHES, *MODEL_SWITCHES, *DELAY_SWITCHES)
#: The plant's actuator time constant (s) with its lag switched off (the smallest the presets allow).
NO_LAG_TIME_CONSTANT_S = 1e-3
#: Stiff tyres: cornering coefficients (1/rad) at the top of each model's allowed range, relaxation length (m).
STIFF_CORNERING_PER_RAD = {"tractor-semitrailer": 30.0, "dynamic-bicycle": 60.0}
STIFF_RELAXATION_M = 0.05
#: The profile's lateral bound (g) that leaves the speed at SPEED_KMH everywhere.
CONSTANT_SPEED_LATERAL_G = 2.0
#: Longitudinal acceleration is smoothed over this many controller samples (0.1 s) before it is read.
ACCEL_SMOOTHING_SAMPLES = 5
#: The models are checked where the vehicle moves faster than this (m/s): the yaw rate over speed is defined there.
MODEL_CHECK_MIN_SPEED_MPS = 1.0


def plant_for(vehicle_name: str, switch: str):
    """The vehicle the run drives: the preset, or the preset with the switch's plant changes."""
    vehicle = make_vehicle(vehicle_name)
    changes: dict[str, float] = {}
    if switch in ("no_actuator_lag", "ideal_plant"):
        changes["steering_time_constant_s"] = NO_LAG_TIME_CONSTANT_S
    if switch in ("stiff_tyres", "ideal_plant"):
        stiff = STIFF_CORNERING_PER_RAD[vehicle_name]
        names = [f"{axle}_cornering_coeff_per_rad" for axle in ("front", "rear", "drive", "trailer")]
        changes |= {name: stiff for name in names if hasattr(vehicle.params, name)}
        changes["relaxation_length_m"] = STIFF_RELAXATION_M
    if not changes:
        return vehicle
    return type(vehicle)(dataclasses.replace(vehicle.params, **changes))


def switched_plants(jobs: list[tuple[str, str, str, str, str]]) -> list[tuple[str, str]]:
    """(vehicle, plant switch) of `jobs` (`jobs_for`'s), each once."""
    return sorted({(v, sw) for v, _, sw, _, _ in jobs if sw in PLANT_SWITCHES})


def tune_plant(plant: tuple[str, str]) -> None:
    """Make (or read) the tuning of a vehicle with a plant switch (`plant_for`'s arguments) in the cache, so that
    its runs read it: without this, two workers starting runs of the same switched plant would each make it."""
    tuning_for(plant_for(*plant))


def clothoid_config_for(switch: str, config):
    if switch == "floor_lowered":
        return dataclasses.replace(config, min_phase_margin_deg=30.0, min_gain_margin_db=3.0)
    if switch == "floor_off":
        return dataclasses.replace(config, min_phase_margin_deg=0.0, min_gain_margin_db=0.0)
    if switch == "feedforward_off":
        return dataclasses.replace(config, path_feedforward=False)
    if switch == "feedforward_rate":
        return dataclasses.replace(config, feedforward_inversion=False, feedforward_window_m=RATE_FEEDFORWARD_WINDOW_M)
    if switch == "reference_lead":
        return dataclasses.replace(config, lag_model_reference=False)
    if switch == "handling_off":
        return dataclasses.replace(config, handling_gain=False)
    if switch in ("lag_model", "preview_model"):
        return dataclasses.replace(config, feedforward_model=switch.removesuffix("_model"))
    return config


def nmpc_config_for(switch: str, plant):
    """The NMPC's config on `plant`: the default (None), or predicting with the plant's identified lag."""
    if switch not in MODEL_SWITCHES:
        return None
    from controllers.mpc.nmpc import NMPCConfig

    return NMPCConfig(lag=tuning_for(plant).lag_at(SPEED_KMH))


@dataclass
class Run:
    vehicle: str
    scenario: str
    switch: str
    controller: str
    conditions: str
    status: str
    max_abs_cte_m: float
    rms_cte_m: float
    s_at_max_m: float
    curvature_at_max_1pm: float
    long_accel_at_max_mps2: float
    speed_at_max_mps: float
    peak_lat_accel_g: float
    steer_oscillation_deg: float
    rms_steer_rate_deg_s: float
    limit_cycle: bool
    mean_lookahead_m: float
    wall_s: float


def model_errors(trace: dict, path, tuning, geometry, window_m: float) -> dict[str, float]:
    """The clothoid controller's reference curvature and feed-forward (module docstring) along a run's `trace`
    (path_s_m, speed_mps, yaw_rate_rad_s, steer_wheel_cmd_rad, path_curvature_1pm) on `path`, with the vehicle's
    identified lags (`tuning`, a VehicleTuning), its geometry and the feed-forward's derivative window (m), as the
    compiled step computes them with no known delay: reference_{rms,max}_1pm, feedforward_{rms,max}_1pm (the
    differences from the measured and the sent), their RMS relative to path_curvature_rms_1pm, and samples."""
    from controllers.clothoid.path_feedforward import lag_inverse_curvature
    from controllers.clothoid.preview_model import preview_curvature
    from controllers.clothoid.speed_tables import table_row
    from controllers.clothoid.step_kernel import reference_curvature

    s, speed, yaw_rate, command, curvature = (
        np.asarray(trace[k], dtype=float)
        for k in ("path_s_m", "speed_mps", "yaw_rate_rad_s", "steer_wheel_cmd_rad", "path_curvature_1pm")
    )
    compiled = path.compiled()
    speeds, lags, measured_lags = tuning.lag_tables
    rows, lag = np.empty(8), np.empty(4)
    moving = np.flatnonzero(speed > MODEL_CHECK_MIN_SPEED_MPS)
    reference, feedforward = np.empty(moving.size), np.empty(moving.size)
    preview_reference, preview_feedforward = np.full(moving.size, np.nan), np.full(moving.size, np.nan)
    first, spacing, steering_taps, measured_taps = tuning.preview_tables
    for j, i in enumerate(moving):
        if steering_taps.shape[0] > 0:
            args = (compiled.table, compiled.record, s[i], speed[i], 0.0, first, spacing, speeds)
            preview_reference[j] = preview_curvature(*args, measured_taps, measured_taps[:, :0])
            preview_feedforward[j] = preview_curvature(*args, steering_taps, tuning.handling_table)
        reference[j] = reference_curvature(
            compiled.table, compiled.record, s[i], speed[i], lags, measured_lags, speeds, window_m, rows
        )
        table_row(speeds, lags, speed[i] * 3.6, False, lag)
        omega_n, zeta, delay, gain = lag
        feedforward[j] = lag_inverse_curvature(
            compiled.table, compiled.record, s[i], speed[i], delay, omega_n, zeta, gain, window_m
        )[0]
    measured = yaw_rate[moving] / speed[moving]
    sent = np.tan(command[moving] / geometry.steering_ratio) / geometry.wheelbase_m
    path_rms = float(np.sqrt(np.mean(curvature[moving] ** 2)))
    out: dict[str, float] = {"path_curvature_rms_1pm": path_rms, "samples": float(moving.size)}
    for name, error in (
        ("reference", measured - reference), ("feedforward", sent - feedforward),
        ("preview_reference", measured - preview_reference), ("preview_feedforward", sent - preview_feedforward),
    ):  # fmt: skip
        rms = float(np.sqrt(np.mean(error**2)))
        out |= {f"{name}_rms_1pm": rms, f"{name}_max_1pm": float(np.max(np.abs(error))),
                f"{name}_relative": rms / path_rms if path_rms > 0.0 else math.nan}  # fmt: skip
    return out


def run_one(job: tuple[str, str, str, str, str]) -> tuple[Run, dict[str, list[float]], dict[str, object] | None]:
    """One run of `jobs_for`: its Run, its trace thinned for the figure and, for the NMPC's nominal run in ideal
    conditions, the clothoid controller's model errors along it (`model_errors`, with vehicle and scenario)."""
    vehicle_name, scenario_name, switch, controller_name, conditions = job
    plant = plant_for(vehicle_name, switch)
    scenario = make_scenario(scenario_name, ScenarioOptions(plant.geometry.width_m, None))
    cfg = SimulationConfig(
        speed_kmh=SPEED_KMH,
        max_lateral_accel_g=CONSTANT_SPEED_LATERAL_G if switch in ("constant_speed", "ideal_plant") else 0.3,
        conditions=CONDITIONS[conditions],
        inform_delays=conditions != "ideal",
        perfect_prediction=switch in DELAY_SWITCHES,
    )
    delays = cfg.known_delays
    nmpc_config = nmpc_config_for(switch, plant) if controller_name == "nmpc" else None
    controller = tuned_controller(controller_name, plant, nmpc_config, delays=delays)
    if controller_name == "clothoid" and switch in CONTROLLER_SWITCHES:
        from controllers import make_controller

        config = clothoid_config_for(switch, controller.config)
        controller = make_controller("clothoid", plant.geometry, config, vehicle=plant)
    start = time.perf_counter()
    result = Simulation(scenario, plant, controller, cfg).run()
    m, tr = result.metrics, result.trace
    cte = np.asarray(tr["cte_m"], dtype=float)
    s = np.asarray(tr["progress_m"], dtype=float)
    t = np.asarray(tr["t_s"], dtype=float)
    v = np.asarray(tr["speed_mps"], dtype=float)
    kernel = np.ones(ACCEL_SMOOTHING_SAMPLES) / ACCEL_SMOOTHING_SAMPLES
    accel = np.convolve(np.gradient(v, t), kernel, mode="same")
    kappa = np.asarray(tr["path_curvature_1pm"], dtype=float)
    i = int(np.nanargmax(np.abs(cte)))
    lookahead = np.asarray(tr["ctrl_lookahead_m"], dtype=float) if "ctrl_lookahead_m" in tr else np.array([math.nan])
    run = Run(
        vehicle_name, scenario_name, switch, controller_name, conditions, result.status.value,
        float(np.nanmax(np.abs(cte))), float(np.sqrt(np.nanmean(cte**2))), float(s[i]), float(kappa[i]),
        float(accel[i]), float(v[i]), float(np.nanmax(np.abs(v**2 * kappa)) / 9.80665),
        m.steer_oscillation_deg or math.nan, m.rms_steer_rate_deg_s or math.nan, bool(m.limit_cycle),
        float(np.nanmean(lookahead[lookahead > 0])) if np.any(lookahead > 0) else math.nan,
        time.perf_counter() - start,
    )  # fmt: skip
    step = max(1, len(s) // 2000)
    steer_deg = np.degrees(np.asarray(tr["steer_wheel_cmd_rad"], dtype=float))
    columns = (("s", s), ("cte", cte), ("kappa", kappa), ("accel", accel), ("steer_deg", steer_deg))
    trace = {k: a[::step].tolist() for k, a in columns}
    errors = None
    if (controller_name, switch, conditions) == ("nmpc", "nominal", "ideal"):
        from controllers.clothoid.controller import ClothoidConfig

        window = ClothoidConfig().feedforward_window_m
        errors = {"vehicle": vehicle_name, "scenario": scenario_name,
                  **model_errors(tr, scenario.path, tuning_for(plant), plant.geometry, window)}  # fmt: skip
    return run, trace, errors


def jobs_for(vehicles: list[str], scenarios: list[str], automotive: bool) -> list[tuple[str, str, str, str, str]]:
    out = []
    for conditions, names in (("ideal", scenarios), ("automotive", AUTOMOTIVE_SCENARIOS if automotive else ())):
        for v in vehicles:
            for sc in names:
                for sw in SWITCHES:
                    if sw in DELAY_SWITCHES and conditions == "ideal":
                        continue
                    if sw not in MODEL_SWITCHES:
                        out.append((v, sc, sw, "clothoid", conditions))
                    if sw == "nominal" or sw in PLANT_SWITCHES or sw in MODEL_SWITCHES or sw in DELAY_SWITCHES:
                        out.append((v, sc, sw, "nmpc", conditions))
    return out


def loop_rows(vehicle_name: str) -> list[dict[str, object]]:
    """The loop analysis at SPEED_KMH, each switched plant with its own tuning, and each factor taken out of the
    nominal identified lags (module docstring)."""
    from controllers.clothoid import loop_analysis as la

    def built(switch: str):
        vehicle = plant_for(vehicle_name, switch)
        controller = tuned_controller("clothoid", vehicle)
        controller.reset(make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m, None)).path, 0.02)
        return controller

    def unit_gain(lag):
        return dataclasses.replace(lag, steady_state_gain=1.0)

    controller = built("nominal")
    nominal = controller.plant_lags(SPEED_KMH)
    own = {sw: built(sw) for sw in ("no_actuator_lag", "stiff_tyres", "ideal_plant")}
    cases = [
        ("nominal", controller, nominal, SPEED_KMH, 45.0, 6.0, None),
        *((f"{sw} (its own lags and lead)", c, c.plant_lags(SPEED_KMH), SPEED_KMH, 45.0, 6.0, None)
          for sw, c in own.items()),
        ("no sideslip lead (measured = path lag)", controller, la.PlantLags(nominal.path, None), SPEED_KMH, 45.0,
         6.0, None),
        ("no understeer (K = 1)", controller, la.PlantLags(unit_gain(nominal.path), unit_gain(nominal.measured)),
         SPEED_KMH, 45.0, 6.0, None),
        ("25 km/h (braking)", controller, controller.plant_lags(25.0), 25.0, 45.0, 6.0, None),
        ("20 km/h (braking)", controller, controller.plant_lags(20.0), 20.0, 45.0, 6.0, None),
        ("floor lowered (30 deg / 3 dB)", controller, nominal, SPEED_KMH, 30.0, 3.0, None),
        ("floor off (5 m)", controller, nominal, SPEED_KMH, 0.0, 0.0, 5.0),
    ]  # fmt: skip
    rows = []
    for name, controller, lags, speed_kmh, pm, gm, fixed in cases:
        settings = controller.loop_settings(speed_kmh)
        v = speed_kmh / 3.6
        arc = min(controller.limits.at_speed(v)[0], 0.4 * 9.80665 / v**2)
        floor = fixed or la.lookahead_floor(lags, settings, v, 5.0, 40.0, 0.5, (0.0, arc), pm, gm)
        mg = la.loop_margins(lags, settings, v, floor)
        loop = la.loop_transfer(lags, settings, v, floor)
        omega = np.logspace(-2, math.log10(math.pi / settings.sample_time_s) - 0.01, 3000)
        resp = la._response(loop, omega)
        closed = np.abs(resp / (1.0 + resp))
        below = np.nonzero(closed < 1.0 / math.sqrt(2.0))[0]
        below = below[omega[below] > mg.crossover_rad_s * 0.3] if mg.stable else below
        bandwidth_hz = float(omega[below[0]] / (2 * math.pi)) if below.size else math.nan
        rows.append({
            "vehicle": vehicle_name, "case": name, "speed_kmh": speed_kmh, "floor_m": floor,
            "phase_margin_deg": mg.phase_margin_deg, "gain_margin_db": mg.gain_margin_db,
            "gain_reduction_margin_db": mg.gain_reduction_margin_db,
            "crossover_hz": mg.crossover_rad_s / (2 * math.pi), "bandwidth_hz": bandwidth_hz, "stable": mg.stable,
        })  # fmt: skip
    return rows


def summary(runs: list[Run]) -> list[dict[str, object]]:
    """Per vehicle, conditions and switch: the clothoid's max |CTE| against its nominal run's and the NMPC's, as the
    median over the scenarios, and the share of the nominal gap to the NMPC the switch closes (a model switch: the
    clothoid's nominal run against the switched NMPC's, and the share of the gap the NMPC loses with that model)."""
    by = {(r.vehicle, r.scenario, r.switch, r.controller, r.conditions): r for r in runs}
    out = []
    for vehicle, conditions in sorted({(r.vehicle, r.conditions) for r in runs}):
        scenarios = sorted({r.scenario for r in runs if r.vehicle == vehicle and r.conditions == conditions})
        run_here = {r.switch for r in runs if (r.vehicle, r.conditions) == (vehicle, conditions)}
        for sw in [sw for sw in SWITCHES if sw in run_here]:  # the delay switch: under automotive only
            ratios, closed, vs_nmpc, rms, cycles = [], [], [], [], 0
            for sc in scenarios:
                c0 = by[(vehicle, sc, "nominal", "clothoid", conditions)]
                n0 = by[(vehicle, sc, "nominal", "nmpc", conditions)]
                c = by.get((vehicle, sc, sw, "clothoid", conditions), c0)
                n = by.get((vehicle, sc, sw, "nmpc", conditions), n0)
                ratios.append(c.max_abs_cte_m / c0.max_abs_cte_m)
                gap = c0.max_abs_cte_m - n0.max_abs_cte_m
                change = (
                    n.max_abs_cte_m - n0.max_abs_cte_m if sw in MODEL_SWITCHES else c0.max_abs_cte_m - c.max_abs_cte_m
                )
                closed.append(change / gap if gap > 1e-9 else math.nan)
                vs_nmpc.append(c.max_abs_cte_m / n.max_abs_cte_m)
                rms.append(c.rms_cte_m / c0.rms_cte_m)
                cycles += c.limit_cycle
            out.append({
                "vehicle": vehicle, "conditions": conditions, "switch": sw,
                "median_max_cte_vs_nominal": float(np.median(ratios)),
                "median_rms_cte_vs_nominal": float(np.median(rms)),
                # None where the clothoid controller is no worse than the NMPC on every scenario: no gap to close
                "median_gap_closed": float(np.nanmedian(closed)) if not np.isnan(closed).all() else None,
                "median_ratio_to_nmpc_same_run": float(np.median(vs_nmpc)), "limit_cycles": cycles,
                "scenarios": len(scenarios),
            })  # fmt: skip
    return out


def figure(vehicle: str, scenario: str, traces: dict, runs: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(4, 1, figsize=(9, 8), sharex=True, gridspec_kw={"height_ratios": [3, 1.4, 1, 1]})
    for sw in SWITCHES:
        tr = traces.get((vehicle, scenario, sw, "clothoid", "ideal"))
        if tr is None:
            continue
        r = runs[(vehicle, scenario, sw, "clothoid", "ideal")]
        style = {"lw": 2.0, "color": "k"} if sw == "nominal" else {"lw": 0.9}
        axes[0].plot(tr["s"], np.abs(tr["cte"]), label=f"{sw} ({r.max_abs_cte_m:.3f} m)", **style)
    nmpc = traces[(vehicle, scenario, "nominal", "nmpc", "ideal")]
    r = runs[(vehicle, scenario, "nominal", "nmpc", "ideal")]
    axes[0].plot(nmpc["s"], np.abs(nmpc["cte"]), "k--", lw=1.2, label=f"NMPC, nominal ({r.max_abs_cte_m:.3f} m)")
    for sw in MODEL_SWITCHES:
        tr = traces.get((vehicle, scenario, sw, "nmpc", "ideal"))
        if tr is not None:
            r = runs[(vehicle, scenario, sw, "nmpc", "ideal")]
            axes[0].plot(
                tr["s"], np.abs(tr["cte"]), ":", color="0.4", lw=1.2, label=f"NMPC, {sw} ({r.max_abs_cte_m:.3f} m)"
            )
    axes[0].set_ylabel("|CTE| (m)")
    axes[0].legend(fontsize=7, ncol=2)
    axes[0].set_title(f"{vehicle}, {scenario}, 30 km/h, ideal: the clothoid controller, one factor switched at a time")
    base = traces[(vehicle, scenario, "nominal", "clothoid", "ideal")]
    for tr, r, style, who in (
        (base, runs[(vehicle, scenario, "nominal", "clothoid", "ideal")], {"color": "k", "lw": 1.5}, "clothoid"),
        (nmpc, runs[(vehicle, scenario, "nominal", "nmpc", "ideal")], {"color": "k", "ls": "--", "lw": 1.2}, "NMPC"),
    ):  # the steering each nominal run took, beside the other's on the same run
        label = f"{who}, nominal (oscillation {r.steer_oscillation_deg:.1f}°, RMS rate {r.rms_steer_rate_deg_s:.0f}°/s)"
        axes[1].plot(tr["s"], tr["steer_deg"], label=label, **style)
    axes[1].set_ylabel("steering wheel (°)")
    axes[1].legend(fontsize=7)
    axes[2].plot(base["s"], base["kappa"], color="tab:blue")
    axes[2].set_ylabel("path κ (1/m)")
    axes[3].plot(base["s"], base["accel"], color="tab:red")
    axes[3].set_ylabel("long. accel (m/s²)")
    axes[3].set_xlabel("distance along the path (m)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "cte_breakdown.json")
    parser.add_argument("--vehicles", default=",".join(VEHICLES))
    parser.add_argument("--scenarios", default=",".join(SCENARIOS))
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--no-automotive", action="store_true", help="skip the automotive check (dlc, figure8)")
    parser.add_argument("--figures-dir", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    vehicles, scenarios = args.vehicles.split(","), args.scenarios.split(",")
    held_out = [s for s in scenarios if s.startswith("circuit:") and int(s.split(":")[1]) >= HELD_OUT_FIRST_SEED]
    if held_out:
        parser.error(f"{', '.join(held_out)}: seeds {HELD_OUT_FIRST_SEED} and up are the held-out set, not for this")
    jobs = jobs_for(vehicles, scenarios, not args.no_automotive)
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        list(pool.map(tune_plant, switched_plants(jobs)))  # each plant's tuning once, before the runs that read it
        results = list(pool.map(run_one, jobs, chunksize=2))
    runs = {(r.vehicle, r.scenario, r.switch, r.controller, r.conditions): r for r, _, _ in results}
    traces = {(r.vehicle, r.scenario, r.switch, r.controller, r.conditions): t for r, t, _ in results}
    models = [errors for _, _, errors in results if errors is not None]
    print(f"{'vehicle':<20} {'scenario':<13} {'cond':<5} {'switch':<21} {'ctrl':<8} {'max|CTE|':>8} {'RMS':>6} "
          f"{'s@max':>7} {'κ@max':>7} {'ax@max':>6} {'osc°':>5} {'rate':>5} LC")  # fmt: skip
    for r, _, _ in results:
        print(
            f"{r.vehicle:<20} {r.scenario:<13} {r.conditions[:5]:<5} {r.switch:<21} {r.controller:<8} "
            f"{r.max_abs_cte_m:8.3f} {r.rms_cte_m:6.3f} {r.s_at_max_m:7.1f} {r.curvature_at_max_1pm:7.3f} "
            f"{r.long_accel_at_max_mps2:6.2f} {r.steer_oscillation_deg:5.1f} {r.rms_steer_rate_deg_s:5.0f} "
            f"{'yes' if r.limit_cycle else 'no'}"
        )
    table = summary([r for r, _, _ in results])
    print(f"\n{'vehicle':<20} {'cond':<10} {'switch':<21} {'max|CTE| x':>10} {'RMS x':>6} {'gap closed':>10} "
          f"{'/ NMPC':>7} LC")  # fmt: skip
    for row in table:
        gap = row["median_gap_closed"]
        gap_text = "no gap" if gap is None else f"{gap:.0%}"
        print(
            f"{row['vehicle']:<20} {row['conditions']:<10} {row['switch']:<21} "
            f"{row['median_max_cte_vs_nominal']:10.2f} {row['median_rms_cte_vs_nominal']:6.2f} "
            f"{gap_text:>10} {row['median_ratio_to_nmpc_same_run']:7.2f} {row['limit_cycles']}"
        )
    print(f"\n{'models along the NMPC run':<34} {'reference RMS':>13} {'max':>8} {'rel.':>5} {'feed-fwd RMS':>12} "
          f"{'max':>8} {'rel.':>5} {'preview: ref. rel.':>18} {'feed-fwd rel.':>13}")  # fmt: skip
    for row in models:
        print(
            f"{row['vehicle'] + ' ' + row['scenario']:<34} {row['reference_rms_1pm']:13.2e} "
            f"{row['reference_max_1pm']:8.1e} {row['reference_relative']:5.1%} {row['feedforward_rms_1pm']:12.2e} "
            f"{row['feedforward_max_1pm']:8.1e} {row['feedforward_relative']:5.1%} "
            f"{row['preview_reference_relative']:18.1%} {row['preview_feedforward_relative']:13.1%}"
        )
    loops = [row for v in vehicles for row in loop_rows(v)]
    print(f"\n{'vehicle':<20} {'loop (30 km/h unless said)':<40} {'floor':>6} {'PM°':>5} {'GM dB':>6} {'GRM dB':>7} "
          f"{'xover Hz':>8} {'BW Hz':>6}")  # fmt: skip
    for row in loops:
        print(
            f"{row['vehicle']:<20} {row['case']:<40} {row['floor_m']:6.1f} {row['phase_margin_deg']:5.0f} "
            f"{row['gain_margin_db']:6.1f} {row['gain_reduction_margin_db']:7.1f} {row['crossover_hz']:8.2f} "
            f"{row['bandwidth_hz']:6.2f}"
        )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    figures = []
    for v in vehicles:
        worst = max(scenarios, key=lambda sc: runs[(v, sc, "nominal", "clothoid", "ideal")].max_abs_cte_m)
        for folder in [args.out.parent] + ([args.figures_dir] if args.figures_dir else []):
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"cte_breakdown_{v}.png"
            figure(v, worst, traces, runs, path)
            figures.append(str(path))
    write_results(args.out, result_document([r for r, _, _ in results], table, loops, figures, models),
                  f" and {', '.join(figures)}")  # fmt: skip
    return 0


def result_document(runs: list[Run], table: list[dict[str, object]], loops: list[dict[str, object]],
                    figures: list[str], models: list[dict[str, object]]) -> dict[str, object]:  # fmt: skip
    """What the benchmark writes: the machine it ran on, when, the speed, every run, the summary table, the loop
    analysis rows, the figures' paths and the model errors along the NMPC's runs."""
    return {
        "machine": machine(), "created_unix_s": time.time(), "speed_kmh": SPEED_KMH,
        "runs": [asdict(r) for r in runs], "summary": table, "loop_analysis": loops, "figures": figures,
        "model_error": models,
    }  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
