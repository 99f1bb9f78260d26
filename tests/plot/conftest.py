"""Short real runs of the Flores slider-crank (3 ms: a few impacts) shared by the plotting tests."""

import json
import shutil
from pathlib import Path

import pytest

from clearsim.runner import simulate_config

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
SLIDER_CRANK_FRICTION = CONFIGS / "slider_crank_flores_friction.yaml"
SHORT = "solver.t_end=3ms"


def _run(folder: Path, name: str, config: Path, *overrides: str) -> Path:
    report = simulate_config(config, [SHORT, *overrides], folder / f"{name}.h5")
    assert report.complete, report.status
    return report.output


@pytest.fixture(scope="session")
def runs(tmp_path_factory) -> dict:
    """{'clearance': c = 0.5 mm, 'ideal': the same without clearance, 'small': c = 0.25 mm, 'tiny': c = 0.05 mm
    (lengths in µm), 'friction': with Ambrósio friction}."""
    folder = tmp_path_factory.mktemp("runs")
    return {
        "clearance": _run(folder, "sc", SLIDER_CRANK),
        "ideal": _run(folder, "ideal", SLIDER_CRANK, "joints.slider_pin.clearance=0"),
        "small": _run(folder, "small", SLIDER_CRANK, "joints.slider_pin.clearance=0.25mm"),
        "tiny": _run(folder, "tiny", SLIDER_CRANK, "joints.slider_pin.clearance=0.05mm"),
        "friction": _run(folder, "friction", SLIDER_CRANK_FRICTION),
    }


def sweep_folder(folder: Path, cases: dict) -> Path:
    """A folder as `clearsim sweep` leaves it: {case name: result file} copied in, and its cases.json."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, path in cases.items():
        if path is not None:
            shutil.copy(path, folder / f"{name}.h5")
    (folder / "cases.json").write_text(json.dumps({"cases": [{"name": name} for name in cases]}))
    return folder
