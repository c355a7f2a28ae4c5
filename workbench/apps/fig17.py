"""The paper's Figure 17/18 comparison (section 6.6): the clothoid controller against an MPC on the fig17 path at
30 km/h, the vehicle starting 1 m off the path.

The paper could only compare its clothoid controller on the TruckSim truck with an "improved MPC" on a CarSim car
(`PUBLISHED`). Here every controller also runs on every plant (`FAIR`: clothoid and NMPC on the loaded
tractor-semitrailer and on the dynamic bicycle car), so that the plant is not confounded with the controller.
`run_fig17` simulates the fair set once; the published pairs are a selection of it.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

from workbench.apps.comparison import Comparison, RunSpec, compare
from workbench.apps.report import ReportSection, write_report
from workbench.simulation.simulator import SimulationConfig

SCENARIO = "fig17"
SPEED_KMH = 30.0
TRUCK, CAR = "tractor-semitrailer", "dynamic-bicycle"
#: As published: the clothoid controller on the truck, the MPC on the car.
PUBLISHED: tuple[RunSpec, ...] = (RunSpec("clothoid", TRUCK), RunSpec("nmpc", CAR))
#: Each controller on each plant.
FAIR: tuple[RunSpec, ...] = tuple(
    RunSpec(controller, vehicle) for vehicle, controller in itertools.product((TRUCK, CAR), ("clothoid", "nmpc"))
)


@dataclass(frozen=True)
class Fig17Result:
    """published: the paper's pairing; fair: every controller on every plant."""

    published: Comparison
    fair: Comparison

    def save(self, out_dir: str | Path) -> list[Path]:
        """Write the fair set's runs, summary.csv and figures to out_dir, the published set's figures with the
        prefix "published_", and report.html with both; return the paths (the report last)."""
        out = Path(out_dir)
        written = self.fair.save(out)
        written += self.published.save_figures(out, prefix="published_")
        sections = [
            ReportSection(
                "As published: clothoid on the truck, NMPC on the car",
                "The pairing of the paper's Figure 17: its clothoid controller on the loaded tractor-semitrailer, "
                "the MPC baseline on a passenger car.",
                self.published,
            ),
            ReportSection(
                "Fair: each controller on each plant",
                "The comparison the paper could not run: both controllers on both plants. The step-time ratio is "
                "each controller's median step time over the clothoid controller's on the same plant.",
                self.fair,
            ),
        ]
        intro = (
            "Replication of Figures 17 and 18 of Shaju, Southward & Ahmadian (2024): tracked trajectories, "
            "cross-track error against distance, speed against distance and steering against time, "
            f"on the fig17 path at {self.fair.config.speed_kmh:g} km/h from a 1 m initial offset."
        )
        written.append(
            write_report(out / "report.html", "Figure 17: clothoid controller against NMPC", sections, intro)
        )
        return written


def run_fig17(config: SimulationConfig | None = None) -> Fig17Result:
    """Simulate the fair set (it contains the published pairs) on the fig17 scenario."""
    fair = compare(SCENARIO, FAIR, config or SimulationConfig(speed_kmh=SPEED_KMH), reference_controller="clothoid")
    return Fig17Result(published=fair.select(PUBLISHED), fair=fair)


__all__ = ["FAIR", "PUBLISHED", "Fig17Result", "run_fig17"]
