"""The life file (clearsim/life/store.py), its plot pages and the `clearsim life` input checks."""

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.life.blocks import Block, Operation
from clearsim.life.store import ANGLES, LifeFile, is_life_file, life_rows
from clearsim.plot.life import life_figures, shown_rows
from clearsim.physics.wear import evaluate_profile

CLEARANCES = {"A": 1e-5, "J": 2e-5}
HARMONICS = {"A": 2, "J": 1}


def block(operations, scale):
    state = {"A": scale * np.array([1e-6, 2e-7, 0.0, 0.0, 1e-7]), "J": scale * np.array([3e-7, 0.0, 1e-7])}
    wear = {"A": np.array([1e-10, 0.0, 0.0, 0.0, 0.0]), "J": np.array([2e-10, 1e-11, 0.0])}
    figures = {"operating_time_s": 0.068 + 1e-5 * scale, "peak_acceleration_m_s2": 600.0 + scale}
    return Block(operations, operations // 2, state, Operation(wear, figures), 0.5 * scale, 0)


@pytest.fixture
def life(tmp_path):
    initial = {"A": np.zeros(len(ANGLES)), "J": evaluate_profile(np.array([1e-6, 0.0, 5e-7]), ANGLES)}
    path = tmp_path / "life.h5"
    file = LifeFile.create(path, {"config_yaml": "x", "tolerance": 0.02, "operations": 100}, CLEARANCES, HARMONICS)
    for operations, scale in ((0, 0.0), (10, 1.0), (40, 2.0)):
        file.append(block(operations, scale), 2 * operations + 1, initial)
    file.finish(True, "complete")
    file.close()
    return path, initial


def test_a_life_file_holds_a_row_per_block_and_continues_from_its_last(life):
    path, initial = life
    assert is_life_file(path)
    with h5py.File(path, "r") as file:
        assert list(file["operations"][()]) == [0, 10, 40]
        depth = file["joints/J/depth"][2]
        expected = initial["J"] + evaluate_profile(block(40, 2.0).state["J"], ANGLES)
        assert np.allclose(depth, expected, rtol=0, atol=1e-18)
        assert file["joints/J/clearance"][2] == pytest.approx(CLEARANCES["J"] + expected.max(), rel=1e-12)
        assert file["figures/operating_time_s"][1] == pytest.approx(0.06801)
    last, size = LifeFile.reopen(path).last_block()
    assert (last.operations, size) == (40, 81)
    assert np.array_equal(last.state["A"], block(40, 2.0).state["A"])
    assert last.operation.figures["peak_acceleration_m_s2"] == 602.0
    labels = dict(life_rows(path))
    assert labels["operations"] == "40 in 2 blocks"


def test_the_life_pages_draw_every_joint_and_figure(life):
    path, _ = life
    figures = life_figures(path)
    assert set(figures) == {"wear", "clearance", "drift"}
    polar = figures["wear"].axes
    assert [ax.get_title() for ax in polar] == ["joint A: worn depth (µm)", "joint J: worn depth (µm)"]
    assert len(polar[1].get_lines()) == 3  # the three rows
    assert len(figures["clearance"].axes[0].get_lines()) == 2
    assert {ax.get_title() for ax in figures["drift"].axes} == {"time to contact touch", "peak |output acceleration|"}


def test_the_profiles_shown_span_the_life():
    assert shown_rows(np.array([0, 1, 2, 10, 100, 1000, 10000])) == [0, 5, 6]
    assert shown_rows(np.arange(0, 100, 10)) == [0, 2, 4, 7, 9]


runner = CliRunner()


@pytest.mark.parametrize("arguments, words", [
    (["--operations", "0"], "a life is at least 1"),
    (["--operations", "100", "--tolerance", "2"], "a fraction of the clearance"),
    (["--operations", "100"], "no joint wears"),
], ids=["no operations", "tolerance above 1", "no wearing joint"])
def test_a_life_that_cannot_start_exits_2_with_its_reason(tmp_path, arguments, words):
    from clearsim.runner import BUNDLED_CONFIG

    result = runner.invoke(app, ["life", str(BUNDLED_CONFIG), "-o", str(tmp_path / "life.h5"), *arguments])
    assert result.exit_code == 2, result.output
    assert words in result.output and "Traceback" not in result.output
    assert not (tmp_path / "life.h5").exists()
