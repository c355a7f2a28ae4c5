"""What the clothoid controller's loop must keep, and how it may compensate a known delay: the defaults the
controller's options (`ClothoidConfig`) and the loop analysis (`loop_analysis.py`) share, in a module light enough
for the controller to import without python-control.

The margins are the design requirement the lookahead floor keeps at every lookahead the controller may pick. With a
known delay compensated by the lags' model (a Smith predictor, `delay_predictor.py`) they are the nominal
(delay-free) loop's, and the loop with its delay, broken at the steering sent, keeps the delayed ones: what a gain
or delay the model does not know may change before the loop goes unstable. A Smith predictor's loop has less than
its nominal one (Normey-Rico & Camacho, "Control of Dead-time Processes", 2007, ch. 5); 30 deg is the usual least
phase margin (Skogestad & Postlethwaite, "Multivariable Feedback Control", 2005, sec. 2.4.3).
"""

from __future__ import annotations

#: Phase margin (deg) the lookahead floor keeps.
REQUIRED_PHASE_MARGIN_DEG = 45.0
#: Gain margin (dB) the lookahead floor keeps, both ways (rise and reduction).
REQUIRED_GAIN_MARGIN_DB = 6.0
#: Phase margin (deg) of the loop with its delay and the model's compensation.
REQUIRED_DELAYED_PHASE_MARGIN_DEG = 30.0
#: Gain margin (dB, both ways) of the loop with its delay and the model's compensation.
REQUIRED_DELAYED_GAIN_MARGIN_DB = 3.0
#: How far (s) the plant's dead time may differ from the known one, either way, with the loop kept stable and
#: UNCERTAIN_DELAY_MARGIN_FRACTION of the delayed margins: a Smith predictor is as sensitive to a delay told too
#: long as too short (the measured response and the model's change then count the same steering twice, or
#: neither), and a few tens of milliseconds of it unsettle a fast loop (the dynamic bicycle at 30 km/h and 5.5 m:
#: unstable 40 ms either way).
DELAY_UNCERTAINTY_S = 0.05
#: The fraction (-) of the delayed margins kept with the dead time DELAY_UNCERTAINTY_S off.
UNCERTAIN_DELAY_MARGIN_FRACTION = 0.5
#: How the pose is predicted over the known delay: "model" (the identified lags driven by the commands sent) or
#: "arc" (on kappa(0)).
DELAY_COMPENSATIONS = ("model", "arc")


def predicts_with_model(delay_compensation: str, known_delay_s: float, yaw_rate_age_s: float = 0.0) -> bool:
    """Whether the pose and kappa(0) are predicted with the identified lags: delay compensation "model" and a known
    delay (s) above zero or a yaw rate older or fresher than the pose (s, `ClothoidConfig.yaw_rate_age_s`)."""
    return delay_compensation == "model" and (known_delay_s > 0.0 or yaw_rate_age_s != 0.0)
