"""The numeric form of a mechanism that the compiled kernels read.

Three constraint primitives cover every ideal joint and driver:
  pin     (2 rows)  P_i − P_j = 0                                 revolute joint
  offset  (1 row)   (A_i w̄)·(P_j − P_i) − c0 − s(t) = 0          prismatic joint (w̄ ⊥ axis), prismatic/x/y driver
  angle   (1 row)   θ_j − θ_i − c0 − s(t) = 0                     prismatic rotation lock, revolute/angle driver
with s(t) a piecewise polynomial (law index ≥ 0) or 0 (law index −1). Rows are ordered
pins, offsets, angles (Φ, λ and every vector of rows); the factor of S = Φ_q M⁻¹ Φ_qᵀ may hold them in another
order (row_place). A clearance joint is no constraint: it is a force pair.
Whatever a sweep varies (clearance, friction, masses) lives in these arrays, so a new value
needs no recompilation.
"""

from __future__ import annotations

import sys
from collections import namedtuple
from contextlib import contextmanager

import numpy as np
from numba import njit, typeof, types
from numba.experimental import structref

from clearsim import numba_inlining
from clearsim.physics.wear import BORE_POINT_TYPE, bore_point_kernel

numba_inlining.install()  # before any kernel compiles: numba's inliner copies each callee's IR once, not per block

# columns of clearance_params
CL_BEARING_POINT = 0  # 0, 1: bearing centre in the bearing body's frame
CL_JOURNAL_POINT = 2  # 2, 3: journal centre in the journal body's frame
CL_BEARING_RADIUS = 4
CL_JOURNAL_RADIUS = 5
CL_CLEARANCE = 6
CL_STIFFNESS = 7  # the elastic law's scale: K (N/m^n) of a power law, S = π L E* (N/m) of a cylindrical law
CL_EXPONENT = 8  # n of a power law (1, unused, for the others)
CL_RESTITUTION = 9
CL_MIN_IMPACT_SPEED = 10
CL_MU_S = 11
CL_MU_D = 12
CL_V_LOW = 13
CL_V_HIGH = 14
CL_VISCOSITY = 15  # oil film (physics/lubrication.py): μ in Pa·s, 0 for a dry joint
CL_FILM_LENGTH = 16  # m, pin length wetted by the film
CL_DRY_GAP = 17  # m, film thickness at which the dry contact starts (δ = |e| − c + this); 0 for a dry joint
CLEARANCE_COLUMNS = 18
# columns of clearance_laws: damping law (contact.CONTACT_LAWS), friction law, stick treatment, elastic law
# (cylindrical.ELASTIC_LAWS), film model (lubrication.BEARING_MODELS)
CLEARANCE_LAW_COLUMNS = 5
LAW_FILM_MODEL = 4

# columns of offset_params
OFF_POINT_I = 0  # 0, 1
OFF_POINT_J = 2  # 2, 3
OFF_DIRECTION = 4  # 4, 5: w̄ in body i's frame
OFF_VALUE = 6  # c0

# columns of load_params (constant or tabulated point loads): point (2), force (2), torque
LOAD_COLUMNS = 5
# columns of spring_params: point i (2), point j (2), stiffness, damping, free length, preload
SPRING_COLUMNS = 8
# columns of hydraulic_params and hydraulic_laws: clearsim/assembly/hydraulics.py HY_*, HL_*
HYDRAULIC_COLUMNS = 20
HYDRAULIC_LAW_COLUMNS = 4
# columns of torsion_params (rotational springs): stiffness, damping, free angle, preload
TORSION_COLUMNS = 4

SystemArrays = namedtuple(
    "SystemArrays",
    [
        "mass", "inertia", "gravity",
        "pin_bodies", "pin_points",
        "offset_bodies", "offset_params", "offset_law",
        "angle_bodies", "angle_value", "angle_law",
        "law_breaks", "law_coefficients", "law_first", "law_count",
        "clearance_bodies", "clearance_laws", "clearance_params",
        "load_bodies", "load_params", "load_law",
        "spring_bodies", "spring_params",
        "driveline_kinds", "driveline_bodies", "driveline_params", "driveline_table",  # assembly/drivelines.py
        "torsion_bodies", "torsion_params",
        "hydraulic_bodies", "hydraulic_params", "hydraulic_laws",
        "wear_harmonics", "wear_profile", "wear_samples", "wear_depth_range", "wear_bounds", "wear_slots", "wear_rates",  # worn bores, Archard wear (physics/wear.py)
        "row_place",  # each constraint row's place in the factor of S (see below)
    ],
    # force elements with states (assembly/hydraulics.py) and wear: none unless given
    defaults=(np.zeros((0, 2), np.int64), np.zeros((0, HYDRAULIC_COLUMNS)), np.zeros((0, HYDRAULIC_LAW_COLUMNS), np.int64),
              np.zeros(0, np.int64), np.zeros((0, 1)), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros((0, 2), np.int64), np.zeros((0, 2)),
              np.zeros(0, np.int64)),
)
# row_place[r]: the place of constraint row r in S and its factor (assembly/constraints.py schur_complement,
# assembly/dynamics.py solve_rows); empty: every row in its own place, as are the stick rows past it. A flexible
# model's rows lie joint by joint along the chain (build.ConstraintRows.places), where pins, offsets, angles would put
# the slides' rows after every pin and their envelope across the whole factor.
# wear_harmonics[k]: M of joint k's worn profile (0: a circular bore), whose coefficients [a_0, a_1, b_1, ...] are the
# start of the row wear_profile[k], and whose points r(2πk/N) (N = wear.sample_count(M)) start wear_samples[k] as
# x_0, y_0, x_1, … (m; the nearest-point searches' samples, wear.bore_samples); wear_depth_range[k] bounds its
# max − min (m; the nearest-point search's window);
# wear_bounds[k]: (WEAR_REACH, WEAR_INNERMOST) lower bounds of its inner reach and of its smallest radius R_B + min h
# (m; physics/wear.inner_reach, innermost_radius: nearer than the reach, the nearest point needs no search).
# wear_slots[k]: (first slot in z of its accumulated Archard profile, −1: none;
# its harmonics M); wear_rates[k]: (WEAR_SCALE, WEAR_LINE_STIFFNESS, g_0 .. g_M the kernel's weights)
WEAR_SLOT, WEAR_SLOT_HARMONICS = 0, 1
WEAR_REACH, WEAR_INNERMOST = 0, 1
WEAR_SCALE = 0  # k_w / (H L R_B c): the rate of the scaled profile h/c per unit F_n |v_t| (1/(N·m))
WEAR_LINE_STIFFNESS = 1  # S = π L E* (N/m) of the load-following band; 0: the stated width's kernel alone
WEAR_WEIGHTS = 2  # g_0 .. g_M from here


# --- the form the kernels take: one numba structref holding the arrays above -------------------------
# A kernel called with the namedtuple receives 25 arrays (≈ 200 machine words) and takes and releases a
# reference to each at every call; with the structref it receives one pointer. Same fields, same attribute
# syntax in the kernels, results bitwise identical; the compiled loop takes 40–50 % less time and compiles
# faster (docs/performance.md).


@structref.register
class KernelArraysType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class KernelArrays(structref.StructRefProxy):
    """SystemArrays as one reference-counted object for the kernels (built by `for_kernels`)."""


# Scratch of the constrained solves (assembly/dynamics.py), sized once per system so that a solve allocates
# nothing but its results: the small arrays numba would allocate, zero and free in every call cost a third of
# a slider-crank's right-hand side. One solve uses them at a time (kernels run single-threaded, under the GIL),
# and nothing a solve returns aliases them.
WORKSPACE_FIELDS = [
    "inverse_mass",  # (3 nb,) diagonal of M⁻¹: 1/m, 1/m, 1/J per body
    "solve_blocks",  # (rows, 2, 3) Φ_q (and stick rows) in row blocks
    "solve_bodies",  # (rows, 2) the bodies of each row block
    "solve_schur",  # (rows, rows) S = Φ_q M⁻¹ Φ_qᵀ
    "solve_lower",  # (rows, rows) its envelope Cholesky factor (only the envelope is written and read)
    "solve_envelope",  # (rows,) first column of each row's envelope
    "solve_band",  # (rows,) first column each row of S can have nonzero (rows sharing a body); S is zero left of it
    "solve_next_row",  # (rows,) the back substitution's list of the rows whose envelope reaches a column
    "solve_body_start",  # (nb + 1,) the row blocks of body b are solve_entries[start[b]:start[b + 1]]
    "solve_entries",  # (2 rows, 2) (row, slot) of each row block, grouped by body
    "solve_body_fill",  # (nb,)
    "solve_vector",  # (3 nb,) M⁻¹ f, then Φ_qᵀ λ
    "solve_residual",  # (rows,)
    "solve_place",  # (rows,) each row's place in S and its factor: row_place, then the rows past it in their own
    "solve_placed",  # (rows,) a right-hand side in those places, while it is solved
    "factor_key",  # (1 + nc,) what solve_lower holds: none / positive definite / not; which joints have stick rows
    "factor_q",  # (3 nb,) the q it was computed at
    "frame_trig",  # (nb, 3) θ, cos θ, sin θ of each body at the θ last seen (kinematics.kept_frame); θ NaN: none yet
    "bore_memo",  # (nc, 14) a worn bore's journal centre last seen in its bearing frame, its nearest point there
    # and the second rim it touches (forces.kept_bore_points: x, y, then bore_point's twelve values; x NaN: none yet)
]


# and the kernel that finds a worn bore's nearest point, called by address (wear.BORE_POINT_TYPE): the worn-bore
# geometry compiles as one library of its own, not linked into (and optimised again in) every kernel that reaches a
# clearance joint's kinematics, and only for a model with a worn bore (wear.bore_point_kernel)
KERNEL_FIELDS = list(SystemArrays._fields) + WORKSPACE_FIELDS + ["bore_point"]
structref.define_proxy(KernelArrays, KernelArraysType, KERNEL_FIELDS)


@njit(cache=True)
def _pack(fields, bore_point):
    return KernelArrays(*fields, bore_point)


def mass_diagonal(arrays: SystemArrays) -> np.ndarray:
    """The diagonal of M: m, m, J per body, in the order of q."""
    return np.column_stack([arrays.mass, arrays.mass, arrays.inertia]).ravel()


def _workspace(arrays: SystemArrays) -> tuple:
    """WORKSPACE_FIELDS for a system: rows = its constraint rows + one stick row per clearance joint."""
    bodies = arrays.mass.shape[0]
    rows = 2 * arrays.pin_bodies.shape[0] + arrays.offset_bodies.shape[0] + arrays.angle_bodies.shape[0]
    rows += arrays.clearance_bodies.shape[0]
    with np.errstate(divide="ignore"):  # as the kernels divide: a zero mass or inertia gives inf, not a warning
        inverse_mass = 1.0 / mass_diagonal(arrays)
    places = np.arange(rows, dtype=np.int64)
    places[:arrays.row_place.shape[0]] = arrays.row_place
    return (inverse_mass, np.zeros((rows, 2, 3)), np.zeros((rows, 2), np.int64), np.zeros((rows, rows)),
            np.zeros((rows, rows)), np.zeros(rows, np.int64), np.arange(rows, dtype=np.int64), np.zeros(rows, np.int64),
            np.zeros(bodies + 1, np.int64),
            np.zeros((2 * rows, 2), np.int64), np.zeros(bodies, np.int64), np.zeros(3 * bodies), np.zeros(rows),
            places, np.zeros(rows), np.zeros(1 + arrays.clearance_bodies.shape[0], np.int64), np.zeros(3 * bodies),
            np.full((bodies, 3), np.nan), np.full((arrays.clearance_bodies.shape[0], 14), np.nan))


def for_kernels(arrays: SystemArrays) -> KernelArrays:
    """The arrays as every compiled kernel takes them (one compiled specialisation for all callers), with the
    scratch of their solves."""
    return packed(tuple(arrays) + _workspace(arrays), arrays.wear_harmonics)


def packed(fields: tuple, wear_harmonics: np.ndarray) -> KernelArrays:
    """KernelArrays of the fields (a SystemArrays' and its workspace's, in KERNEL_FIELDS' order) with the worn bores'
    nearest-point kernel the joints' wear harmonics call for (wear.bore_point_kernel)."""
    bore_point = bore_point_kernel(wear_harmonics)
    if not _numba_target_ready:
        return _first_pack(fields, bore_point)
    return _packed(fields, bore_point)


def _packed(fields, bore_point) -> KernelArrays:
    """_pack compiled (or loaded) for the field `bore_point` typed by its function type, not as the kernel given, so
    that every model's KernelArrays has one type whichever kernel it holds. Its entry point is kept per the fields'
    array kinds (field_kinds): numba's typeof of the ~64 arrays takes ~0.4 ms, and a run packs its arrays four times
    (the assembly's checks, the run)."""
    kinds = field_kinds(fields)
    entry = _pack_entries.get(kinds)
    if entry is None:
        entry = _pack_entries[kinds] = _pack.compile((typeof(fields), BORE_POINT_TYPE))
    return entry(fields, bore_point)


_pack_entries: dict = {}


def field_kinds(fields: tuple) -> tuple:
    """What numba's typeof reads of each array (its dtype, dimensions and flags: layout, writeable, aligned), as a
    key; anything not an array by its type."""
    return tuple((field.dtype, field.ndim, field.flags.num) if type(field) is np.ndarray else typeof(field)
                 for field in fields)


_numba_target_ready = False


def _first_pack(fields, bore_point) -> KernelArrays:
    """_pack, the process's first kernel call, with scipy's BLAS hidden from numba (`blas_hidden`)."""
    global _numba_target_ready
    _numba_target_ready = True
    with blas_hidden():
        return _packed(fields, bore_point)


@contextmanager
def blas_hidden():
    """Around a process's first kernel call: numba's CPU target loads without scipy's BLAS.

    The first kernel a process calls loads numba's CPU target, which checks for BLAS by importing
    scipy.linalg.cython_blas: scipy.linalg and what it pulls in (numpy.testing, numpy.f2py, ...) cost 18 MB of
    memory and ~0.1 s per process (run, sweep worker). No kernel here uses BLAS (no `@`, np.dot or np.linalg
    inside a kernel), so numba is told there is none; scipy.linalg itself stays importable for everything else.
    If scipy.linalg is already loaded (diagnose), there is nothing to save and nothing is hidden.
    """
    name = "scipy.linalg.cython_blas"
    if "scipy.linalg" in sys.modules or name in sys.modules:
        yield
        return
    sys.modules[name] = None  # `import scipy.linalg.cython_blas` raises ImportError: numba records "no BLAS"
    try:
        yield
    finally:
        del sys.modules[name]


@njit(cache=True, inline="always")
def copy_into(out, values):
    """out[...] = values element by element (1-D): a slice assignment would compile numba's shape-mismatch
    message, 1.4 s of compile time for a check the callers' fixed sizes make needless."""
    for i in range(values.shape[0]):
        out[i] = values[i]
