"""What the joint and energy pages draw of a lubricated joint and of drive elements: the oil film force beside the
dry contact force, and every /energy entry of the file in the energy panel's legend."""

from pathlib import Path

import numpy as np
import pytest

from clearsim.plot import load_run, plot_contact_forces, plot_energies
from clearsim.plot.history import energy_figure
from clearsim.plot.journal import FILM_GID, joint_figure
from clearsim.plot.style import new_figure
from clearsim.runner import simulate_config

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
LUBRICATED = ("solver.t_end=3ms", "joints.slider_pin.lubrication.viscosity=1e-4 Pa*s",
              "joints.slider_pin.lubrication.length=10 mm")
JOINT = "slider_pin"


@pytest.fixture(scope="module")
def lubricated(tmp_path_factory):
    """The Flores slider-crank with an oil film in slider_pin: film and dry contact take turns within 3 ms."""
    report = simulate_config(CONFIGS / "slider_crank_flores.yaml", list(LUBRICATED),
                             tmp_path_factory.mktemp("film") / "film.h5")
    assert report.complete, report.status
    return load_run(report.output)


@pytest.fixture(scope="module")
def hydraulic(tmp_path_factory):
    report = simulate_config(CONFIGS / "uhv_breaker_hydraulic.yaml", ["solver.t_end=5ms"],
                             tmp_path_factory.mktemp("hydraulic") / "hydraulic.h5")
    assert report.complete, report.status
    return load_run(report.output)


def test_the_contact_force_panel_draws_the_film_force_of_a_lubricated_joint(lubricated):
    active = lubricated.series(f"joints/{JOINT}/film_active")
    assert np.any(active == 1) and np.any(active == 0)  # precondition: both regimes in the run
    ax = plot_contact_forces([lubricated], JOINT, new_figure((5.0, 4.0)).add_subplot())
    film = [line for line in ax.get_lines() if line.get_gid() == FILM_GID]
    assert len(film) == 1
    expected = np.hypot(*lubricated.series(f"joints/{JOINT}/film_force").T)
    factor = {"N": 1.0, "kN": 1e-3, "MN": 1e-6}[ax.get_ylabel().rsplit("(", 1)[1].rstrip(")")]
    np.testing.assert_allclose(film[0].get_ydata(), factor * expected, rtol=1e-12)
    assert np.max(expected) > 0.0 and "film" in ax.get_ylabel()
    assert [text.get_text() for text in ax.get_legend().get_texts()] == ["dry contact $F_n$", "oil film $|F_{film}|$"]
    assert any(line.get_gid() == FILM_GID for line in joint_figure([lubricated], JOINT).axes[1].get_lines())


def test_a_dry_joint_draws_no_film_force(lubricated, tmp_path):
    report = simulate_config(CONFIGS / "slider_crank_flores.yaml", ["solver.t_end=1ms"], tmp_path / "dry.h5")
    ax = plot_contact_forces([load_run(report.output)], JOINT, new_figure((5.0, 4.0)).add_subplot())
    assert not any(line.get_gid() == FILM_GID for line in ax.get_lines()) and ax.get_legend() is None


def test_the_energy_panel_labels_every_energy_entry_of_the_file(hydraulic):
    """The hydraulic breaker's file holds the cylinder's works, the gas load's stored energy and the guide friction's
    dissipation besides the mechanism's energies: each is a line of the energy panel, its name in the legend."""
    entries = [key.split("/", 1)[1] for key in hydraulic.datasets if key.startswith("energy/")]
    assert {"gas_stored", "oil_compression", "hydraulic_supply_work", "guide_friction_dissipated"} <= set(entries)
    figure = energy_figure([hydraulic])
    legend = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    for entry in entries:
        if entry == "balance_error":  # the panel below is the balance error's
            continue
        name = "potential (change)" if entry == "potential" else entry.replace("_", " ")
        assert sum(label.startswith(name) for label in legend) == 1, (entry, legend)
    assert "gas stored (part of potential)" in legend
    assert len(legend) == len(entries) - 1


def test_an_energy_entry_that_stays_zero_is_labelled_so(hydraulic):
    ax = plot_energies(hydraulic, new_figure((5.0, 4.0)).add_subplot())
    labels = {line.get_label(): line for line in ax.get_lines()}
    zero = [key.split("/", 1)[1] for key in hydraulic.datasets
            if key.startswith("energy/") and key != "energy/balance_error" and not np.any(hydraulic.series(key))]
    assert "hydraulic_tank_work" in zero  # precondition: the rod chamber has not yet returned oil to the tank
    for entry in zero:
        assert f"{entry.replace('_', ' ')} (0 throughout)" in labels
