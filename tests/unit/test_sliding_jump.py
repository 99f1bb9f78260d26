"""A sliding speed that jumps across 0 is integrated past, not located as a sliding stop again and again: on a worn
bore with a pocket tighter than the journal the contact's normal flips between the pocket's rims, and v_t with it
(docs/model-contact.md, "Contact on a worn bore")."""

from pathlib import Path

from clearsim.runner import simulate_config
from clearsim.solver import integrator as ig

UHV = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "uhv_breaker.yaml"
# an oval 20 µm deep at A and J (radius of curvature 49.9601 mm against the journal's 49.9900 mm): at 0.785 ms the
# journal at A crosses the pocket's bottom sliding at 0.063 m/s, and its v_t jumps to the other rim's −0.019 m/s.
# The sliding-stops event was located at the jump, the state reached there still slid the first way, and the next
# step found the same jump 5e-17 s on: 2000 such steps stopped the run ("the contact events stopped advancing the time")
OVAL_POCKET = [f"joints.{joint}.wear.profile.cos=[0.02mm, 0, 0.02mm]" for joint in "AJ"]


def test_a_jump_of_the_sliding_speed_across_zero_is_integrated_past(tmp_path):
    report = simulate_config(UHV, [*OVAL_POCKET, "solver.t_end=1ms"], tmp_path / "r.h5")
    assert report.complete, report.status
    assert report.statistics.steps < ig.STALLED_STEPS  # 152 steps (186 rejected); the stall alone took 2000
