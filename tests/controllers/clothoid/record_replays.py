"""Records the replay cases (`replay_cases.py`): python tests/controllers/clothoid/record_replays.py [NAME ...].

Each case is simulated with the controller's step wrapped to record what it saw and returned; the file holds
`measurements` (n, 8: t, x, y, vx, vy, yaw, yaw rate, steering wheel), `commands` (n,), `diagnostics` (n, k) and
`diagnostic_names`. Re-record only on purpose: the files are the reference the compiled step is held to.
"""

from __future__ import annotations

import sys

import numpy as np
from replay_cases import CASES, ZANDVOORT_CSV


def record(case) -> None:
    controller = case.controller()
    rows, commands, diagnostics = [], [], []
    inner = controller.step

    def step(measurement, path):
        command = inner(measurement, path)
        rows.append(dataclasses_row(measurement))
        commands.append(command)
        diagnostics.append(controller.diagnostic_values.copy())
        return command

    controller.step = step
    result = case.simulation(controller).run()
    np.savez_compressed(
        case.file,
        measurements=np.array(rows),
        commands=np.array(commands),
        diagnostics=np.array(diagnostics),
        diagnostic_names=np.array(controller.diagnostic_names),
    )
    print(f"{case.name}: {len(commands)} steps, {result.status.value}, {case.file.stat().st_size / 1e3:.0f} kB")


def dataclasses_row(m) -> tuple[float, ...]:
    return (m.t_s, m.x_m, m.y_m, m.vx_mps, m.vy_mps, m.yaw_rad, m.yaw_rate_rad_s, m.steer_wheel_rad)


if __name__ == "__main__":
    names = set(sys.argv[1:])
    for case in CASES:
        if names and case.name not in names:
            continue
        if case.scenario == "zandvoort" and not ZANDVOORT_CSV.is_file():
            print(f"{case.name}: skipped, no {ZANDVOORT_CSV}")
            continue
        record(case)
