"""The study run parameter circuit_ranges (`workbench.apps.studies.circuit_parameters`): typed as a file relative to
the spec, carried by the runs on generated circuits only, hashed into their ids by the ranges it holds (a spec
without it plans the ids it planned before), swept in [grid], read from the spec's own [circuits] table, refused
where it cannot shape anything, and the circuits checked for feasibility as the runs draw them."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import SMALL_CIRCUITS as SMALL
from study_helpers import write_spec

from workbench.apps.studies import load_spec
from workbench.apps.studies.runner import simulate
from workbench.base.errors import WorkbenchInputError

#: Turns of 5-7 m: tighter than the tractor-semitrailer's lock.
TIGHT = """[circuits]
min_radius_m = 5.0
max_radius_m = 7.0
max_curvature_rate_1pm2 = 0.1
offtracking_length_m = 0.0
clearance_m = 9.0
min_length_m = 100.0
max_length_m = 400.0
"""


def _spec(folder: Path, scenarios: str, grid: str = "", vehicles: str = '["kinematic-bicycle"]', tail: str = ""):
    text = (
        f'[study]\nscenarios = {scenarios}\ncontrollers = ["pure-pursuit"]\nvehicles = {vehicles}\n'
        f"[grid]\nspeed_kmh = 30\n{grid}\n{tail}"
    )
    return write_spec(folder, text)


def test_the_runs_on_circuits_carry_the_ranges_and_the_others_plan_the_ids_they_had(tmp_path):
    write_spec(tmp_path, SMALL, "small.toml")
    with_ranges = load_spec(_spec(tmp_path / "a", '["circuit:7", "dlc"]', 'circuit_ranges = "../small.toml"'))
    without = load_spec(_spec(tmp_path / "b", '["circuit:7", "dlc"]'))
    (circuit, dlc), (circuit_default, dlc_default) = with_ranges.plan(), without.plan()
    assert dict(circuit.values)["circuit_ranges"] == (tmp_path / "a" / ".." / "small.toml")
    assert circuit.parameters()["circuit_ranges"] == str(tmp_path / "a" / ".." / "small.toml")
    assert "circuit_ranges" not in dict(dlc.values) and dlc.run_id == dlc_default.run_id
    assert circuit.run_id != circuit_default.run_id
    assert simulate(circuit).metrics.path_length_m < 400.0 < simulate(circuit_default).metrics.path_length_m


def test_a_grid_sweeps_the_ranges_and_an_id_follows_the_ranges_not_the_file(tmp_path):
    write_spec(tmp_path, SMALL, "small.toml")
    write_spec(tmp_path, SMALL.replace("max_radius_m = 20.0", "max_radius_m = 24.0"), "wider.toml")
    write_spec(tmp_path, "# the same ranges, another file\n" + SMALL, "copy.toml")
    swept = load_spec(_spec(tmp_path, '["circuit:7", "circuit:8"]', 'circuit_ranges = ["small.toml", "wider.toml"]'))
    runs = swept.plan()
    assert swept.run_count() == len(runs) == 4 and len({r.run_id for r in runs}) == 4
    copy = load_spec(_spec(tmp_path / "c", '["circuit:7", "circuit:8"]', 'circuit_ranges = "../copy.toml"'))
    small = [r.run_id for r in runs if dict(r.values)["circuit_ranges"].name == "small.toml"]
    assert [r.run_id for r in copy.plan()] == small


def test_a_spec_carrying_a_circuits_table_names_itself_and_keeps_its_ids_when_edited(tmp_path):
    spec = load_spec(_spec(tmp_path, '["circuit:7"]', 'circuit_ranges = "spec.toml"', tail=SMALL))
    (run,) = spec.plan()
    assert dict(run.values)["circuit_ranges"] == tmp_path / "spec.toml"
    commented = SMALL.replace("[circuits]", "# another line\n[circuits]")
    edited = load_spec(_spec(tmp_path, '["circuit:7"]', 'circuit_ranges = "spec.toml"', tail=commented))
    assert edited.plan()[0].run_id == run.run_id
    with pytest.raises(WorkbenchInputError, match=r"\[circuits\] holds circuit ranges, read by the runs whose "):
        load_spec(_spec(tmp_path / "unread", '["circuit:7"]', tail=SMALL))


@pytest.mark.parametrize(
    ("scenarios", "grid", "message"),
    [
        ('["dlc", "fig17"]', 'circuit_ranges = "small.toml"', r"grid.circuit_ranges gives the ranges of generated "
         r"circuits \(circuit:SEED\), and study.scenarios has none \(dlc, fig17\)"),
        ('["circuit:7", "dlc"]', 'circuit_ranges = ["small.toml", "small2.toml"]', r"grid.circuit_ranges lists 2 "
         r"files, and study.scenarios has 'dlc', which is not a generated circuit: its runs would repeat alike"),
        ('["circuit:7"]', 'circuit_ranges = "none.toml"', r"grid.circuit_ranges: circuit ranges file '.*none.toml': "
         "no such file"),
        ('["circuit:7"]', 'circuit_ranges = "bad.toml"', r"grid.circuit_ranges: circuit ranges file '.*bad.toml': "
         r"\[circuits\]: unknown key 'radius'"),
        ('["circuit:7"]', "circuit_ranges = 3", r"grid.circuit_ranges\[0\] must be a file path; got 3"),
    ],
)  # fmt: skip
def test_ranges_that_shape_nothing_or_cannot_be_read_are_refused_naming_the_key(tmp_path, scenarios, grid, message):
    write_spec(tmp_path, SMALL, "small.toml")
    write_spec(tmp_path, SMALL.replace("12.0", "13.0"), "small2.toml")
    write_spec(tmp_path, "[circuits]\nradius = 3\n", "bad.toml")
    with pytest.raises(WorkbenchInputError, match=message):
        load_spec(_spec(tmp_path, scenarios, grid))


def test_the_feasibility_check_draws_the_circuits_within_the_ranges(tmp_path):
    write_spec(tmp_path, TIGHT, "tight.toml")
    truck = '["tractor-semitrailer"]'
    load_spec(_spec(tmp_path / "default", '["circuit:1"]', vehicles=truck))  # the default ranges: followed
    with pytest.raises(
        WorkbenchInputError,
        match=r"study.scenarios: circuit:1 \(circuit_ranges 'tight.toml'\) cannot be followed by tractor-semitrailer",
    ):
        load_spec(_spec(tmp_path, '["circuit:1"]', 'circuit_ranges = "tight.toml"', vehicles=truck))
