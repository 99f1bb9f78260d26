"""The peer: the Flores slider-crank built in Exudyn, with the same contact law and friction.

Matched accuracy: each step of STEP_LADDER is run once and its errors (peak slider acceleration on
clearsim's 100 kHz output grid, max contact force over every step) are taken against a run at
NOMINAL_STEP/100, as clearsim's are against rtol/100; the largest step whose contact-force error is within
clearsim's is timed and compared. Its acceleration error is reported beside it (it stays larger than
clearsim's at every step tried, so the ratio is, if anything, in Exudyn's favour).

The clearance joint between rod (journal) and slider (bearing) is an `ObjectContactSphereSphere`
with the bearing as a hollow sphere: in the plane this is exactly a journal in a bearing, evaluated
entirely in C++. Its Hunt–Crossley law (impactModel 1),
    F_n = K δ^n (1 + 3(1 − e)/2 · δ̇/δ̇⁻),
is the Lankarani–Nikravesh law F_n = K δ^n (1 + 3(1 − c_e²)/4 · δ̇/δ̇⁻) when e = (1 + c_e²)/2.
Friction is Exudyn's regularised Coulomb law (linear up to `frictionProportionalZone`, then μ_d);
clearsim's Ambrósio law (0 below v_0, linear to μ_d at v_1) differs only below v_1 = 1 mm/s, so the
peer's friction case is compared with clearsim run with the same μ_d (see `PEER_FRICTION`).

Formulation, the most efficient Exudyn offers for this mechanism: a kinematic tree in minimal
coordinates (crank → rod, and the slider on its own prismatic joint), integrated by Exudyn's explicit
Runge–Kutta (RK44) at a fixed step with no Python in the loop. Exudyn has no event location, so the
step must be small enough for the first impact (~50 µs of contact): 1e-6 s converges it
(`first_impact_check`). A kinematic tree cannot prescribe a joint's motion, so the crank is a flywheel:
inertia FLYWHEEL_INERTIA and the initial speed 5000 rpm; its speed changes by less than 1e-8 relative
over the run (reported as `crank_speed_drift`).

Needs `pip install -e '.[bench]'`; `available()` says whether Exudyn is importable.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from benchmarks.suite import clearsim_ladder, paired_ratio
from tests.support.slider_crank_minimal import FRICTION, FRICTIONLESS, Parameters, ideal_initial_state

FLYWHEEL_INERTIA = 1e4  # kg m², the crank's inertia about its pivot: a prescribed constant speed in effect
MISSING = "exudyn not installed (pip install -e '.[bench]')"


def available() -> bool:
    try:
        import exudyn  # noqa: F401
    except ImportError:
        return False
    return True


def hunt_crossley_restitution(restitution: float) -> float:
    """Exudyn's Hunt–Crossley e that gives the Lankarani–Nikravesh damping of c_e: (1 + c_e²)/2."""
    return 0.5 * (1.0 + restitution**2)


@dataclass
class PeerResult:
    step: float
    wall_s: float
    steps: int
    times: np.ndarray  # s, every recorded step
    normal_force: np.ndarray  # N, at `times`
    output_times: np.ndarray  # s, the output grid (clearsim's output rate)
    slider_acceleration: np.ndarray  # m/s², at `output_times`
    crank_speed_drift: float  # relative change of the crank (flywheel) speed over the run

    @property
    def max_contact_force(self) -> float:
        return float(np.max(self.normal_force))

    @property
    def peak_acceleration(self) -> float:
        return float(np.max(np.abs(self.slider_acceleration)))

    def first_impact(self) -> tuple[float, float]:
        """(onset time, peak normal force) of the first contact episode."""
        touching = self.normal_force > 0.0
        if not touching.any():
            return math.nan, 0.0
        start = int(np.argmax(touching))
        after = touching[start:]
        end = start + (int(np.argmin(after)) if not after.all() else len(after))
        return float(self.times[start]), float(np.max(self.normal_force[start:end]))


def _system(p: Parameters):
    """Exudyn system: kinematic tree [crank, rod | slider] with the contact; sensors for force, accelerations, speeds."""
    import exudyn as exu
    from exudyn.itemInterface import (MarkerKinematicTreeRigid, NodeGenericData, NodeGenericODE2, ObjectContactSphereSphere,
                                      ObjectKinematicTree, SensorNode, SensorObject, VObjectKinematicTree)

    system_container = exu.SystemContainer()
    mbs = system_container.AddSystem()
    theta2, x3, rate2, v3 = ideal_initial_state(p)
    r, l = p.crank_length, p.rod_length
    # joints: crank Rz at O; rod Rz at A (angle relative to the crank); slider Px along the x axis
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * 3, initialCoordinates=[0.0, theta2, x3],
                                       initialCoordinates_t=[p.crank_speed, rate2 - p.crank_speed, v3],
                                       numberOfODE2Coordinates=3))
    inertias = [np.diag([0.0, 0.0, value]) for value in (FLYWHEEL_INERTIA, p.rod_inertia, 1e-4)]
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ, exu.JointType.RevoluteZ, exu.JointType.PrismaticX],
        linkParents=[-1, 0, -1], jointTransformations=exu.Matrix3DList([np.eye(3)] * 3),
        jointOffsets=exu.Vector3DList([[0.0, 0.0, 0.0], [r, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        linkInertiasCOM=exu.Matrix3DList(inertias),
        linkCOMs=exu.Vector3DList([[0.0, 0.0, 0.0], [0.5 * l, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        linkMasses=[1.0, p.rod_mass, p.slider_mass], visualization=VObjectKinematicTree(show=False)))
    journal = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=1, localPosition=[l, 0.0, 0.0]))
    bearing = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=2, localPosition=[0.0, 0.0, 0.0]))
    data = mbs.AddNode(NodeGenericData(initialCoordinates=[0.0] * 4, numberOfDataCoordinates=4))
    contact = mbs.AddObject(ObjectContactSphereSphere(
        markerNumbers=[journal, bearing], nodeNumber=data, spheresRadii=[p.journal_radius, p.bearing_radius],
        isHollowSphere1=True, contactStiffness=p.stiffness, contactStiffnessExponent=p.exponent, contactDamping=0.0,
        impactModel=1, restitutionCoefficient=hunt_crossley_restitution(p.restitution),
        minimumImpactVelocity=p.min_impact_speed, dynamicFriction=p.mu_d, frictionProportionalZone=p.v_1))
    sensors = [mbs.AddSensor(SensorObject(objectNumber=contact, storeInternal=True,
                                          outputVariableType=exu.OutputVariableType.Force))]
    for kind in (exu.OutputVariableType.Coordinates_tt, exu.OutputVariableType.Coordinates_t):
        sensors.append(mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, outputVariableType=kind)))
    mbs.Assemble()
    return system_container, mbs, sensors


def _settings(t_end: float, step: float, record_period: float):
    import exudyn as exu

    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.numberOfSteps = int(round(t_end / step))
    integration.endTime = t_end
    integration.verboseMode = 0
    integration.adaptiveStep = False
    # the contact's data (gap, impact speed δ̇⁻) is updated once after each step; an explicit step is not
    # iterated again (the discontinuous iteration belongs to implicit solvers)
    integration.discontinuous.ignoreMaxIterations = True
    integration.discontinuous.maxIterations = 1
    integration.discontinuous.useRecommendedStepSize = False
    integration.explicit.computeEndOfStepAccelerations = True  # the slider acceleration is an output
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = record_period
    settings.linearSolver.solverType = exu.LinearSolverType.EXUdense
    return settings


def simulate(friction: bool = False, t_end: float = 0.024, step: float = 1e-6, output_period: float = 1e-5,
             record_period: float | None = None) -> PeerResult:
    """One run at a fixed step (RK44). The wall time covers building, assembling and integrating.

    The contact force is recorded every `record_period` (default: every step; clearsim tracks its peak
    over every step end too); the slider acceleration is read on clearsim's output grid, `output_period`.
    """
    import exudyn as exu

    p = FRICTION if friction else FRICTIONLESS
    record = step if record_period is None else record_period
    started = time.perf_counter()
    _, mbs, (force, acceleration, speed) = _system(p)
    exu.SolveDynamic(mbs, _settings(t_end, step, record), solverType=exu.DynamicSolverType.RK44)
    wall = time.perf_counter() - started
    forces = mbs.GetSensorStoredData(force)
    accelerations = mbs.GetSensorStoredData(acceleration)
    speeds = mbs.GetSensorStoredData(speed)
    on_grid = np.abs(accelerations[:, 0] / output_period - np.round(accelerations[:, 0] / output_period)) < 1e-6
    normal = _normal_force(forces, p)
    drift = abs(speeds[-1, 1] - speeds[0, 1]) / p.crank_speed
    return PeerResult(step, wall, int(round(t_end / step)), forces[:, 0], normal, accelerations[on_grid, 0],
                      accelerations[on_grid, 3], float(drift))


def _normal_force(forces: np.ndarray, p: Parameters) -> np.ndarray:
    """|F_n| from the contact's force vector: F_n = |F| / sqrt(1 + μ²) when sliding at full μ_d.

    With friction the force vector holds F_n n + F_t t; |F_t| ≤ μ_d F_n, so |F| overstates F_n by at
    most sqrt(1 + μ_d²) − 1 = 5e-5 for μ_d = 0.01. The peak is reached while sliding (|v_t| > v_1).
    """
    magnitude = np.linalg.norm(forces[:, 1:3], axis=1)
    return magnitude / math.sqrt(1.0 + p.mu_d**2)


def reference(friction: bool, t_end: float, step: float, factor: float = 100.0) -> PeerResult:
    """The run at a `factor` times smaller step, its contact force recorded every 10 steps (memory)."""
    return simulate(friction, t_end, step / factor, record_period=10.0 * step / factor)


def errors(result: PeerResult, tight: PeerResult) -> dict:
    """Relative errors of the peak slider acceleration and of the max contact force vs the tight run."""
    return {"error_peak_acceleration": abs(result.peak_acceleration - tight.peak_acceleration) / tight.peak_acceleration,
            "error_max_contact_force": abs(result.max_contact_force - tight.max_contact_force) / tight.max_contact_force}


STEP_LADDER = (1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2e-7)  # s, tried from the largest down
NOMINAL_STEP = 1e-6  # s: converges the first impact; its 100× smaller step is the reference


def first_impact_check(step: float = NOMINAL_STEP) -> dict:
    """The peer's first impact against clearsim's and the independent minimal model's (onset, peak F_n)."""
    from benchmarks.suite import CRANK, clearsim_first_impact
    from tests.support.slider_crank_minimal import simulate as minimal

    t_end = 4e-4  # the first episode is over by 0.29 ms
    peer = simulate(False, t_end, step).first_impact()
    exact = minimal(FRICTIONLESS, t_end=t_end, rtol=1e-11).episodes[0]
    onset, force = clearsim_first_impact(CRANK, t_end)
    return {"exudyn": {"step_s": step, "onset_s": peer[0], "peak_normal_force": peer[1]},
            "clearsim": {"onset_s": onset, "peak_normal_force": force},
            "minimal_model": {"onset_s": float(exact.onset), "peak_normal_force": float(exact.peak_normal_force)}}


def _matched(rows: list[dict], target: float) -> dict | None:
    """The largest step whose max-contact-force error is within clearsim's (the rows run largest first)."""
    return next((row for row in rows if row["error_max_contact_force"] <= target), None)


def at_peer_accuracy(row: dict, ladder: list[dict]) -> dict:
    """An Exudyn row with the loosest clearsim rtol at least as accurate in both errors, and the wall ratio."""
    keys = ("error_peak_acceleration", "error_max_contact_force")
    mine = next((r for r in ladder if "failed" not in r and all(r[k] <= row[k] for k in keys)), None)
    return {**row, "clearsim": mine, "ratio": row["wall_s"] / mine["wall_s"] if mine else None,
            # equal outputs: Exudyn keeps its sensors in memory, so clearsim's run without its HDF5 file
            "ratio_in_memory": row["wall_s"] / mine["wall_in_memory_s"] if mine and "wall_in_memory_s" in mine else None}


def compare_case(friction: bool, clearsim, repeats: int, quick: bool, folder) -> dict:
    """Peer rows for one slider-crank case: each step of the ladder run `repeats` times (wall median, min and max;
    its errors, the same in every run), as clearsim's ladder is; the step matching clearsim's accuracy, if any,
    against clearsim's measurement."""
    import statistics as stats

    t_end = clearsim.simulated_time_s
    factor = 10.0 if quick else 100.0  # --quick: a smoke test, not a measurement
    tight = reference(friction, t_end, NOMINAL_STEP, factor)
    rows = []
    for step in STEP_LADDER[3:4] if quick else STEP_LADDER:
        result = simulate(friction, t_end, step)
        walls = [result.wall_s] + [simulate(friction, t_end, step).wall_s for _ in range(repeats - 1)]
        rows.append({"step_s": step, "wall_s": stats.median(walls), "wall_min_s": min(walls), "wall_max_s": max(walls),
                     "repeats": len(walls), "steps": result.steps,
                     "max_contact_force": result.max_contact_force, "peak_acceleration": result.peak_acceleration,
                     "crank_speed_drift": result.crank_speed_drift, **errors(result, tight)})
    matched = _matched(rows, clearsim.error_max_contact_force)
    ladder = clearsim_ladder(clearsim.case, repeats, folder)
    out = {"case": clearsim.case, "t_end_s": t_end, "reference_step_s": NOMINAL_STEP / factor, "rows": rows,
           "clearsim_error_max_contact_force": clearsim.error_max_contact_force,
           "clearsim_error_peak_acceleration": clearsim.error_peak_acceleration, "matched": matched}
    out["clearsim_ladder"] = ladder
    out["at_peer_accuracy"] = [at_peer_accuracy(row, ladder) for row in rows]
    for row in out["at_peer_accuracy"]:  # the ratio again, from alternated pairs (equal outputs)
        if row["clearsim"] is not None:
            row["paired_ratio_in_memory"] = paired_ratio(lambda step=row["step_s"]: simulate(friction, t_end, step).wall_s,
                                                         clearsim.case, row["clearsim"]["rtol"], repeats)
    if matched is None:
        return out
    out.update(wall_median_s=matched["wall_s"], wall_min_s=matched["wall_min_s"], wall_max_s=matched["wall_max_s"],
               clearsim_wall_median_s=clearsim.wall_median_s, ratio=matched["wall_s"] / clearsim.wall_median_s)
    return out


def peer(quick: bool, folder, measurements, repeats: int = 1) -> dict:
    """Study entry for the harness: the first-impact check, then each slider-crank case side by side."""
    if not available():
        return {"skipped": MISSING}
    from benchmarks.suite import crank_study

    def compare(friction, clearsim, repeats, quick):
        return compare_case(friction, clearsim, repeats, quick, folder)

    return {"first_impact": first_impact_check(), **crank_study(compare, measurements, repeats, quick, folder)}
