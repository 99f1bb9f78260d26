"""Helpers for physics tests: run a config (bundled or inline YAML) and read its result file."""

from pathlib import Path

import pytest

from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.runner import prepare, run_to_file

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"


@pytest.fixture
def simulate_with_statistics(tmp_path):
    """simulate_with_statistics(config_name_or_yaml_text, *overrides) → (dict of the result file's datasets, the
    run's Statistics)."""
    counter = iter(range(10**6))

    def run(source: str, *overrides: str) -> tuple[dict, object]:
        if source.endswith(".yaml") and "\n" not in source:
            loaded = load_mechanism(CONFIGS / source, overrides)
        else:
            loaded = load_mechanism_text(source, overrides=overrides)
        output = tmp_path / f"run{next(counter)}.h5"
        report = run_to_file(prepare(loaded), loaded, output)
        assert report.complete, report.status
        return read_result(output), report.statistics

    return run


@pytest.fixture
def simulate(simulate_with_statistics):
    """simulate(config_name_or_yaml_text, *overrides) → dict of the result file's datasets."""
    return lambda source, *overrides: simulate_with_statistics(source, *overrides)[0]


@pytest.fixture(scope="module")
def uhv_runs(tmp_path_factory):
    """run(*overrides) → result of the bundled UHV model, memoised across the test module."""
    from clearsim.runner import BUNDLED_CONFIG

    folder, done = tmp_path_factory.mktemp("uhv"), {}

    def run(*overrides):
        if overrides not in done:
            loaded = load_mechanism(BUNDLED_CONFIG, overrides)
            output = folder / f"run{len(done)}.h5"
            report = run_to_file(prepare(loaded), loaded, output)
            assert report.complete, report.status
            done[overrides] = read_result(output)
        return done[overrides]

    return run
