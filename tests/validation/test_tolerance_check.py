"""A run says when its tolerance is coarser than a contact, and its penetration guard holds each contact step's
penetration error to 1 % whatever the tolerance (docs/model.md §4, "Unresolved contacts", "The penetration guard").

At rtol 1e-4, atol 1e-7 m the frictionless slider-crank sinks a gentle contact 0.33 mm into
the bearing (392 kN instead of 46 kN) and finishes without a word; the run now finishes with a warning naming the
joint, and stays silent at the default tolerances, where the same contacts are resolved. That gentle contact comes
late in a chaotic impact sequence, so whether a run meets it depends on round-off (on another machine the same
run does not): the test takes the first impact, the same on every machine, at a position tolerance of 1 mm (13× its
Hertz penetration).
"""

from pathlib import Path

import h5py
import pytest

from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare, run_to_file, summarize

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"


def run(tmp_path: Path, config: Path, *overrides: str):
    loaded = load_mechanism(config, overrides)
    report = run_to_file(prepare(loaded), loaded, tmp_path / "run.h5")
    assert report.complete, report.status
    return report


def test_a_tolerance_coarser_than_the_penetration_is_reported(tmp_path):
    report = run(tmp_path, CONFIGS / "slider_crank_flores.yaml", "solver.t_end=0.4ms", "solver.atol=1e-3")
    assert report.statistics.tolerance_over_penetration > 10.0
    assert len(report.warnings) == 1
    assert "not resolved by the solver tolerance" in report.warnings[0] and "joint slider_pin" in report.warnings[0]
    assert summarize(report.output).warnings == report.warnings
    with h5py.File(report.output) as handle:
        assert handle.attrs["warnings"] == report.warnings[0]


@pytest.mark.parametrize("config, overrides", [
    (CONFIGS / "slider_crank_flores.yaml", ()),
    (CONFIGS / "slider_crank_flores_friction.yaml", ()),
    (BUNDLED_CONFIG, ()),
    (BUNDLED_CONFIG, ("joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm")),
])
def test_the_default_tolerances_resolve_every_contact_of_the_bundled_models(tmp_path, config, overrides):
    report = run(tmp_path, config, *overrides)
    assert report.statistics.contact_events > 0  # there were contacts to check
    assert 0.0 < report.statistics.tolerance_over_penetration < 3.0
    assert solver_warnings(report.warnings) == []
    assert solver_warnings(summarize(report.output).warnings) == []
    # the guard rejected no try: these runs take the steps of the tolerance norm alone
    assert report.statistics.penetration_rejections == 0
    with h5py.File(report.output) as handle:
        assert handle.attrs["penetration_guard_rejections"] == 0


def test_the_penetration_guard_resolves_an_impact_a_loose_tolerance_would_flatten(tmp_path):
    """The slider-crank's first impact (the same on every machine) at rtol 1e-2, atol 1e-5 m: the tolerance norm
    alone accepts steps that leave its peak force 11 % low (40.7 kN); the guard rejects those whose estimated
    penetration error exceeds 1 % of the penetration, and the peak lands within 1e-3 of the default run's."""
    crank = CONFIGS / "slider_crank_flores.yaml"
    reference = run(tmp_path, crank, "solver.t_end=0.4ms").statistics.peak_normal_force
    report = run(tmp_path, crank, "solver.t_end=0.4ms", "solver.rtol=1e-2", "solver.atol=1e-5")
    assert report.statistics.penetration_rejections > 0
    assert report.statistics.peak_normal_force == pytest.approx(reference, rel=1e-3)


def solver_warnings(warnings: list[str]) -> list[str]:
    """All but the whirl of a journal, a warning about the model (the UHV's J whirls: tests/validation/test_whirl.py)."""
    return [line for line in warnings if "whirls around its bearing" not in line]


def test_once_the_guard_has_rejected_a_try_it_steers_the_steps():
    """A try within the tolerance and within the guard's share is measured by the tolerance norm alone until the
    guard has rejected a try in the run (the default runs' steps stay those of the norm); from then on by the larger
    of the norm and the guard's ratio, so the step after a guarded one is proposed short enough for the guard
    instead of being tried at the norm's length and rejected (model.md §4)."""
    import numpy as np

    from clearsim.solver import integrator as ig
    from clearsim.solver.simulate import Run

    loaded = load_mechanism(CONFIGS / "slider_crank_flores.yaml", ["solver.t_end=0.235ms"])  # inside the first impact
    run = Run(prepare(loaded))
    for _chunk in run.chunks():
        pass
    assert run.modes.max() > 0  # the journal is in contact
    journal = run.system.arrays.clearance_bodies[0, 1]
    unit = np.zeros_like(run.y)
    unit[3 * journal:3 * journal + 2] = 1e-9  # a position error of the journal's centre
    scratch = np.empty_like(run.y)
    per_unit = ig.penetration_error_ratio(run.kernel_arrays, unit, run.y, run.y, run.modes, run.real[ig.R_ATOL],
                                          scratch)
    assert per_unit > 0.0
    error = unit * (0.5 / per_unit)  # the guard's ratio ≈ 0.5: within its share
    ratio = ig.penetration_error_ratio(run.kernel_arrays, error, run.y, run.y, run.modes, run.real[ig.R_ATOL], scratch)
    assert 0.4 < ratio < 0.6
    ints = np.zeros(ig.INT_SLOTS, np.int64)

    def guarded(norm):
        return ig.guarded_norm(run.kernel_arrays, norm, error, 1.0, run.y, run.y, run.modes, run.real, ints, scratch)

    assert guarded(0.1) == 0.1  # no guard rejection yet: the norm's
    assert guarded(2.0) == 2.0  # the norm rejects; the guard does not count it
    assert ints[ig.I_PENETRATION_REJECTED] == 0
    ints[ig.I_PENETRATION_REJECTED] = 1  # the guard has rejected a try in this run
    assert guarded(0.1) == ratio  # the guard's ratio steers
    assert guarded(0.7) == 0.7  # the norm where it is the larger
    assert ints[ig.I_PENETRATION_REJECTED] == 1
