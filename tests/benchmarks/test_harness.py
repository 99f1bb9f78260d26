"""The benchmark harness runs and writes every field (no timing is asserted: timings live in benchmarks/)."""

import json

import yaml

from benchmarks.extras import four_bar_chain
from benchmarks.suite import main


def test_the_quick_harness_writes_a_complete_json(tmp_path):
    out = tmp_path / "bench.json"
    assert main(["--quick", "--cases", "crank-frictionless,scaling", "--json", str(out)]) == 0
    document = json.loads(out.read_text())
    (case,) = document["cases"]
    assert case["case"] == "crank-frictionless" and case["repeats"] == 1
    assert case["steps"] > 0 and case["rhs_evaluations"] >= 6 * case["steps"]
    assert 0.0 < case["wall_min_s"] <= case["wall_median_s"] <= case["wall_max_s"]
    assert 0.0 <= case["error_peak_acceleration"] < 0.05 and 0.0 <= case["error_max_contact_force"] < 0.05
    rows = document["scaling"]["rows"]
    assert all(row["complete"] for row in rows) and {row["clearance_joints"] for row in rows} == {0, 1}


def test_the_four_bar_chain_is_a_one_degree_of_freedom_mechanism_plus_its_clearance_joints():
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare

    for bars, clearances in ((1, 0), (4, 2)):
        document = yaml.safe_load(four_bar_chain(bars, clearances))
        assert len(document["bodies"]) == 2 * bars + 1
        system = prepare(load_mechanism_text(four_bar_chain(bars, clearances)))
        assert system.degrees_of_freedom == 2 * clearances  # the crank is driven
