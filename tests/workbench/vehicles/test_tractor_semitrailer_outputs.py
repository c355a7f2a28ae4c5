"""The tractor-semitrailer's outputs: the compiled kernel's array sized by the output names, not by a count of its
own."""

from __future__ import annotations

import numpy as np

from workbench.vehicles import TractorSemitrailer
from workbench.vehicles.tractor_semitrailer import EXTRA_OUTPUT_NAMES, OUTPUT_COUNT


def test_the_outputs_array_is_sized_by_its_names() -> None:
    truck = TractorSemitrailer()
    out = truck.outputs(truck.initial_state(0.0, 0.0, 0.3, 20.0), 0.1, 0.0)
    assert truck.extra_output_names is EXTRA_OUTPUT_NAMES
    assert out.shape == (OUTPUT_COUNT,) == (len(truck.output_names),)
    assert np.isfinite(out).all()
