"""The compiled step (`step_kernel.py`) against the Python step it replaced: the recorded runs of
tests/controllers/clothoid/replay (`replay_cases.py`, recorded with the Python step of commit b614e88) replayed through
today's controller, measurement by measurement, give the same commands and diagnostics to rounding (`TOLERANCE`)."""

from __future__ import annotations

import numpy as np
import pytest
from replay_cases import CASES, ZANDVOORT_CSV

from controllers.base import Measurement

#: Agreement asked of the replay: absolute, and relative to each diagnostic's own scale. The lookahead floors come
#: from LAPACK solves whose last bits depend on the kernel OpenBLAS picks for the processor: forcing its Haswell
#: kernel (OPENBLAS_CORETYPE=Haswell, as some machines here set) on an AMD EPYC moves the commands by up to 8e-12 rad
#: from the recording. 1e-10 allows that rounding and is still eight orders below any steering a change would make.
TOLERANCE = 1e-10


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_the_compiled_step_replays_the_recorded_python_steps(case) -> None:
    if case.scenario == "zandvoort" and not ZANDVOORT_CSV.is_file():
        pytest.skip(f"no track file at {ZANDVOORT_CSV}")
    recorded = np.load(case.file)
    controller, path = case.controller(), case.path()
    controller.reset(path, 0.02)
    assert tuple(recorded["diagnostic_names"]) == controller.diagnostic_names
    commands, diagnostics = [], []
    for row in recorded["measurements"]:
        commands.append(controller.step(Measurement(*row.tolist()), path))
        diagnostics.append(controller.diagnostic_values.copy())
    np.testing.assert_allclose(commands, recorded["commands"], rtol=TOLERANCE, atol=TOLERANCE)
    scale = np.maximum(np.abs(recorded["diagnostics"]).max(axis=0), 1.0)
    np.testing.assert_allclose(np.array(diagnostics) / scale, recorded["diagnostics"] / scale, rtol=0.0, atol=TOLERANCE)
