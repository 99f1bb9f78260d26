"""Progress is reported at every return of the compiled loop, not only when it brings samples."""

from pathlib import Path

from clearsim.runner import simulate_config
from clearsim.solver import simulate as sim

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"


def test_progress_moves_between_samples(tmp_path):
    """At 1 kHz output a 0.5 ms run has one sample (t = 0) but the loop returns every t_end/100 (steps of at most
    1 µs, so each hundredth holds several): the progress bar must follow the integration, not the samples (it stood
    still for minutes with a tiny max_step)."""
    seen = []
    report = simulate_config(SLIDER_CRANK, ["solver.t_end=0.5ms", "solver.output_rate=1kHz", "solver.max_step=1us"], tmp_path / "r.h5",
                             progress=seen.append)
    assert report.complete
    assert len(seen) >= sim.CHUNKS // 2, seen
    assert seen == sorted(seen) and seen[-1] == 0.5e-3
    assert len({round(t * 1e9) for t in seen}) >= sim.CHUNKS // 2  # distinct times: it moved
