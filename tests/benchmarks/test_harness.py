"""The benchmark harness runs and writes every field (no timing is asserted: timings live in benchmarks/)."""

import json
from dataclasses import fields

import pytest
import yaml

from benchmarks import exudyn_slider_crank
from benchmarks.scaling import four_bar_chain
from benchmarks.suite import Measurement, main


@pytest.fixture(scope="module")
def document(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "bench.json"
    assert main(["--quick", "--cases", "crank-frictionless,baseline,baseline-cartesian,peer", "--json", str(out)]) == 0
    return json.loads(out.read_text())


def test_the_quick_harness_writes_every_field_of_a_case(document):
    (case,) = document["cases"]
    assert set(case) == {f.name for f in fields(Measurement)}
    assert case["case"] == "crank-frictionless" and case["repeats"] == 1 and document["quick"] is True
    assert case["steps"] > 0 and case["rhs_evaluations"] >= 6 * case["steps"]
    assert 0.0 < case["wall_min_s"] <= case["wall_median_s"] <= case["wall_max_s"]
    assert case["peak_memory_mb"] > 0.0 and case["us_per_step"] > 0.0
    assert 0.0 <= case["error_peak_acceleration"] < 0.05 and 0.0 <= case["error_max_contact_force"] < 0.05


def test_the_baseline_states_its_accuracy_and_its_ratio(document):
    (case,) = document["baseline"]["cases"]
    assert case["case"] == "crank-frictionless" and case["rows"]
    complete = {"rtol", "wall_s", "steps", "max_contact_force", "error_max_contact_force", "error_peak_acceleration"}
    for row in case["rows"]:  # a hand-written run that steps through the wall is a row that says so
        assert complete <= set(row) or set(row) == {"rtol", "failed"}
    if case["matched"] is not None:
        assert case["ratio"] > 0.0 and case["wall_median_s"] > 0.0


def test_the_cartesian_baseline_states_both_errors_and_its_ratio(document):
    (case,) = document["baseline-cartesian"]["cases"]
    assert case["case"] == "crank-frictionless" and case["reference"]["rtol"] == 1e-12
    for row in case["rows"]:
        assert {"error_max_contact_force", "error_peak_acceleration", "self_error_max_contact_force",
                "self_error_peak_acceleration", "constraint_drift"} <= set(row) or set(row) == {"rtol", "failed"}
    clearsim = [case["clearsim_reference_error_" + name] for name in ("max_contact_force", "peak_acceleration")]
    if case["matched"] is not None:  # matched means as accurate as clearsim on both figures, against the same reference
        assert case["matched"]["error_max_contact_force"] <= clearsim[0]
        assert case["matched"]["error_peak_acceleration"] <= clearsim[1]
        assert case["ratio"] == pytest.approx(case["wall_median_s"] / case["clearsim_wall_median_s"])
        assert case["ratio_equal_outputs"] == pytest.approx(case["equal_outputs_wall_median_s"]
                                                            / case["clearsim_in_memory_wall_median_s"])


def test_the_in_memory_run_is_the_file_run_without_its_file(tmp_path):
    """The equal-output comparisons time clearsim without its HDF5 file: the same integration, step for step."""
    from benchmarks.suite import CRANK, _run, _run_in_memory

    settings = ("solver.t_end=2ms",)
    _, report, _ = _run(CRANK, settings, tmp_path, "file")
    wall, history = _run_in_memory(CRANK, settings)
    mine, theirs = history.statistics, report.statistics
    assert wall > 0.0 and history.complete
    assert (mine.steps, mine.rejected_steps, mine.rhs_evaluations) == (theirs.steps, theirs.rejected_steps,
                                                                        theirs.rhs_evaluations)
    assert history.chunk.times.size == 201 and history.chunk.accelerations.shape[0] == 201  # 100 kHz over 2 ms
    assert mine.peak_normal_force.tolist() == theirs.peak_normal_force.tolist()


def test_the_peer_runs_or_says_how_to_install_it(document):
    peer = document["peer"]
    if not exudyn_slider_crank.available():
        assert peer == {"skipped": exudyn_slider_crank.MISSING}
        pytest.skip(exudyn_slider_crank.MISSING)
    first = peer["first_impact"]
    # the peer's model is the same mechanism: the first impact lands within one step of clearsim's
    assert abs(first["exudyn"]["onset_s"] - first["clearsim"]["onset_s"]) <= 2 * first["exudyn"]["step_s"]
    assert first["exudyn"]["peak_normal_force"] == pytest.approx(first["minimal_model"]["peak_normal_force"], rel=1e-3)
    (case,) = peer["cases"]
    assert {"step_s", "error_max_contact_force", "error_peak_acceleration", "crank_speed_drift"} <= set(case["rows"][0])
    for row in case["rows"]:  # each step timed as often as clearsim's ladder: a median, not one run
        assert row["repeats"] == document["repeats"] and row["wall_min_s"] <= row["wall_s"] <= row["wall_max_s"]
    for row in case["at_peer_accuracy"]:  # each against clearsim's file run and its in-memory run (equal outputs)
        if row["clearsim"] is not None:
            assert row["ratio_in_memory"] == pytest.approx(row["wall_s"] / row["clearsim"]["wall_in_memory_s"])
            paired = row["paired_ratio_in_memory"]  # and from alternated pairs
            assert paired["pairs"] == document["repeats"] and 0.0 < paired["min"] <= paired["median"] <= paired["max"]


def test_the_four_bar_chain_is_a_one_degree_of_freedom_mechanism_plus_its_clearance_joints():
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare

    for bars, clearances in ((1, 0), (4, 2)):
        document = yaml.safe_load(four_bar_chain(bars, clearances))
        assert len(document["bodies"]) == 2 * bars + 1
        system = prepare(load_mechanism_text(four_bar_chain(bars, clearances)))
        assert system.degrees_of_freedom == 2 * clearances  # the crank is driven


def test_the_diagnosis_benchmark_finds_the_hidden_clearance_and_counts_its_runs(tmp_path):
    from benchmarks.extras import describe, diagnose_throughput

    result = diagnose_throughput(quick=True, folder=tmp_path, measurements=[], repeats=1)
    assert result["study"] == "crank-clearance" and result["repeats"] == 1 and result["runs"] > 0
    assert result["wall_min_s"] == result["wall_median_s"] == result["wall_max_s"] > 0.0
    assert result["runs_per_minute"] == pytest.approx(60.0 * result["runs"] / result["wall_median_s"])
    (effect,) = result["found"]
    assert effect["kind"] == "clearance"
    assert "slider_pin" in {effect["target"], *[label.split("joint ")[-1] for label in effect["ties"]]}
    if effect["target"] == "slider_pin":  # the crank pin's clearance fits as well (a tie the report names)
        assert effect["value"] == pytest.approx(0.2e-3, rel=0.3) and result["error"] < 0.3
        assert "found clearance slider_pin" in describe("diagnose", result)
    assert result["gap_after"] < 0.6 * result["gap_before"]


def test_the_sweep_keep_benchmark_compares_equal_summaries_and_the_file_sizes(tmp_path):
    from benchmarks.extras import describe, sweep_keep

    result = sweep_keep(quick=True, folder=tmp_path, measurements=[], repeats=1)
    assert result["cases"] == 2 and result["repeats"] == 1 and result["same_summary"]
    full, summary = result["all"], result["summary"]
    # the UHV's nine bodies and twelve reactions left out: the histories (uncompressed; measured 0.22 against 0.74 MB
    # a 10 ms case) — the files' sizes also hold a fixed part (attributes, episode tables) that is most of a 10 ms
    # summary file (0.25 against 0.71 MB)
    assert summary["history_mb_per_case"] < full["history_mb_per_case"] / 3
    assert summary["mb_per_case"] < full["mb_per_case"]
    assert full["cases_per_minute"] == pytest.approx(60.0 * 2 / full["wall_median_s"])
    assert "same summary: True" in describe("sweep-keep", result)


def test_clearsims_side_of_the_first_impact_check_matches_the_minimal_model():
    """The peer study's first-impact check without the peer (which CI does not install): clearsim's onset and peak
    contact force of the slider-crank's first impact against the independent minimal-coordinate model."""
    from benchmarks.suite import CRANK, clearsim_first_impact
    from tests.support.slider_crank_minimal import FRICTIONLESS
    from tests.support.slider_crank_minimal import simulate as minimal

    onset, force = clearsim_first_impact(CRANK, 4e-4)
    exact = minimal(FRICTIONLESS, t_end=4e-4, rtol=1e-11).episodes[0]
    assert onset == pytest.approx(exact.onset, rel=1e-9)
    assert force == pytest.approx(exact.peak_normal_force, rel=1e-6)
