"""`clearsim life` on a pin worn by a steady load (tests/validation/test_wear.py's loaded pin): the wear of one
operation, k_w F ω R_J t / (H L w) at the loaded angle, scaled over the life; the blocks, the life file, resuming,
the pages and a stopped life."""

import math

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.life.run import LifeRequest, run_life
from tests.validation.test_wear import CLEARANCE, FORCE, JOURNAL_RADIUS, loaded_pin

K_W, HARDNESS, LENGTH, WIDTH, OMEGA, DURATION = 1e-4, 2e9, 0.02, 0.02, 100.0, 0.002  # 1, Pa, m, m, rad/s, s
PER_OPERATION = K_W * FORCE * OMEGA * JOURNAL_RADIUS * DURATION / (HARDNESS * LENGTH * WIDTH)  # m of depth at 270°
OPERATIONS = 10_000  # 10 000 × 0.5 nm = 5 µm, in a pocket 20 mm wide: curved less than the journal (a pocket of width w
# and depth d is tighter than it once d > w² c / (8 R_J R_B) = 12.6 µm; the pin would then ride on its rims and wear
# them, docs/model-contact.md "Contact on a worn bore")


@pytest.fixture(scope="module")
def pin_config(tmp_path_factory):
    wear = f"{{archard: {{coefficient: {K_W}, hardness: {HARDNESS} Pa, length: {LENGTH} m, width: {WIDTH} m}}}}"
    path = tmp_path_factory.mktemp("life") / "pin.yaml"
    path.write_text(loaded_pin(wear, t_end=f"{DURATION * 1e3} ms"))
    return path


@pytest.fixture(scope="module")
def pin_life(pin_config):
    report = run_life(LifeRequest(pin_config, OPERATIONS, pin_config.with_name("life.h5")))
    return report, pin_config.with_name("life.h5")


def test_a_steady_wear_is_scaled_over_the_life_in_few_blocks(pin_life):
    report, path = pin_life
    assert report.complete and report.last.operations == OPERATIONS
    assert report.simulations <= 2 * report.blocks + 6  # few refusals
    with h5py.File(path, "r") as life:
        operations = life["operations"][()]
        depth = life["joints/J/depth"][()]
        angles = life["angle"][()]
        loaded = int(np.argmin(np.abs(angles - 1.5 * math.pi)))
        assert operations[0] == 0 and operations[-1] == OPERATIONS and np.all(np.diff(operations) > 0)
        assert len(operations) - 1 <= 8  # blocks grow 4× while the wear does not change
        # the worn bore lowers the pin by the depth: each operation starts with a fall of < 5 µm (≈ 10 µs of the 2 ms)
        assert depth[-1, loaded] == pytest.approx(OPERATIONS * PER_OPERATION, rel=1e-2)
        assert np.argmax(depth[-1]) == loaded
        clearance = life["joints/J/clearance"][()]
        assert clearance[0] == pytest.approx(CLEARANCE) and np.all(np.diff(clearance) > 0)
        peak_force = life["figures/peak_contact_force_J_N"][()]
        assert peak_force[0] == pytest.approx(FORCE, rel=1e-6)  # new: the pin starts settled
        assert np.all(np.diff(peak_force) > 0)  # worn: it starts above the bore and lands, harder the deeper the wear
        assert life.attrs["complete"] and life.attrs["status"] == "complete"


def test_halving_the_blocks_error_changes_the_life_by_less_than_the_tolerance(pin_config, pin_life, tmp_path):
    _, coarse_path = pin_life
    fine = run_life(LifeRequest(pin_config, OPERATIONS, tmp_path / "fine.h5", tolerance=0.005))
    with h5py.File(coarse_path, "r") as coarse, h5py.File(tmp_path / "fine.h5", "r") as finer:
        difference = abs(coarse["joints/J/clearance"][-1] - finer["joints/J/clearance"][-1])
        assert difference < 0.02 * CLEARANCE, difference
        assert finer["operations"].shape[0] >= coarse["operations"].shape[0]
    assert fine.complete


def test_with_the_load_following_band_halving_the_blocks_error_changes_the_life_by_less_than_the_tolerance(tmp_path):
    """The default wear band (no `width`: the Hertz line contact's, narrowing as the load and the groove change it)
    over 1 000 operations: 2 blocks at the default tolerance, 4 at a quarter of it, the clearances within 2 % of c."""
    wear = f"{{archard: {{coefficient: {K_W}, hardness: {HARDNESS} Pa, length: {LENGTH} m}}}}"
    config = tmp_path / "band.yaml"
    config.write_text(loaded_pin(wear, t_end=f"{DURATION * 1e3} ms"))
    clearances = []
    for name, tolerance in (("coarse", 0.02), ("fine", 0.005)):
        report = run_life(LifeRequest(config, 1000, tmp_path / f"{name}.h5", tolerance=tolerance))
        assert report.complete
        with h5py.File(tmp_path / f"{name}.h5", "r") as life:
            clearances.append(life["joints/J/clearance"][()])
    coarse, fine = clearances
    assert len(fine) > len(coarse)  # the tighter tolerance took more blocks
    assert coarse[-1] - CLEARANCE > 0.01 * CLEARANCE  # it wore, by more than the tolerance's resolution
    assert abs(coarse[-1] - fine[-1]) < 0.02 * CLEARANCE, (coarse[-1], fine[-1])


def test_a_life_continues_from_its_file(pin_config, tmp_path):
    path = tmp_path / "life.h5"
    first = run_life(LifeRequest(pin_config, 2500, path))
    with h5py.File(path, "r") as life:
        rows = life["operations"][()].tolist()
        depth = life["joints/J/depth"][()]
    more = run_life(LifeRequest(pin_config, OPERATIONS, path))
    assert first.last.operations == 2500 and more.resumed_from == 2500 and more.last.operations == OPERATIONS
    with h5py.File(path, "r") as life:
        assert life["operations"][()].tolist()[:len(rows)] == rows and len(life["operations"]) > len(rows)
        assert np.array_equal(life["joints/J/depth"][:len(rows)], depth)  # the rows written before are kept
        assert life.attrs["complete"] and life.attrs["operations"] == OPERATIONS
    again = run_life(LifeRequest(pin_config, OPERATIONS, path))  # finished: nothing to do
    assert again.simulations == 0 and again.last.operations == OPERATIONS


runner = CliRunner()


def test_the_life_command_prints_its_summary_and_plots_its_pages(pin_config, pin_life, tmp_path):
    _, path = pin_life
    result = runner.invoke(app, ["plot", str(path), "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["life-clearance.png", "life-drift.png", "life-wear.png"]
    result = runner.invoke(app, ["life", str(pin_config), "-n", "10", "-o", str(tmp_path / "short.h5")])
    assert result.exit_code == 0, result.output
    assert "joint J: largest clearance" in result.output and "10 operations" in result.output


def test_refused_predictions_leave_no_operation_files(pin_config, tmp_path, monkeypatch):
    from clearsim.life import run

    original, failures = run.Machine.simulate, {"left": 3}

    def failing_predictions(machine, state, output):
        if output.name == "predicted.h5" and failures["left"] > 0:  # a prediction the solver could not finish
            failures["left"] -= 1
            output.write_bytes(b"a failed run's partial file")
            raise run.WornOperationFailed(f"{output}: did not complete")
        return original(machine, state, output)

    monkeypatch.setattr(run.Machine, "simulate", failing_predictions)
    report = run_life(LifeRequest(pin_config, 2500, tmp_path / "life.h5"))
    assert report.complete and failures["left"] == 0
    left = sorted(path.name for path in (tmp_path / "life-operations").iterdir())
    assert not [name for name in left if name.startswith("predicted")], left


def test_a_ctrl_c_during_an_operation_stops_the_life_and_the_same_command_continues_it(pin_config, tmp_path,
                                                                                     monkeypatch):
    """Ctrl-C (or SIGTERM) mostly lands while an operation integrates, where the run catches it and writes its flagged
    file: the life stops there with its rows kept and flagged interrupted, instead of refusing the block as if the
    operation had failed and going on; the same command then continues it to the end."""
    from clearsim.life import run

    original, calls = run.run_to_file, {"count": 0}

    def interrupted_fourth_run(system, loaded, output, **options):
        calls["count"] += 1
        if calls["count"] != 4:  # the second block's prediction (the first block: 0 → 4 020)
            return original(system, loaded, output, **options)

        def ctrl_c(time):
            raise KeyboardInterrupt

        return original(system, loaded, output, progress=ctrl_c, **options)

    monkeypatch.setattr(run, "run_to_file", interrupted_fourth_run)
    path = tmp_path / "life.h5"
    with pytest.raises(KeyboardInterrupt):
        run_life(LifeRequest(pin_config, OPERATIONS, path))
    assert calls["count"] == 4
    with h5py.File(path, "r") as life:
        assert not life.attrs["complete"] and life.attrs["status"] == "interrupted"
        kept = life["operations"][()].tolist()
    assert 0 < kept[-1] < OPERATIONS
    monkeypatch.setattr(run, "run_to_file", original)
    report = run_life(LifeRequest(pin_config, OPERATIONS, path))
    assert report.complete and report.resumed_from == kept[-1] and report.last.operations == OPERATIONS
