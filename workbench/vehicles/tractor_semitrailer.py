"""Tractor-semitrailer: articulated yaw-plane model with saturating tyres, a steering system and quasi-static roll.

Stands in for the TruckSim 5-axle rig of the paper. Two rigid units joined at the fifth wheel (hitch); each axle
group (tractor steer axle, drive tandem, trailer tandem) is lumped at its centre with one tyre force that follows
a magic formula (peak = friction x static group load, cornering stiffness = coefficient x static group load) and
lags it by a relaxation length. The reference point is the tractor's drive-group centre. A road-friction scale
lambda (`set_road_friction`) multiplies the friction, in the peak and in B = coefficient / (C friction): the peak
scales, the cornering stiffness stays.

States (SI): x_m, y_m (drive-group centre), yaw_rad (tractor), vx_mps (tractor longitudinal speed),
vy_cg_mps (tractor CG lateral velocity, tractor frame), yaw_rate_rad_s (tractor), trailer_yaw_rad,
trailer_yaw_rate_rad_s, road_wheel_angle_rad, fy_front_N, fy_drive_N, fy_trailer_N (tyre lateral forces).
Inputs: steering-wheel angle command (rad; / steering_ratio = road-wheel command, first-order actuator with rate
limit) and longitudinal acceleration command (m/s^2, realised by the powertrain; speed stays >= 0).

Yaw plane: Newton-Euler for both units with the hitch force eliminated, giving a 3x3 symmetric mass matrix in
(dvy/dt, dr1/dt, dr2/dt) solved in closed form. Below kinematic_blend_high_mps the lateral accelerations blend
smoothly into those of the kinematic (no-slip) articulated vehicle, so the model is well-posed down to v = 0 and
matches CommonRoad's KST model there.

Roll (quasi-static): each unit's sprung mass rolls on its suspension (the trailer also through the fifth wheel
into the tractor suspension); the overturning moment of each axle group is its share of sprung mass x unit
lateral acceleration x (CG height + roll-compliance lift) plus the unsprung term, and
LTR = 2 M / (track x static load). |LTR| = 1 is wheel lift-off. Lift-off itself is not simulated: LTR goes on
past 1 and the yaw plane does not see it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.actuator import realised_accel, road_wheel_rate
from workbench.vehicles.base import STANDARD_OUTPUTS, CompiledVehicleModel, VehicleGeometry
from workbench.vehicles.blend import blend, blend_weight, check_blend_speeds, pull
from workbench.vehicles.integration import rk4
from workbench.vehicles.reference_point import reference_point, world_velocity
from workbench.vehicles.single_track import PredictionParams, SingleTrackParams
from workbench.vehicles.tyres import COMMONROAD_G_MPS2, magic_formula, relaxation_rate, slip_angle, steered_slip_angle


@dataclass(frozen=True)
class TractorSemitrailerParams:
    """A loaded 5-axle US tractor-semitrailer. Sources: A = Auburn GAVLAB vehParams.m (5-axle rig, config 2
    'loaded'); B = GOPS 7-DoF yaw-roll semitruck (Semitruck7DoFParam); C = OpenPBS TractorSemitrailer6x2.mo;
    D = CommonRoad vehicle 4 (parameters_vehicle4.yaml). Distances along the unit's axis.
    """

    # tractor
    tractor_sprung_mass_kg: float = 6493.0  # A: m_s1
    front_unsprung_mass_kg: float = 570.0  # A: m_us_A1
    drive_unsprung_mass_kg: float = 1570.0  # A: m_us_A2 + m_us_A3 (785 + 785)
    tractor_yaw_inertia_kgm2: float = 19658.0  # A: m_s1 Rz1^2 (sprung mass about its CG)
    cg_to_front_axle_m: float = 1.384  # A: a (from the sprung-mass CG)
    cg_to_drive_axle_m: float = 4.251  # A: mean of b1 = 3.616 and b2 = 4.886 (tandem centre)
    hitch_ahead_of_drive_m: float = 0.0  # A: c = 4.251 m, i.e. the fifth wheel sits over the tandem centre
    tractor_cg_height_m: float = 1.175  # B: h1 (tractor sprung CG height)
    # trailer
    trailer_sprung_mass_kg: float = 3196.0  # A: m_s2 (empty trailer)
    trailer_unsprung_mass_kg: float = 1330.0  # A: m_us_A4 + m_us_A5 (665 + 665)
    trailer_yaw_inertia_kgm2: float = 180010.0  # A: m_s2 Rz2^2 (empty trailer)
    hitch_to_trailer_cg_m: float = 7.303  # A: d
    hitch_to_trailer_axle_m: float = 13.768  # A: mean of f1 = 13.124 and f2 = 14.412 (tandem centre)
    trailer_cg_height_m: float = 1.7  # assumed: empty van trailer; with the payload below gives B's loaded 2.12 m
    # payload
    payload_kg: float = 17000.0  # A: m_l
    payload_cg_from_hitch_m: float = 7.303  # assumed: load centred at the trailer's own CG (A: d)
    payload_length_m: float = 12.0  # assumed: spread evenly over ~3/4 of a 53 ft (16.2 m) deck (yaw inertia)
    payload_cg_height_m: float = 2.2  # assumed: mid-height of a van load; loaded trailer CG 2.12 m (B: h2 2.125)
    # roll
    tractor_roll_stiffness_nm_per_rad: float = 9.1731e5  # B: kr1
    trailer_roll_stiffness_nm_per_rad: float = 2.6023e6  # B: kr2
    fifth_wheel_roll_stiffness_nm_per_rad: float = 3.5503e6  # B: ka
    roll_axis_height_m: float = 0.8  # assumed: typical heavy-vehicle roll-centre height (leaf/air springs)
    front_track_m: float = 2.05  # assumed: US steer-axle track (wheel centres)
    dual_track_m: float = 1.83  # assumed: dual-tyre pair centre spacing, drive and trailer axles
    unsprung_cg_height_m: float = 0.51  # A: r_eff (axles at wheel-centre height)
    # tyres
    front_cornering_coeff_per_rad: float = 4.8  # assumed: C's 5.5 less ~13% for the heavier-loaded steer tyres
    drive_cornering_coeff_per_rad: float = 5.5  # C: cornering coefficient 5.5 /rad (x axle load)
    trailer_cornering_coeff_per_rad: float = 5.5  # C: cornering coefficient 5.5 /rad (x axle load)
    tyre_friction: float = 0.8  # assumed: dry asphalt, peak lateral friction of truck tyres 0.75-0.85
    tyre_shape_factor: float = 1.35  # CommonRoad parameters_tire p_cy1 = 1.3507 (magic-formula C)
    relaxation_length_m: float = 0.6  # assumed: truck tyre, about one rolling radius (A: r_eff 0.51 m)
    # steering system
    steering_ratio: float = 22.0  # assumed: heavy trucks 20-25:1 (reference facts; paper's ~300 deg peaks)
    max_road_wheel_angle_rad: float = 0.55  # D: steering.max
    max_road_wheel_rate_rad_s: float = 0.7103  # D: steering.v_max
    steering_time_constant_s: float = 0.1  # assumed: hydraulic power steering + steering actuator, ~1.6 Hz
    # longitudinal, envelope, low speed
    max_accel_mps2: float = 1.0  # assumed: 30 t rig, ~300 kW
    max_decel_mps2: float = 4.0  # assumed: ~0.4 g air brakes
    width_m: float = 2.59  # assumed: US 102 in trailer width
    kinematic_blend_low_mps: float = 1.0  # assumed: purely kinematic below
    kinematic_blend_high_mps: float = 3.0  # assumed: purely dynamic above

    def __post_init__(self) -> None:
        for name, low, high, unit in _RANGES:
            require_in_range(name, getattr(self, name), low, high, unit)
        if self.hitch_to_trailer_cg_m >= self.hitch_to_trailer_axle_m:
            raise WorkbenchInputError(
                f"hitch_to_trailer_cg_m must be < hitch_to_trailer_axle_m = {self.hitch_to_trailer_axle_m} m "
                f"(trailer CG ahead of its axles); got {self.hitch_to_trailer_cg_m!r}"
            )
        if self.payload_cg_from_hitch_m >= self.hitch_to_trailer_axle_m:
            raise WorkbenchInputError(
                f"payload_cg_from_hitch_m must be < hitch_to_trailer_axle_m = {self.hitch_to_trailer_axle_m} m; "
                f"got {self.payload_cg_from_hitch_m!r}"
            )
        if self.hitch_ahead_of_drive_m >= self.cg_to_front_axle_m + self.cg_to_drive_axle_m - 0.5:
            raise WorkbenchInputError(
                "hitch_ahead_of_drive_m must leave the fifth wheel at least 0.5 m behind the front axle, i.e. be "
                f"< {self.cg_to_front_axle_m + self.cg_to_drive_axle_m - 0.5:g} m; got {self.hitch_ahead_of_drive_m!r}"
            )
        check_blend_speeds(self.kinematic_blend_low_mps, self.kinematic_blend_high_mps)


#: (field, low, high, unit): the physically sensible range of every parameter.
_RANGES: tuple[tuple[str, float, float, str], ...] = (
    ("tractor_sprung_mass_kg", 1000.0, 30000.0, "kg"),
    ("front_unsprung_mass_kg", 50.0, 3000.0, "kg"),
    ("drive_unsprung_mass_kg", 50.0, 6000.0, "kg"),
    ("tractor_yaw_inertia_kgm2", 1000.0, 500000.0, "kg m^2"),
    ("cg_to_front_axle_m", 0.2, 6.0, "m"),
    ("cg_to_drive_axle_m", 0.5, 8.0, "m"),
    ("hitch_ahead_of_drive_m", -1.0, 3.0, "m"),
    ("tractor_cg_height_m", 0.3, 2.5, "m"),
    ("trailer_sprung_mass_kg", 500.0, 30000.0, "kg"),
    ("trailer_unsprung_mass_kg", 50.0, 6000.0, "kg"),
    ("trailer_yaw_inertia_kgm2", 1000.0, 5.0e6, "kg m^2"),
    ("hitch_to_trailer_cg_m", 0.5, 20.0, "m"),
    ("hitch_to_trailer_axle_m", 1.0, 20.0, "m"),
    ("trailer_cg_height_m", 0.3, 4.0, "m"),
    ("payload_kg", 0.0, 40000.0, "kg"),
    ("payload_cg_from_hitch_m", 0.0, 20.0, "m"),
    ("payload_length_m", 0.0, 20.0, "m"),
    ("payload_cg_height_m", 0.3, 4.0, "m"),
    ("tractor_roll_stiffness_nm_per_rad", 1.0e4, 1.0e8, "N m/rad"),
    ("trailer_roll_stiffness_nm_per_rad", 1.0e4, 1.0e8, "N m/rad"),
    ("fifth_wheel_roll_stiffness_nm_per_rad", 1.0e4, 1.0e9, "N m/rad"),
    ("roll_axis_height_m", 0.0, 2.0, "m"),
    ("front_track_m", 1.0, 3.0, "m"),
    ("dual_track_m", 1.0, 3.0, "m"),
    ("unsprung_cg_height_m", 0.1, 1.5, "m"),
    ("front_cornering_coeff_per_rad", 1.0, 30.0, "1/rad"),
    ("drive_cornering_coeff_per_rad", 1.0, 30.0, "1/rad"),
    ("trailer_cornering_coeff_per_rad", 1.0, 30.0, "1/rad"),
    ("tyre_friction", 0.05, 2.0, ""),
    ("tyre_shape_factor", 1.0, 1.9, ""),
    ("relaxation_length_m", 0.01, 3.0, "m"),
    ("steering_ratio", 1.0, 60.0, ""),
    ("max_road_wheel_angle_rad", 0.01, 1.5, "rad"),
    ("max_road_wheel_rate_rad_s", 0.01, 20.0, "rad/s"),
    ("steering_time_constant_s", 1e-3, 2.0, "s"),
    ("max_accel_mps2", 0.01, 20.0, "m/s^2"),
    ("max_decel_mps2", 0.01, 20.0, "m/s^2"),
    ("width_m", 0.5, 4.0, "m"),
    ("kinematic_blend_low_mps", 0.0, 10.0, "m/s"),
    ("kinematic_blend_high_mps", 0.1, 20.0, "m/s"),
)

# Indices into the derived-parameter array handed to the compiled code.
(
    P_A,
    P_B,
    P_C,
    P_L1,
    P_LT,
    P_E,
    P_M1,
    P_M2,
    P_I1,
    P_I2,
    P_TAU,
    P_RATE,
    P_SIGMA,
    P_VLO,
    P_VHI,
    P_DF,
    P_DD,
    P_DT,
    P_BF,
    P_BD,
    P_BT,
    P_SHAPE,
    P_HOFF,
    P_KF1,
    P_KF2,
    P_KD1,
    P_KD2,
    P_KT1,
    P_KT2,
    P_N,
) = range(30)


@dataclass(frozen=True)
class Derived:
    """Whole-unit quantities derived from the parameters (SI)."""

    m1: float  # tractor total mass
    m2: float  # trailer total mass incl. payload
    a: float  # tractor total CG to front axle
    b: float  # tractor total CG to drive-group centre
    e: float  # hitch to trailer total CG
    i1: float  # tractor yaw inertia about its total CG
    i2: float  # trailer yaw inertia about its total CG
    loads_n: tuple[float, float, float]  # static vertical load on front, drive, trailer groups
    ltr_per_ay: tuple[tuple[float, float], ...]  # d LTR_g / d a_y of (tractor, trailer), per group
    rollover_threshold_g: float  # lateral acceleration (g, both units) at which the first group reaches LTR 1


def derive(p: TractorSemitrailerParams) -> Derived:
    """Masses, CGs, inertias, static axle-group loads and the quasi-static LTR coefficients.

    Checks what the parameters' own ranges cannot: that each axle group carries a share of the weight, and that
    each unit's roll stiffness holds its sprung mass up.

    Parameters
    ----------
    p : TractorSemitrailerParams
        The vehicle's parameters.

    Returns
    -------
    Derived
        The whole-unit quantities (SI), the static rollover threshold (g) among them.

    Raises
    ------
    WorkbenchInputError
        When an axle group would carry under 5 % of the vehicle's weight (the message names the group and the
        parameters that place the loads), or a unit's roll stiffness is at most 1.2 m g h of its sprung mass.

    Examples
    --------
    >>> from workbench.vehicles.tractor_semitrailer import TractorSemitrailerParams, derive
    >>> round(derive(TractorSemitrailerParams()).rollover_threshold_g, 2)
    0.45
    """
    l1, lt, hoff = p.cg_to_front_axle_m + p.cg_to_drive_axle_m, p.hitch_to_trailer_axle_m, p.hitch_ahead_of_drive_m
    # tractor: x forward from the sprung CG
    parts1 = (
        (p.tractor_sprung_mass_kg, 0.0),
        (p.front_unsprung_mass_kg, p.cg_to_front_axle_m),
        (p.drive_unsprung_mass_kg, -p.cg_to_drive_axle_m),
    )
    m1 = sum(m for m, _ in parts1)
    x1 = sum(m * x for m, x in parts1) / m1
    i1 = p.tractor_yaw_inertia_kgm2 + sum(m * (x - x1) ** 2 for m, x in parts1)
    # trailer: x backward from the hitch
    parts2 = (
        (p.trailer_sprung_mass_kg, p.hitch_to_trailer_cg_m),
        (p.trailer_unsprung_mass_kg, lt),
        (p.payload_kg, p.payload_cg_from_hitch_m),
    )
    m2 = sum(m for m, _ in parts2)
    e = sum(m * x for m, x in parts2) / m2
    i2 = (
        p.trailer_yaw_inertia_kgm2
        + p.payload_kg * p.payload_length_m**2 / 12.0
        + sum(m * (x - e) ** 2 for m, x in parts2)
    )
    a, b = p.cg_to_front_axle_m - x1, p.cg_to_drive_axle_m + x1
    king = m2 * COMMONROAD_G_MPS2 * (lt - e) / lt
    loads = (
        m1 * COMMONROAD_G_MPS2 * b / l1 + king * hoff / l1,
        m1 * COMMONROAD_G_MPS2 * a / l1 + king * (l1 - hoff) / l1,
        m2 * COMMONROAD_G_MPS2 * e / lt,
    )
    for group, load in zip(("front", "drive", "trailer"), loads, strict=True):
        if load < 0.05 * (m1 + m2) * COMMONROAD_G_MPS2:
            raise WorkbenchInputError(
                f"the {group} axle group would carry {load / COMMONROAD_G_MPS2:.0f} kg, under 5% of the vehicle "
                "mass; check cg_to_front_axle_m, cg_to_drive_axle_m, hitch_ahead_of_drive_m, hitch_to_trailer_cg_m, "
                "payload_*"
            )
    # quasi-static roll: sprung masses, their CG heights and roll-compliance lift per unit
    ms1, ms2 = p.tractor_sprung_mass_kg, p.trailer_sprung_mass_kg + p.payload_kg
    xs2 = (p.trailer_sprung_mass_kg * p.hitch_to_trailer_cg_m + p.payload_kg * p.payload_cg_from_hitch_m) / ms2
    hs2 = (p.trailer_sprung_mass_kg * p.trailer_cg_height_m + p.payload_kg * p.payload_cg_height_m) / ms2
    k1, k5 = p.tractor_roll_stiffness_nm_per_rad, p.fifth_wheel_roll_stiffness_nm_per_rad
    k2 = p.trailer_roll_stiffness_nm_per_rad + k1 * k5 / (k1 + k5)
    heff = []
    for name, ms, hs, k in (
        ("tractor_roll_stiffness_nm_per_rad", ms1, p.tractor_cg_height_m, k1),
        ("trailer_roll_stiffness_nm_per_rad", ms2, hs2, k2),
    ):
        arm = max(hs - p.roll_axis_height_m, 0.0)
        if k <= 1.2 * ms * COMMONROAD_G_MPS2 * arm:
            raise WorkbenchInputError(
                f"{name} too low for the sprung mass: the roll stiffness must exceed 1.2 x m g h = "
                f"{1.2 * ms * COMMONROAD_G_MPS2 * arm:.4g} N m/rad (the unit would fall over standing still)"
            )
        heff.append(hs + arm * ms * COMMONROAD_G_MPS2 * arm / (k - ms * COMMONROAD_G_MPS2 * arm))
    s1f = ms1 * p.cg_to_drive_axle_m / l1
    s2k = ms2 * (lt - xs2) / lt
    hu = p.unsprung_cg_height_m
    moments = (  # overturning moment per unit a_y: (from tractor a_y, from trailer a_y)
        (s1f * heff[0] + p.front_unsprung_mass_kg * hu, s2k * heff[1] * hoff / l1),
        ((ms1 - s1f) * heff[0] + p.drive_unsprung_mass_kg * hu, s2k * heff[1] * (l1 - hoff) / l1),
        (0.0, (ms2 - s2k) * heff[1] + p.trailer_unsprung_mass_kg * hu),
    )
    tracks = (p.front_track_m, p.dual_track_m, p.dual_track_m)
    coef = tuple((2 * mt / (t * w), 2 * ml / (t * w)) for (mt, ml), t, w in zip(moments, tracks, loads, strict=True))
    threshold = 1.0 / max((c1 + c2) * COMMONROAD_G_MPS2 for c1, c2 in coef)
    return Derived(m1, m2, a, b, e, i1, i2, loads, coef, threshold)


@njit(cache=True)
def _rhs(s, p, delta_cmd, accel, out):  # pragma: no cover - compiled
    """State derivative into `out`."""
    yaw, u, v, r1, yaw2, r2, delta = s[2], max(s[3], 0.0), s[4], s[5], s[6], s[7], s[8]  # RK4 stages may dip < 0
    fyf, fyd, fyt = s[9], s[10], s[11]
    a, b, c, l1, lt, e = p[P_A], p[P_B], p[P_C], p[P_L1], p[P_LT], p[P_E]
    m1, m2, i1, i2 = p[P_M1], p[P_M2], p[P_I1], p[P_I2]
    ax = realised_accel(u, accel)
    ddelta = road_wheel_rate(delta_cmd, delta, p[P_TAU], p[P_RATE])
    th = yaw - yaw2
    sth, cth, sd, cd = math.sin(th), math.cos(th), math.sin(delta), math.cos(delta)
    vh = v - c * r1  # hitch lateral velocity, tractor frame
    # tyre slip and relaxation
    vy_t = u * sth + vh * cth - lt * r2
    vx_t = u * cth - vh * sth
    alpha_f = steered_slip_angle(v + a * r1, u, sd, cd)
    alpha_d = slip_angle(v - b * r1, u)
    alpha_t = slip_angle(vy_t, vx_t)
    relax = relaxation_rate(u, p[P_VLO], p[P_SIGMA])
    out[9] = relax * (magic_formula(alpha_f, p[P_DF], p[P_BF], p[P_SHAPE], 0.0) - fyf)
    out[10] = relax * (magic_formula(alpha_d, p[P_DD], p[P_BD], p[P_SHAPE], 0.0) - fyd)
    out[11] = relax * (magic_formula(alpha_t, p[P_DT], p[P_BT], p[P_SHAPE], 0.0) - fyt)
    # dynamic branch: 3x3 symmetric system in (dv, dr1, dr2), hitch force eliminated
    ff = fyf * cd
    x_acc = ax - v * r1 + c * r1 * r1
    m11, m12, m13 = m1 + m2, -m2 * c, -m2 * e * cth
    m22, m23, m33 = i1 + m2 * c * c, m2 * c * e * cth, i2 + m2 * e * e
    q1 = ff + fyd + fyt * cth - (m1 + m2) * u * r1 + m2 * e * r2 * r2 * sth
    q2 = a * ff - b * fyd - c * fyt * cth + c * m2 * u * r1 - c * m2 * e * r2 * r2 * sth
    q3 = -lt * fyt + e * m2 * (x_acc * sth + u * r1 * cth)
    c11, c12, c13 = m22 * m33 - m23 * m23, m13 * m23 - m12 * m33, m12 * m23 - m13 * m22
    c22, c23, c33 = m11 * m33 - m13 * m13, m12 * m13 - m11 * m23, m11 * m22 - m12 * m12
    det = m11 * c11 + m12 * c12 + m13 * c13
    dv_d = (c11 * q1 + c12 * q2 + c13 * q3) / det
    dr1_d = (c12 * q1 + c22 * q2 + c23 * q3) / det
    dr2_d = (c13 * q1 + c23 * q2 + c33 * q3) / det
    # kinematic branch: no lateral slip at any axle group, plus a pull onto those values
    td = sd / cd
    r1_k = u * td / l1
    dr1_k = (ax * td + u * ddelta / (cd * cd)) / l1
    dv_k = b * dr1_k
    vh_k = (b - c) * r1_k
    r2_k = (u * sth + vh_k * cth) / lt
    dth = r1 - r2
    dr2_k = (ax * sth + u * cth * dth + (b - c) * dr1_k * cth - vh_k * sth * dth) / lt
    dv_k += pull(b * r1_k, v)
    dr1_k += pull(r1_k, r1)
    dr2_k += pull(r2_k, r2)
    w = blend_weight(u, p[P_VLO], p[P_VHI])
    out[0], out[1] = world_velocity(u, v - b * r1, yaw)
    out[2] = r1
    out[3] = ax
    out[4] = blend(w, dv_d, dv_k)
    out[5] = blend(w, dr1_d, dr1_k)
    out[6] = r2
    out[7] = blend(w, dr2_d, dr2_k)
    out[8] = ddelta


#: The model's outputs after the standard ones (`_outputs` writes them in this order): the load transfer ratios
#: (the largest |LTR| and each axle group's), the trailer axle's position (m) and yaw (rad), the articulation angle
#: (rad) and the path curvature the reference point follows (1/m).
EXTRA_OUTPUT_NAMES: tuple[str, ...] = (
    "ltr",
    "ltr_front",
    "ltr_drive",
    "ltr_trailer",
    "trailer_x_m",
    "trailer_y_m",
    "trailer_yaw_rad",
    "articulation_rad",
    "path_curvature_1pm",
)
#: The length of `_outputs`' array: the standard outputs, then EXTRA_OUTPUT_NAMES.
OUTPUT_COUNT = len(STANDARD_OUTPUTS) + len(EXTRA_OUTPUT_NAMES)


@njit(cache=True)
def _advance(state, p, delta_cmd, accel, h, n):  # pragma: no cover - compiled
    return rk4(_rhs, state, p, delta_cmd, accel, h, n)


@njit(cache=True)
def _outputs(s, p, delta_cmd, accel, ratio):  # pragma: no cover - compiled
    d = np.empty(12)
    _rhs(s, p, delta_cmd, accel, d)
    x, y, yaw, u, v, r1, yaw2, delta = s[0], s[1], s[2], max(s[3], 0.0), s[4], s[5], s[6], s[8]
    b, c, e, lt = p[P_B], p[P_C], p[P_E], p[P_LT]
    th = yaw - yaw2
    vref, _, ay_ref, kappa = reference_point(u, v, r1, d[3], d[4], d[5], b, delta, p[P_L1])
    ay1 = d[4] + u * r1
    x_acc = d[3] - v * r1 + c * r1 * r1
    y_acc = d[4] + u * r1 - c * d[5]
    ay2 = x_acc * math.sin(th) + y_acc * math.cos(th) - e * d[7]
    ltr_f = p[P_KF1] * ay1 + p[P_KF2] * ay2
    ltr_d = p[P_KD1] * ay1 + p[P_KD2] * ay2
    ltr_t = p[P_KT1] * ay1 + p[P_KT2] * ay2
    hx = x + p[P_HOFF] * math.cos(yaw)
    hy = y + p[P_HOFF] * math.sin(yaw)
    out = np.empty(OUTPUT_COUNT)
    out[0], out[1], out[2], out[3], out[4], out[5] = x, y, yaw, u, vref, r1
    out[6], out[7], out[8] = delta * ratio, delta, ay_ref
    out[9] = max(abs(ltr_f), abs(ltr_d), abs(ltr_t))
    out[10], out[11], out[12] = ltr_f, ltr_d, ltr_t
    out[13], out[14] = hx - lt * math.cos(yaw2), hy - lt * math.sin(yaw2)
    out[15], out[16], out[17] = yaw2, th, kappa
    return out


class TractorSemitrailer(CompiledVehicleModel[TractorSemitrailerParams]):
    """The articulated tractor-semitrailer with saturating tyres, a steering system and quasi-static roll,
    registered as "tractor-semitrailer", referenced at the tractor's drive-group centre (module docstring).

    Parameters
    ----------
    params : TractorSemitrailerParams or None
        The model's parameters (None: the dataclass's defaults); `make_vehicle` builds the model from its preset
        or a vehicle file instead.

    Raises
    ------
    WorkbenchInputError
        Parameters that place too little load on an axle group, or a roll stiffness too low for a unit's sprung
        mass (`derive`).
    """

    name: ClassVar[str] = "tractor-semitrailer"
    state_names: ClassVar[tuple[str, ...]] = (
        "x_m",
        "y_m",
        "yaw_rad",
        "vx_mps",
        "vy_cg_mps",
        "yaw_rate_rad_s",
        "trailer_yaw_rad",
        "trailer_yaw_rate_rad_s",
        "road_wheel_angle_rad",
        "fy_front_N",
        "fy_drive_N",
        "fy_trailer_N",
    )
    heading_states: ClassVar[tuple[str, ...]] = ("trailer_yaw_rad",)
    has_tyres: ClassVar[bool] = True
    extra_output_names: ClassVar[tuple[str, ...]] = EXTRA_OUTPUT_NAMES

    _advance_kernel = staticmethod(_advance)
    _outputs_kernel = staticmethod(_outputs)

    def __init__(self, params: TractorSemitrailerParams | None = None) -> None:
        self.params = p = params or TractorSemitrailerParams()
        self.derived = dv = derive(p)
        arr = np.zeros(P_N)
        arr[P_A], arr[P_B], arr[P_C] = dv.a, dv.b, dv.b - p.hitch_ahead_of_drive_m
        arr[P_L1], arr[P_LT], arr[P_E] = dv.a + dv.b, p.hitch_to_trailer_axle_m, dv.e
        arr[P_M1], arr[P_M2], arr[P_I1], arr[P_I2] = dv.m1, dv.m2, dv.i1, dv.i2
        arr[P_TAU], arr[P_RATE] = p.steering_time_constant_s, p.max_road_wheel_rate_rad_s
        arr[P_SIGMA] = p.relaxation_length_m
        arr[P_VLO], arr[P_VHI] = p.kinematic_blend_low_mps, p.kinematic_blend_high_mps
        arr[P_SHAPE], arr[P_HOFF] = p.tyre_shape_factor, p.hitch_ahead_of_drive_m
        arr[P_KF1:P_N] = np.ravel(dv.ltr_per_ay)
        self._p = arr
        self._apply_road_friction(1.0)
        self._geometry = VehicleGeometry.from_params(p, p.cg_to_front_axle_m + p.cg_to_drive_axle_m)

    def _apply_road_friction(self, scale: float) -> None:
        """Per axle group, peak D = mu x static load and B = coefficient / (C mu) with mu = scale x tyre_friction,
        so that the cornering stiffness B C D = coefficient x load is kept; scale 1.0 gives exactly the entries
        built from the parameters."""
        p, arr = self.params, self._p
        mu = scale * p.tyre_friction
        coeffs = (p.front_cornering_coeff_per_rad, p.drive_cornering_coeff_per_rad, p.trailer_cornering_coeff_per_rad)
        for i, (load, k) in enumerate(zip(self.derived.loads_n, coeffs, strict=True)):
            arr[P_DF + i] = mu * load
            arr[P_BF + i] = k / (p.tyre_shape_factor * mu)

    def single_track(self, source: str | None = None) -> PredictionParams:
        """Equivalent single track (module docstring): the tractor plus the kingpin's share of the trailer as a
        point mass at the fifth wheel; axle loads and cornering stiffnesses of the articulated model (drive group
        including the kingpin load). Exact for the tractor in steady cornering; it neglects the trailer's yaw
        transient, which an identified lag captures.

        Parameters
        ----------
        source : str or None
            Where the numbers come from, for messages and reports (None: this model's parameters).

        Returns
        -------
        PredictionParams
            The geometry, the steering actuator and the equivalent single track's mass, yaw inertia and
            axle tyres: what the MPC controllers predict with.
        """
        p, d = self.params, self.derived
        l1 = p.cg_to_front_axle_m + p.cg_to_drive_axle_m
        lt = p.hitch_to_trailer_axle_m
        king_mass = d.m2 * (lt - d.e) / lt
        w_front, w_drive = d.loads_n[0], d.loads_n[1]
        mass = d.m1 + king_mass
        # Equivalent CG from the static loads (moment balance about the axles); x forward from the drive axle.
        b_eq = l1 * w_front / (w_front + w_drive)
        a_eq = l1 - b_eq
        x_tractor_cg, x_hitch = d.b, p.hitch_ahead_of_drive_m
        inertia = d.i1 + d.m1 * (x_tractor_cg - b_eq) ** 2 + king_mass * (x_hitch - b_eq) ** 2
        track = SingleTrackParams(
            mass_kg=mass,
            yaw_inertia_kgm2=inertia,
            cg_to_front_axle_m=a_eq,
            cg_to_rear_axle_m=b_eq,
            front_cornering_stiffness_n_per_rad=p.front_cornering_coeff_per_rad * w_front,
            rear_cornering_stiffness_n_per_rad=p.drive_cornering_coeff_per_rad * w_drive,
            front_peak_force_n=p.tyre_friction * w_front,
            rear_peak_force_n=p.tyre_friction * w_drive,
            tyre_shape_factor=p.tyre_shape_factor,
            tyre_curvature_factor=0.0,
        )
        source = (source or f"the {self.name} model's parameters") + (
            " (equivalent single track: tractor + kingpin share of the trailer at the fifth wheel)"
        )
        return PredictionParams.from_actuator(p, l1, source, track)

    def describe(self) -> str:
        """One line with the key parameters, for `workbench vehicles`: the geometry's, then the mass, the payload
        and the static rollover threshold.

        Returns
        -------
        str
            The wheelbase (m), steering ratio, maximum road-wheel angle (deg), width (m), total mass and payload
            (kg) and static rollover threshold (g).
        """
        dv = self.derived
        return (
            f"{super().describe()}, mass {dv.m1 + dv.m2:.0f} kg (payload {self.params.payload_kg:.0f} kg), "
            f"static rollover threshold {dv.rollover_threshold_g:.2f} g"
        )


__all__ = ["Derived", "TractorSemitrailer", "TractorSemitrailerParams", "derive"]
