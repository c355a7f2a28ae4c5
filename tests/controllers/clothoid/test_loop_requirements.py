"""The loop's requirements have one home (`loop_requirements.py`): the controller's options default to them and the
loop analysis uses them, and both tell alike whether a known delay is predicted with the lags' model."""

from __future__ import annotations

import dataclasses
import itertools

from controllers.clothoid import loop_requirements as req
from controllers.clothoid.controller import ClothoidConfig
from controllers.clothoid.loop_analysis import DelayRobustness, LoopSettings, keeps_margins, lookahead_floor


def test_the_options_and_the_analysis_default_to_the_same_requirements() -> None:
    defaults = {f.name: f.default for f in dataclasses.fields(ClothoidConfig)}
    assert (defaults["min_phase_margin_deg"], defaults["min_gain_margin_db"]) == (
        req.REQUIRED_PHASE_MARGIN_DEG, req.REQUIRED_GAIN_MARGIN_DB,
    )  # fmt: skip
    robustness = DelayRobustness()
    assert (
        defaults["min_delayed_phase_margin_deg"], defaults["min_delayed_gain_margin_db"],
        defaults["known_delay_uncertainty_s"],
    ) == (robustness.phase_margin_deg, robustness.gain_margin_db, robustness.delay_uncertainty_s)  # fmt: skip
    for search in (lookahead_floor, keeps_margins):
        parameters = search.__defaults__
        assert req.REQUIRED_PHASE_MARGIN_DEG in parameters and req.REQUIRED_GAIN_MARGIN_DB in parameters
    delay_choices = ClothoidConfig.__dataclass_fields__["delay_compensation"].metadata["rule"].choices()
    assert delay_choices == req.DELAY_COMPENSATIONS


def test_the_options_and_the_analysis_predict_with_the_model_alike() -> None:
    for compensation, delay in itertools.product(req.DELAY_COMPENSATIONS, (0.0, 0.04)):
        config = ClothoidConfig(delay_compensation=compensation, known_delay_s=delay)
        settings = LoopSettings(known_delay_s=delay, delay_compensation=compensation)
        expected = compensation == "model" and delay > 0.0
        assert config.predicts_with_model is settings.predicts_with_model is expected
