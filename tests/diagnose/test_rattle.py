"""Whether a candidate's run rattles (docs/diagnose.md §4 step 3, "seen below the chaotic detail"): decided from the
impacts of the run it reports, not from whether its model has a clearance joint. A lubricated joint whose film carries
the load has a clearance but strikes nothing, so a gain in the comparison band alone is its film's signature.

The mechanism: the slider-crank with its slider pin in a 9 mm short-bearing oil film of 20 mPa·s (the benchmark's
crank-viscosity-mid, `solver.method: rosenbrock`), and the same slider-crank dry, whose 0.5 mm clearance rattles."""

import json
from pathlib import Path

import yaml
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.evaluate import Evaluator
from clearsim.model.loader import load_mechanism

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
ROSENBROCK = "solver.method=rosenbrock"  # the film's squeeze damping is stiff (docs/model-contact.md)


def film(viscosity: str) -> list[str]:
    return [f"joints.slider_pin.lubrication={{viscosity: {viscosity}, length: 9 mm}}", ROSENBROCK]


LUBRICATED = film("20 mPa*s")
CRANK_BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
               "--trigger-offset", "0.1ms"]
runner = CliRunner()


class InOrder:
    """An executor that runs each task in this process, one after another, as a sweep worker would."""

    def run(self, function, tasks, collect) -> bool:
        for task in tasks:
            collect(function(task))
        return False


def prediction_of(overrides: list[str], folder: Path):
    document = yaml.safe_load(load_mechanism(SLIDER_CRANK, overrides).resolved_yaml)
    evaluator = Evaluator(folder, SLIDER_CRANK.name, SLIDER_CRANK.parent, InOrder(), output_rate=50e3)
    (prediction,) = evaluator.evaluate([document])
    assert prediction.ok, prediction.error
    return prediction


def test_a_run_counts_its_impacts_from_the_episode_tables_of_a_sensors_only_file(tmp_path):
    """The dry slider pin (0.5 mm) strikes its wall again and again; in a 20 mPa·s film it never does (the film
    carries the load, or the journal rides the wall in continuous contact): no impacts."""
    assert prediction_of([], tmp_path / "dry").impacts > 10
    assert prediction_of(LUBRICATED, tmp_path / "film").impacts == 0


def test_a_thinner_oil_whose_film_carries_the_load_is_named(tmp_path):
    """The benchmark's crank-viscosity-mid: 12 mPa·s hidden where the model says 20 (0.5 % noise). The viscosity
    ranks first (ΔBIC ≈ −100, gap 1.96 → 0.97) with little gain in the screening band; its run has a clearance joint
    but no impact, so nothing chaotic to replay by luck, and it is named with an interval that covers 12 mPa·s. Judged
    by the clearance joint alone, it was rejected as "chaotic detail of the impacts"."""
    record = tmp_path / "bench.csv"
    made = runner.invoke(app, ["synthesize", str(SLIDER_CRANK), *sum((["--set", s] for s in film("12 mPa*s")), []),
                               *CRANK_BENCH, "--noise", "0.5%", "--seed", "3", "-o", str(record)])
    assert made.exit_code == 0, made.output
    result = runner.invoke(app, ["diagnose", str(SLIDER_CRANK), *sum((["--set", s] for s in LUBRICATED), []),
                                 "--measured", str(record), "--candidates", "viscosity,clearance,mass",
                                 "--workers", "2", "-o", str(tmp_path / "report")])
    assert result.exit_code == 0, result.output
    assert "chaotic detail of the impacts" not in result.output, result.output
    found = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    assert [(e["kind"], e["target"]) for e in found["effects"]] == [("viscosity", "slider_pin")], result.output
    low, high = found["effects"][0]["interval"]["viscosity"]
    assert low <= 0.012 <= high and found["gap_after"] < 0.6 * found["gap_before"], found["effects"][0]
