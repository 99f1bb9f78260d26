"""The numeric form of a mechanism that the compiled kernels read.

Three constraint primitives cover every ideal joint and driver:
  pin     (2 rows)  P_i − P_j = 0                                 revolute joint
  offset  (1 row)   (A_i w̄)·(P_j − P_i) − c0 − s(t) = 0          prismatic joint (w̄ ⊥ axis), prismatic/x/y driver
  angle   (1 row)   θ_j − θ_i − c0 − s(t) = 0                     prismatic rotation lock, revolute/angle driver
with s(t) a piecewise polynomial (law index ≥ 0) or 0 (law index −1). Rows are ordered
pins, offsets, angles. A clearance joint is no constraint: it is a force pair.
Whatever a sweep varies (clearance, friction, masses) lives in these arrays, so a new value
needs no recompilation.
"""

from __future__ import annotations

from collections import namedtuple

# columns of clearance_params
CL_BEARING_POINT = 0  # 0, 1: bearing centre in the bearing body's frame
CL_JOURNAL_POINT = 2  # 2, 3: journal centre in the journal body's frame
CL_BEARING_RADIUS = 4
CL_JOURNAL_RADIUS = 5
CL_CLEARANCE = 6
CL_STIFFNESS = 7
CL_EXPONENT = 8
CL_RESTITUTION = 9
CL_MIN_IMPACT_SPEED = 10
CL_MU_S = 11
CL_MU_D = 12
CL_V_LOW = 13
CL_V_HIGH = 14
CLEARANCE_COLUMNS = 15

# columns of offset_params
OFF_POINT_I = 0  # 0, 1
OFF_POINT_J = 2  # 2, 3
OFF_DIRECTION = 4  # 4, 5: w̄ in body i's frame
OFF_VALUE = 6  # c0

# columns of load_params (constant or tabulated point loads): point (2), force (2), torque
LOAD_COLUMNS = 5
# columns of spring_params: point i (2), point j (2), stiffness, damping, free length, preload
SPRING_COLUMNS = 8

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
    ],
)
