"""A worn bore's contact kinematics (clearsim/physics/wear.py, assembly/forces.py) against geometry computed
independently (tests/support/worn_bore.py): the closest point of the bore curve to the journal centre."""

import numpy as np
import pytest

from clearsim.assembly.arrays import for_kernels
from clearsim.assembly.forces import clearance_kinematics, second_rim, stick_row
from clearsim.assembly.system import assemble
from clearsim.model.loader import load_mechanism_text
from clearsim.physics import wear
from tests.support.worn_bore import bore_contacts, nearest_bore_contact, series_profile

BEARING_RADIUS = 0.02
CLEARANCE = 1e-4
JOURNAL_RADIUS = BEARING_RADIUS - CLEARANCE
MEAN, OVAL, TILT = 3e-5, 2e-5, 5e-6  # m: h(θ) = MEAN + OVAL cos 2θ + TILT sin θ


def depth(theta):
    return MEAN + OVAL * np.cos(2 * theta) + TILT * np.sin(theta)


def depth_slope(theta):
    return -2 * OVAL * np.sin(2 * theta) + TILT * np.cos(theta)


def depth_curvature(theta):
    return -4 * OVAL * np.cos(2 * theta) - TILT * np.sin(theta)


MODEL = f"""
name: worn bore geometry
units: SI
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: sleeve, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}}
  - {{name: pin, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: pivot, type: revolute, bodies: [ground, sleeve], at: O}}
  - {{name: J, type: revolute, bodies: [sleeve, pin], at: O, bearing_radius: {BEARING_RADIUS} m,
      clearance: {CLEARANCE} m, wear: {{profile: {{cos: [{MEAN} m, 0, {OVAL} m], sin: [{TILT} m]}}}}}}
solver: {{t_end: 1 ms}}
"""


@pytest.fixture(scope="module")
def system():
    return for_kernels(assemble(load_mechanism_text(MODEL).mechanism).arrays)


def profile(theta):
    return depth(theta), depth_slope(theta), depth_curvature(theta)


def reference_contact(local_e):
    return nearest_bore_contact(profile, BEARING_RADIUS, JOURNAL_RADIUS, local_e)


def journal_states(count=60, seed=3):
    """(q, q̇) of sleeve and pin: the sleeve turned, the pin's centre near the worn wall (±3 µm) all around."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        turn = rng.uniform(-np.pi, np.pi)
        angle = rng.uniform(-np.pi, np.pi)
        local = (CLEARANCE + depth(angle) + rng.uniform(-3e-6, 3e-6)) * np.array([np.cos(angle), np.sin(angle)])
        c, s = np.cos(turn), np.sin(turn)
        centre = np.array([c * local[0] - s * local[1], s * local[0] + c * local[1]])
        q = np.array([0.0, 0.0, turn, centre[0], centre[1], rng.uniform(-1, 1)])
        yield q, rng.normal(size=6) * np.array([0.0, 0.0, 3.0, 0.01, 0.01, 3.0]), turn


def test_penetration_and_normal_are_the_closest_bore_points(system):
    tilts = []
    for q, qd, turn in journal_states():
        ex, ey, _, _, penetration, _, nx, ny, _ = clearance_kinematics(system, 0, q, qd)
        c, s = np.cos(turn), np.sin(turn)
        local_e = np.array([c * ex + s * ey, -s * ex + c * ey])
        expected_penetration, local_normal = reference_contact(local_e)
        expected_normal = np.array([c * local_normal[0] - s * local_normal[1], s * local_normal[0] + c * local_normal[1]])
        assert penetration == pytest.approx(expected_penetration, abs=1e-12)
        assert np.array([nx, ny]) * JOURNAL_RADIUS == pytest.approx(expected_normal * JOURNAL_RADIUS, abs=1e-12)
        tilts.append(abs(expected_normal[0] * ey - expected_normal[1] * ex) / np.hypot(ex, ey))
    assert max(tilts) > 1e-3  # the worn normal is not e/|e|: the test tells the two apart


def along(function, q, qd, step=1e-6):
    """d/dt of function(q) along q̇ (central difference)."""
    return (function(q + step * qd) - function(q - step * qd)) / (2 * step)


def test_rates_are_the_time_derivatives_of_the_geometry(system):
    """δ̇ = dδ/dt, and the stick row: G q̇ = v_t and Ġ q̇ = d(G)/dt q̇ on the worn bore."""
    for q, qd, _ in journal_states(20, seed=5):
        rate = clearance_kinematics(system, 0, q, qd)[5]
        assert rate == pytest.approx(along(lambda x: clearance_kinematics(system, 0, x, qd)[4], q, qd), rel=1e-6,
                                     abs=1e-12)

        def g_times(x, velocity):
            bearing, journal, _ = stick_row(system, 0, x, qd)
            return np.dot(bearing, velocity[:3]) + np.dot(journal, velocity[3:])

        sliding = clearance_kinematics(system, 0, q, qd)[8]
        assert g_times(q, qd) == pytest.approx(sliding, rel=1e-12, abs=1e-15)
        curvature = stick_row(system, 0, q, qd)[2]
        assert curvature == pytest.approx(along(lambda x: g_times(x, qd), q, qd), rel=1e-5, abs=1e-9)


def test_the_kept_nearest_point_is_that_of_the_centre_asked_for():
    """One system asked in turn for journal centres, back and forth (the forces, the wear rates and the stick row of
    one state share a kept nearest point): every answer is bit for bit that of a fresh system asked only for it."""
    shared = for_kernels(assemble(load_mechanism_text(MODEL).mechanism).arrays)
    states = list(journal_states(count=8, seed=11))
    q, qd, _ = states[0]
    q = q.copy()
    q[2] = 0.0  # the sleeve unturned: the bearing frame is the global one
    for dy in (0.0, 2e-6, -0.0):  # centres on one line x = const. of the bearing frame
        moved = q.copy()
        moved[4] += dy
        states.append((moved, qd, 0.0))
    for q, qd, _ in states + states[::-1] + states:
        fresh = for_kernels(assemble(load_mechanism_text(MODEL).mechanism).arrays)
        assert clearance_kinematics(shared, 0, q, qd) == clearance_kinematics(fresh, 0, q, qd)
        assert stick_row(shared, 0, q, qd) == stick_row(fresh, 0, q, qd)


def test_a_circular_profile_gives_the_circular_kinematics():
    """A worn profile of constant depth h is a circular bore of clearance c + h (the worn branch against the
    circular one)."""
    worn = for_kernels(assemble(load_mechanism_text(MODEL.replace(f"{OVAL} m]", "0 m]").replace(
        f"sin: [{TILT} m]", "sin: [0 m]")).mechanism).arrays)
    round_model = MODEL.replace(f"clearance: {CLEARANCE} m", f"clearance: {CLEARANCE + MEAN} m, "
                                f"journal_radius: {JOURNAL_RADIUS} m").replace(f"bearing_radius: {BEARING_RADIUS} m,", "")
    round_model = round_model[:round_model.index(", wear:")] + "}\nsolver: {t_end: 1 ms}\n"
    circular = for_kernels(assemble(load_mechanism_text(round_model).mechanism).arrays)
    for q, qd, _ in journal_states(20, seed=7):
        assert np.array(clearance_kinematics(worn, 0, q, qd)) == pytest.approx(
            np.array(clearance_kinematics(circular, 0, q, qd)), rel=1e-9, abs=1e-13)


def test_profile_coefficients_evaluate_as_written():
    coefficients = wear.profile_coefficients([MEAN, 0.0, OVAL], [TILT])
    angles = np.linspace(0, 2 * np.pi, 37)
    assert wear.evaluate_profile(coefficients, angles) == pytest.approx(depth(angles), abs=1e-18)
    for theta in angles:
        assert wear.profile_value(coefficients, 2, theta) == pytest.approx(
            (depth(theta), depth_slope(theta), depth_curvature(theta)), abs=1e-16)


@pytest.mark.parametrize("width", [0.004, 0.01, 0.05])
def test_the_wear_kernel_has_the_stated_width_and_unit_volume(width):
    """w = R/K(0) to round-off, ∫K dθ = 1 (its a_0 is 1/2π), and the series is non-negative within its ringing."""
    harmonics = 64
    sigma = wear.kernel_sigma(width, harmonics, BEARING_RADIUS)
    rates = np.zeros(2 * harmonics + 1)
    wear.add_kernel_rates(rates, wear.kernel_weights(sigma, harmonics), harmonics, 1.0, 0.7)
    angles = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    kernel = wear.evaluate_profile(rates, angles)
    assert rates[0] == pytest.approx(1 / (2 * np.pi), rel=1e-15)
    assert wear.evaluate_profile(rates, [0.7])[0] == pytest.approx(BEARING_RADIUS / width, rel=1e-12)
    assert angles[np.argmax(kernel)] == pytest.approx(0.7, abs=2 * np.pi / 4000)
    assert kernel.min() > -1e-4 * kernel.max()


@pytest.mark.parametrize("harmonics", [8, 64, 512])
def test_the_narrowest_kernel_hardly_rings(harmonics):
    """σ = 4/M: the truncated series' negative lobes stay below 1e-4 of its peak; a narrower width is raised to it."""
    narrowest = wear.narrowest_width(harmonics, BEARING_RADIUS)
    assert wear.kernel_sigma(0.1 * narrowest, harmonics, BEARING_RADIUS) == wear.SMALLEST_SIGMA / harmonics
    rates = np.zeros(2 * harmonics + 1)
    weights = wear.kernel_weights(wear.SMALLEST_SIGMA / harmonics, harmonics)
    wear.add_kernel_rates(rates, weights, harmonics, 1.0, 0.3)
    kernel = wear.evaluate_profile(rates, np.linspace(0, 2 * np.pi, 20000, endpoint=False))
    assert kernel.min() > -1e-4 * kernel.max()
    assert narrowest == pytest.approx(np.sqrt(2 * np.pi) * BEARING_RADIUS * 4 / harmonics, rel=1e-3)


def test_a_measured_profile_is_fitted_to_its_series():
    """Depths measured at 12 angles of a profile with 2 harmonics give back its coefficients (least squares)."""
    angles = np.radians(np.arange(0, 360, 30))
    text = MODEL.replace(f"profile: {{cos: [{MEAN} m, 0, {OVAL} m], sin: [{TILT} m]}}",
                         f"profile: {{angles: [{', '.join(f'{a} rad' for a in angles)}], "
                         f"depth: [{', '.join(f'{d} m' for d in depth(angles))}], harmonics: 2}}")
    fitted = assemble(load_mechanism_text(text).mechanism).arrays.wear_profile[0]
    assert fitted == pytest.approx([MEAN, 0.0, TILT, OVAL, 0.0], abs=1e-18)


def test_a_centred_journal_has_finite_kinematics(system):
    """At the centre of an oval bore (the start of a run) the nearest-point search has no minimum to converge to; the
    kinematics stay finite and far from contact."""
    kinematics = clearance_kinematics(system, 0, np.zeros(6), np.array([0.0, 0.0, 1.0, 1e-3, -1e-3, 2.0]))
    assert np.all(np.isfinite(kinematics)) and kinematics[4] < -CLEARANCE
    assert np.all(np.isfinite(stick_row(system, 0, np.zeros(6), np.ones(6))[2]))


def test_a_pocket_tighter_than_the_journal_touches_it_at_its_rims():
    """A 10 µm pocket worn by a narrow kernel (1.5 mm on a 10 mm bore, journal 9.5 mm) is curved tighter than the
    journal: seen from a journal centre on its axis its bottom is a local maximum of the distance, the rims the
    minima (a two-point contact). The nearest bore point is the global minimum, to 1e-12 m of a dense reference,
    at every journal position round it (Newton's method from the angle of e alone stopped on the bottom, 10 µm too
    far, as a worn slider-crank bore did at 11.8 ms)."""
    bearing, journal, harmonics = 0.010, 0.0095, 64
    sigma = wear.kernel_sigma(0.0015, harmonics, bearing)
    rates = np.zeros(2 * harmonics + 1)
    wear.add_kernel_rates(rates, wear.kernel_weights(sigma, harmonics), harmonics, 1.0, 0.0)
    coefficients = rates * 1e-5 / wear.evaluate_profile(rates, np.array([0.0]))[0]  # 10 µm deep at θ = 0

    profile = series_profile(coefficients)
    depth_range = wear.depth_range(coefficients)
    reach, innermost = wear.inner_reach(coefficients, bearing), wear.innermost_radius(coefficients, bearing)
    samples = wear.bore_samples(coefficients, bearing)
    two_point = 0
    for angle in np.radians([-3.0, -1.0, -0.2, 0.0, 0.1, 0.4, 2.0, 5.0]):
        for eccentricity in (0.49e-3, 0.505e-3, 0.506e-3):
            e = eccentricity * np.array([np.cos(angle), np.sin(angle)])
            theta, rx, ry, *_ = wear.closest_bore_point(coefficients, samples, harmonics, depth_range, bearing, e[0],
                                                        e[1])
            penetration = journal - np.hypot(rx - e[0], ry - e[1])
            expected, _ = nearest_bore_contact(profile, bearing, journal, e)
            assert penetration == pytest.approx(expected, abs=1e-12), (np.degrees(angle), eccentricity)
            # the second rim (nearest_bore_point's last six values): the reference's other touched point, or none
            found = wear.nearest_bore_point(coefficients, samples, harmonics, depth_range, reach, innermost, bearing,
                                            *e, journal)
            touched = bore_contacts(profile, bearing, journal, e)
            assert journal - np.hypot(found[1] - e[0], found[2] - e[1]) == pytest.approx(expected, abs=1e-12)
            if len(touched) < 2:
                assert np.isnan(found[6]), (np.degrees(angle), eccentricity)
                continue
            two_point += 1
            rim = journal - np.hypot(found[7] - e[0], found[8] - e[1])
            assert rim == pytest.approx(touched[1][0], abs=1e-12)
            angles = sorted((value + np.pi) % (2 * np.pi) - np.pi for value in (found[0], found[6]))
            assert angles == pytest.approx(sorted((t + np.pi) % (2 * np.pi) - np.pi for _, _, t in touched), abs=1e-9)
    assert two_point >= 4  # the journal pressed into the pocket near its axis touches both rims


def test_a_bore_nowhere_tighter_than_the_journal_has_no_second_rim(system):
    """The oval of the module's model: every journal position near the wall touches it at one point only."""
    for q, qd, _ in journal_states():
        ex, ey, dex, dey = clearance_kinematics(system, 0, q, qd)[:4]
        assert second_rim(system, 0, q, qd, ex, ey, dex, dey)[0] == -np.inf


def random_profiles(seed, count):
    """(coefficients, M, R_B, c) of worn bores: 1 to 16 harmonics, wear up to 20 clearances deep, 0.01 to 5 % of R_B."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        harmonics = int(rng.choice([1, 2, 4, 8, 16]))
        bearing = float(rng.choice([0.01, 0.05]))
        clearance = bearing * float(rng.choice([1e-4, 2e-4, 1e-3, 0.05]))
        size = clearance * float(rng.uniform(0.1, 20.0))
        coefficients = np.zeros(2 * harmonics + 1)
        coefficients[0] = size
        coefficients[1:] = size * rng.normal(size=2 * harmonics) / np.repeat(np.arange(1, harmonics + 1), 2) ** 2 / 2
        yield coefficients, harmonics, bearing, clearance


def test_newton_alone_finds_the_searched_nearest_point():
    """Wherever Newton's method alone is taken (its minimum nearer than the bore's reach) it lands on the point the
    search finds, to 1e-15 m, its angle to the round-off of a nearest point's angle: 1e-12 rad (Newton's tolerance)
    + 4 ε R_B/|e| (g's round-off ε R_B² over g′ ≈ R_B |e| near the bore's centre, where the distance hardly varies
    round the bore); elsewhere the narrower search finds a point as near as the full one's, or
    nearer. 200 profiles, 50 journal centres each from the bore's centre to a clearance beyond its deepest wear."""
    rng = np.random.default_rng(11)
    newton_alone, worst_angle, worst_distance, farther = 0, 0.0, 0.0, []  # worst_angle: in units of its round-off
    for coefficients, harmonics, bearing, clearance in random_profiles(5, 200):
        depth_range = wear.depth_range(coefficients)
        reach = wear.inner_reach(coefficients, bearing)
        innermost = wear.innermost_radius(coefficients, bearing)
        samples = wear.bore_samples(coefficients, bearing)
        for _ in range(50):
            angle = rng.uniform(-np.pi, np.pi)
            e = rng.uniform(0.0, 2 * clearance + depth_range) * np.array([np.cos(angle), np.sin(angle)])
            nearest = wear.nearest_bore_point(coefficients, samples, harmonics, depth_range, reach, innermost, bearing,
                                              *e, 0.0)
            searched = wear.closest_bore_point(coefficients, samples, harmonics, depth_range, bearing, *e)
            distance = np.hypot(nearest[1] - e[0], nearest[2] - e[1])
            searched_distance = np.hypot(searched[1] - e[0], searched[2] - e[1])
            if distance < reach:
                newton_alone += 1
                round_off = wear.NEWTON_TOLERANCE + 4.0 * np.finfo(float).eps * bearing / np.hypot(*e)
                worst_angle = max(worst_angle,
                                  abs((nearest[0] - searched[0] + np.pi) % (2 * np.pi) - np.pi) / round_off)
                worst_distance = max(worst_distance, abs(distance - searched_distance))
            elif distance > searched_distance + 1e-15:
                farther.append((harmonics, bearing, clearance, e, distance - searched_distance))
    assert worst_angle < 1.0 and worst_distance < 1e-15
    assert newton_alone > 2000  # of 10 000: the comparison covers Newton's method alone
    assert farther == []


def test_a_journal_in_contact_needs_no_search():
    """A journal centre at R_J − δ (δ up to c/1000) along the inward normal of any point of a bore nowhere tighter
    than the journal (reach > R_J) is nearer than the reach: Newton's method from the angle of e finds its point
    alone, without the search — as it does in contact in each worn arc diagnose tries (the UHV breaker's joint A:
    0.0105 mm at 0°, 0.126 mm at 120°)."""
    from clearsim.diagnose.candidates import worn_arc

    arcs = [(worn_arc(depth, np.radians(angle), 0.05, 1e-5), 16, 0.05, 1e-5)
            for depth, angle in ((1.05e-5, 0.0), (1.26e-4, 120.0))]
    assert _missed_in_contact(arcs, 100) == (200, [])
    positions, missed = _missed_in_contact(random_profiles(6, 200), 20)
    assert positions > 1000 and len(missed) <= positions // 50, missed[:5]  # a minimum farther off e's angle


def _missed_in_contact(bores, count):
    """(positions, [(M, c/R_B, θ) where Newton's method alone did not find the point]) of `count` journal centres in
    contact round each bore whose reach is above R_J."""
    rng = np.random.default_rng(12)
    positions, missed = 0, []
    for coefficients, harmonics, bearing, clearance in bores:
        reach = wear.inner_reach(coefficients, bearing)
        if reach <= bearing - clearance:
            continue
        for theta in rng.uniform(-np.pi, np.pi, count):
            h, slope, _ = wear.profile_value(coefficients, harmonics, theta)
            rho = bearing + h
            tangent = np.array([slope * np.cos(theta) - rho * np.sin(theta), slope * np.sin(theta) + rho * np.cos(theta)])
            inward = np.array([-tangent[1], tangent[0]]) / np.hypot(*tangent)
            distance = bearing - clearance - rng.uniform(0, 1e-3) * clearance
            e = rho * np.array([np.cos(theta), np.sin(theta)]) + distance * inward
            found = wear.descended_foot(coefficients, harmonics, bearing, e[0], e[1], np.arctan2(e[1], e[0]),
                                        2 * np.pi / (8 * harmonics))[1] < reach
            positions += 1
            if not found:
                missed.append((harmonics, clearance / bearing, theta))
    return positions, missed


def test_the_inner_reach_is_below_the_tightest_radius_and_the_bottleneck():
    """inner_reach: R_B for a circle; otherwise at most the tightest radius of curvature on 200 000 angles and the
    half-width of the bore, and within 1e-8 of that radius where it is below 0.99 ρ_min cos ψ_max (the bound of the
    bottleneck, ψ the angle between the normal and the radius: tan ψ = |ρ'|/ρ)."""
    assert wear.inner_reach(np.zeros(1), 0.02) == 0.02
    assert wear.inner_reach(np.array([0.0, 0.0, 0.0, 0.0, 0.0]), 0.02) == pytest.approx(0.02, rel=1e-8)
    angles = np.linspace(0.0, 2 * np.pi, 200_000, endpoint=False)
    curvature_set = 0
    for coefficients, harmonics, bearing, _ in random_profiles(7, 40):
        tightest = min(wear.bore_curvature_radius(coefficients, harmonics, bearing, theta) for theta in angles)
        radii = bearing + wear.evaluate_profile(coefficients, angles)
        half_width = 0.5 * (radii + np.roll(radii, len(angles) // 2)).min()
        slopes = np.abs(np.gradient(radii, angles[1]))
        reach = wear.inner_reach(coefficients, bearing)
        assert reach <= min(tightest, half_width)
        if tightest < 0.99 * radii.min() / np.hypot(1.0, slopes.max() / radii.min()):
            assert reach == pytest.approx(tightest, rel=1e-8)
            curvature_set += 1
    assert curvature_set > 10
