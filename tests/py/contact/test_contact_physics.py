"""Block contacts (vertex-face / edge-edge penalty springs, Coulomb friction,
open-close iteration) checked against closed forms and conservation laws.

Scenes are built in `scenes.py`, whose closed forms and geometry are tested
first here without running DDA (the `test_closed_form_*` and
`test_geometry_*` tests). All blocks are hard rock (E = 10 GPa, nu = 0.25,
rho = 2600 kg/m^3): with the default contact stiffness kn = 40 E L (L the
block size) a 1 m cube sinks m g / (4 kn) ~ 1.6e-8 m into its support and its
own elastic shortening under gravity is rho g L^2 / (2E) ~ 1.3e-6 m, so every
tolerance below sits orders of magnitude above what a correct penalty model
gives and below what a wrong one would.

Every scene sets `maxDisplacement` explicitly (0.02 m per step, twice the
largest step displacement of these motions at the chosen dt), so the
allowed step displacement, and with it the default contact distance
(2.5 x that), does not depend on the scene's extent.

Run time: about 18 000 DDA steps in all, of scenes with 2 to 11 blocks
(no test is marked slow; the longest is the 10 s resting block, 5000 steps).

The `scene` tests use the contact engine's Python side: DDAIntegrator's
contact parameters, yade_dda.contacts() (id1, id2, state, normal,
normalForce, shearForce) and stats()['maxPenetration'].

"""
import math
import os
import random
import sys

import numpy
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator
from yade import Vector3

import scenes as S
from scenes import G

DT = 2e-3                  # largest time step [s]
MAX_DISPLACEMENT = 0.02    # allowed vertex displacement per step [m]; the fastest scene moves 0.01 m per step
deg = math.radians


# ---------------------------------------------------------------- helpers

def integrator(dt=DT, **kw):
    params = dict(dt=dt, gravity=(0, 0, -G), maxDisplacement=MAX_DISPLACEMENT)
    params.update(kw)
    return DDAIntegrator(label='dda', **params)


def run_to(t_end):
    """Runs until O.time reaches t_end [s]: whole steps, then the last one trimmed.

    Fails (instead of running for ever) when step cuts would need more than
    four times the nominal number of steps: a time step that collapses is a
    failure of the scene, reported with the time reached.
    """
    dda = O.engines[0]
    dt = dda.dt
    n = int(math.floor((t_end - O.time) / dt + 1e-9)) - 1
    budget = 4 * (n + 1) + 100
    if n > 0:
        O.run(n, True)
        budget -= n
    while O.time < t_end - 1e-12 * max(1.0, t_end):
        if budget <= 0:
            dda.dt = dt
            pytest.fail('time step collapsed: O.time = %.6g s of %.6g s after %d steps (last dt %.3g s)'
                        % (O.time, t_end, O.iter, yade_dda.stats()['dt']))
        dda.dt = min(dt, t_end - O.time)
        O.step()
        budget -= 1
    dda.dt = dt
    assert abs(O.time - t_end) <= 1e-12 * max(1.0, t_end)


def centroid(body):
    return tuple(yade_dda.block(body).centroid)


def moved(body, point, c0):
    """Current position of the material point that was at `point` when the centroid was c0
    (rigid part of the motion: the strains here are ~1e-6 and are left out)."""
    blk = yade_dda.block(body)
    offset = blk.rotation * Vector3(*S.sub(point, c0))
    return S.add(tuple(blk.centroid), tuple(offset))


def rotation_vector(body):
    return tuple(yade_dda.block(body).rotation.toRotationVector())


def force_on(body, other=None):
    """Total contact force [N] on `body` (from `other` only, if given), from yade_dda.contacts().

    A contact's normal points from id2 towards id1 and its forces act on id1,
    so a contact where `body` is id2 contributes with the opposite sign.
    """
    total = (0.0, 0.0, 0.0)
    for c in yade_dda.contacts():
        if body not in (c.id1, c.id2) or (other is not None and other not in (c.id1, c.id2)):
            continue
        f = S.add(S.scale(c.normalForce, tuple(c.normal)), tuple(c.shearForce))
        total = S.add(total, f if c.id1 == body else S.scale(-1.0, f))
    return total


def normal_force_between(a, b):
    """Sum of the normal forces [N] of the closed contacts between bodies a and b."""
    return sum(c.normalForce for c in yade_dda.contacts()
               if {c.id1, c.id2} == {a, b} and c.state != 'open')


def check_block(points, frictionDeg=0.0):
    """Raises if the points cannot make a DDA block of hard rock (core's own validation)."""
    check = yade_dda._core.checkBlock
    try:
        check(points, S.ROCK['density'], S.ROCK['young'], S.ROCK['poisson'], deg(frictionDeg))
    except TypeError:   # the core before contacts took no friction angle
        check(points, S.ROCK['density'], S.ROCK['young'], S.ROCK['poisson'])


def plane_of(face, above):
    """(point, unit normal) of the plane through the first three points of a face, the normal
    pointing to the side of the point `above`."""
    n = S.unit(S.cross(S.sub(face[1], face[0]), S.sub(face[2], face[0])))
    if S.dot(S.sub(above, face[0]), n) < 0:
        n = S.scale(-1.0, n)
    return face[0], n


def distance_to_plane(p, plane):
    return S.dot(S.sub(p, plane[0]), plane[1])


def margin_inside_rectangle(p, rectangle):
    """Smallest in-plane distance [m] from p to the edges of a rectangle face (4 corners in
    `box` order: 0-1 and 0-2 are edges); negative when p is outside."""
    o, a, b = rectangle[0], S.sub(rectangle[1], rectangle[0]), S.sub(rectangle[2], rectangle[0])
    s, t = S.dot(S.sub(p, o), S.unit(a)), S.dot(S.sub(p, o), S.unit(b))
    return min(s, S.norm(a) - s, t, S.norm(b) - t)


# ---------------------------------------------------------------- scene parameters

INCLINE = deg(30)
INCLINE_BLOCK = (1.0, 1.0, 1.0)    # along the slope, across, normal [m]
AZIMUTHS = {'dip-x': 0.0, 'dip-rotated': 1.1}   # dip direction of the slope, from +x [rad]


def regime_slab(b):
    """Slab extent in slope coordinates for a block of length b: 3 m of slope below it."""
    return (-1.0, -1.5, -1.0), (b + 3.0, 1.5, 0.0)

# One case per regime (classical chart: slides iff tan a > tan phi, topples iff tan a > b/h):
# (slope [deg], friction [deg], b along the slope [m], h [m]).
REGIMES = {
    # tan a = 0.364 < tan phi = 0.839 (x2.3), < b/h = 1 (x2.7)
    'stable': (20.0, 40.0, 1.0, 1.0),
    # tan a = 0.577 > tan phi = 0.176 (x3.3), < b/h = 1.5 (x2.6)
    'sliding': (30.0, 10.0, 1.5, 1.0),
    # tan a = 0.364 < tan phi = 0.839 (x2.3), > b/h = 0.2 (x1.8); pivot friction demand 0.24 < 0.839
    'toppling': (20.0, 40.0, 0.4, 2.0),
    # tan a = 1.43 > tan phi = 0.213 (x6.7), > b/h = 0.12 (x12); and, beyond the classical chart,
    # tan phi > b/h (x1.8, else the block would only slide) and the pivot friction demand for
    # toppling without slip, 0.413, exceeds tan phi (x1.9, else it would topple first, slip later)
    'sliding+toppling': (55.0, 12.0, 0.3, 2.5),
}
REGIME_TIME = 0.5   # [s]

# Wedges: (plunge of the intersection line, xi, beta [deg], azimuth [rad],
#          tan(phi_B)/tan(phi_A), target factor of safety)
WEDGES = {
    'symmetric-FS0.70': (35.0, 90.0, 90.0, 0.3, 1.0, 0.70),
    'tilted-FS0.85': (30.0, 100.0, 75.0, 2.0, 1.5, 0.85),
    'tilted-FS1.20': (30.0, 100.0, 75.0, 2.0, 1.5, 1.20),
    'symmetric-FS1.50': (35.0, 90.0, 90.0, 0.3, 1.0, 1.50),
}
WEDGE_ORIGIN = (3.0, -2.0, 10.0)
WEDGE_FRICTION_DEG = 60.0   # the wedge's own angle: above both planes', so each contact takes its plane's


def wedge_case(name):
    plunge, xi, beta, azimuth, ratio, fs = WEDGES[name]
    geo = S.wedge_geometry(deg(plunge), deg(xi), deg(beta), azimuth=azimuth, origin=WEDGE_ORIGIN)
    phiA, phiB = S.friction_for_wedge_fs(geo['nA'], geo['nB'], fs, ratio)
    return geo, phiA, phiB, fs


# ================================================================ closed forms (no DDA)

def test_closed_form_regime_cases_lie_far_inside_their_regimes():
    """The four regime cases, classified by the classical criteria and by the rigid-block model.

    The rigid model (scenes.rigid_block_on_incline) integrates the plane
    motion of a rigid block on a rigid incline with Coulomb friction; its
    starting mode must agree with the classical name, and the motion it
    predicts over REGIME_TIME is what the scene test checks DDA against.
    """
    expected = {'stable': (False, False), 'sliding': (True, False), 'toppling': (False, True),
                'sliding+toppling': (True, True)}
    modes = {'stable': ['rest'], 'sliding': ['slide'], 'toppling': ['topple'], 'sliding+toppling': ['slidetopple']}
    for name, (a, phi, b, h) in REGIMES.items():
        a, phi = deg(a), deg(phi)
        assert S.classical_regime(a, phi, b, h) == expected[name], name
        ratios = [math.tan(a) / math.tan(phi), math.tan(a) / (b / h)]
        assert min(max(r, 1 / r) for r in ratios) > 1.75, (name, ratios)
        slip, theta, seq = S.rigid_block_on_incline(a, phi, b, h, REGIME_TIME)
        assert seq == modes[name], (name, seq)
        if name == 'sliding':
            assert abs(slip - S.incline_slide_distance(a, phi, REGIME_TIME)) < 1e-3 * slip
    # the slide-topple case is far from both refined boundaries too
    a, phi, b, h = REGIMES['sliding+toppling']
    assert math.tan(deg(phi)) / (b / h) > 1.7
    assert S.toppling_friction_demand(deg(a), b, h) / math.tan(deg(phi)) > 1.8
    a, phi, b, h = REGIMES['toppling']
    assert S.toppling_friction_demand(deg(a), b, h) < 0.3 * math.tan(deg(phi))


def test_closed_form_incline_acceleration():
    """s(t) = g (sin a - tan(phi) cos a) t^2/2 equals the rigid model's sliding and is 0 when friction holds."""
    assert abs(S.incline_slide_distance(INCLINE, 0.0, 1.0) - G / 4) < 1e-12
    closed = G * (0.5 - math.tan(deg(20)) * math.sqrt(0.75)) / 2     # sin 30 = 1/2, cos 30 = sqrt(3/4)
    assert abs(S.incline_slide_distance(INCLINE, deg(20), 1.0) - closed) < 1e-12
    assert S.incline_slide_distance(INCLINE, deg(35), 2.0) == 0.0
    slip, theta, modes = S.rigid_block_on_incline(INCLINE, deg(20), 1.0, 1.0, 1.0)
    assert modes == ['slide'] and abs(slip - S.incline_slide_distance(INCLINE, deg(20), 1.0)) < 1e-3 * slip


def test_closed_form_wedge_vector_method_equals_textbook_forms():
    """Four independent routes to one wedge agree on 500 random wedges.

    (1) the vector method (normal reactions from equilibrium perpendicular to
    the line of intersection, scenes.wedge_reactions), (2) the textbook form
    FS = sin(beta)/sin(xi/2) tan(phi)/tan(psi_i) with xi, beta, psi_i measured
    from the planes (scenes.wedge_section_angles), (3) the same with the
    angles the geometry was built from, (4) a full 3x3 solve of
    R_A n_A + R_B n_B + T l = W z (numpy), whose T must be -W sin(psi_i); and the
    plunge and trend of the line from the dips and dip directions by the
    stereonet formula (scenes.intersection_from_dips).
    """
    rng = random.Random(7)
    for _ in range(500):
        xi = deg(rng.uniform(30, 170))
        beta = rng.uniform(xi / 2 + 0.05, math.pi - xi / 2 - 0.05)
        plunge, azimuth, phi = deg(rng.uniform(10, 70)), rng.uniform(0, 2 * math.pi), deg(rng.uniform(5, 50))
        geo = S.wedge_geometry(plunge, xi, beta, azimuth=azimuth)
        nA, nB = geo['nA'], geo['nB']
        fs = S.wedge_factor_of_safety(nA, nB, phi, phi)
        xi2, beta2, plunge2 = S.wedge_section_angles(nA, nB)
        assert abs(xi2 - xi) < 1e-12 and abs(math.sin(beta2) - math.sin(beta)) < 1e-12
        assert abs(plunge2 - plunge) < 1e-12
        assert abs(S.hoek_bray_factor_of_safety(xi2, beta2, plunge2, phi) - fs) < 1e-12 * fs
        assert abs(S.hoek_bray_factor_of_safety(xi, beta, plunge, phi) - fs) < 1e-12 * fs
        RA, RB = S.wedge_reactions(nA, nB)
        full = numpy.linalg.solve(numpy.array([nA, nB, geo['line']]).T, [0.0, 0.0, 1.0])
        assert RA > 0 and RB > 0
        assert abs(full[0] - RA) < 1e-12 and abs(full[1] - RB) < 1e-12
        assert abs(full[2] + math.sin(plunge)) < 1e-12
        dipA, dirA = S.dip_and_direction(nA)
        dipB, dirB = S.dip_and_direction(nB)
        if max(dipA, dipB) < deg(85):
            trend, plunge3 = S.intersection_from_dips(dipA, dirA, dipB, dirB)
            assert abs(plunge3 - plunge) < 1e-10
            horizontal = S.unit((geo['line'][0], geo['line'][1], 0.0))
            assert abs(math.sin(trend) - horizontal[0]) < 1e-10 and abs(math.cos(trend) - horizontal[1]) < 1e-10


def test_closed_form_wedge_limits():
    """Known limits: planes nearly coplanar (xi -> 180 deg) give a single plane's FS = tan(phi)/tan(psi);
    a symmetric right-angled wedge has the wedge factor K = 1/sin(45 deg) = sqrt(2); unequal angles weight
    each plane by its reaction."""
    phi, plunge = deg(30), deg(35)
    single = math.tan(phi) / math.tan(plunge)
    geo = S.wedge_geometry(plunge, deg(179), deg(90))   # K = 1/sin(89.5 deg) = 1 + 3.8e-5
    assert abs(S.wedge_factor_of_safety(geo['nA'], geo['nB'], phi, phi) - single) < 1e-4 * single
    geo = S.wedge_geometry(plunge, deg(90), deg(90))
    assert abs(S.wedge_factor_of_safety(geo['nA'], geo['nB'], phi, phi) - math.sqrt(2) * single) < 1e-12
    RA, RB = S.wedge_reactions(geo['nA'], geo['nB'])
    assert abs(RA - RB) < 1e-12 and abs(RA + RB - math.cos(plunge) / math.sin(deg(45))) < 1e-12
    # only plane A rough: FS = R_A tan(phi) / sin(psi) = half the symmetric one
    assert abs(S.wedge_factor_of_safety(geo['nA'], geo['nB'], phi, 0.0) - math.sqrt(2) * single / 2) < 1e-12


def test_closed_form_wedge_cases_reach_their_factor_of_safety_and_can_slide_without_lifting_a_corner():
    """Each scene wedge has its target FS, and a rigid wedge can translate along the line with all
    six contact points (keel corners on both planes, Q_A, Q_B) in compression.

    Translation along l with acceleration a: for normal forces N_i at points
    p_i with normals n_i, each carrying friction mu_i N_i against the motion
    (mu_i = tan(phi) when FS < 1; the uniformly mobilised tan(phi)/FS, a = 0,
    when FS > 1), force and moment balance about the centroid c,
        sum N_i (n_i - mu_i l) - W z = m a l,   sum (p_i - c) x N_i (n_i - mu_i l) = 0,
    are six equations for seven unknowns (N_i, a): a one-parameter family.
    Some member must have every N_i > 0 (else the wedge would tip or lift
    off a plane rather than slide), and a must be g sin(psi_i) (1 - FS).
    """
    for name in WEDGES:
        geo, phiA, phiB, fs = wedge_case(name)
        nA, nB, line = geo['nA'], geo['nB'], numpy.array(geo['line'])
        assert abs(S.wedge_factor_of_safety(nA, nB, phiA, phiB) - fs) < 1e-12
        assert max(phiA, phiB) < deg(WEDGE_FRICTION_DEG)
        mobilised = 1.0 if fs < 1 else fs
        _, c = S.tetrahedron_volume_centroid(geo['wedge'])
        points = [geo['wedge'][i] for i in geo['onA']] + [geo['wedge'][i] for i in geo['onB']]
        normals = [nA] * 3 + [nB] * 3
        mus = [math.tan(phiA) / mobilised] * 3 + [math.tan(phiB) / mobilised] * 3
        A = numpy.zeros((6, 7))
        for i, (p, n, mu) in enumerate(zip(points, normals, mus)):
            f = numpy.array(n) - mu * line
            A[0:3, i] = f
            A[3:6, i] = numpy.cross(numpy.array(S.sub(p, c)), f)
        A[0:3, 6] = -line                          # per unit mass and g: W = 1, m a = a
        rhs = numpy.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        particular = numpy.linalg.lstsq(A, rhs, rcond=None)[0]
        null = numpy.linalg.svd(A)[2][-1]
        assert numpy.abs(A @ particular - rhs).max() < 1e-12 and numpy.abs(A @ null).max() < 1e-12
        # acceleration is the same for every member of the family
        _, plunge = S.wedge_line(nA, nB)
        expected = math.sin(plunge) * (1 - fs) if fs < 1 else 0.0
        assert abs(null[6]) < 1e-12 and abs(particular[6] - expected) < 1e-12
        # best smallest normal force over the family: max over t of min_i (p_i + t q_i)
        p, q = particular[:6], null[:6]
        candidates = [0.0] + [(p[j] - p[i]) / (q[i] - q[j]) for i in range(6) for j in range(6)
                              if abs(q[i] - q[j]) > 1e-14]
        best = max(min(p + t * q) for t in candidates)
        assert best > 0.1, (name, best)   # every corner carries at least 10% of the weight


# ================================================================ geometry (core validation, no stepping)

def test_geometry_incline_scenes_are_valid_and_touch_exactly():
    """Every incline scene's blocks pass the core's validation; the block's base corners lie on the
    slab's top face (the plane through three of the slab's own corners) to 1e-12 m, at least 0.5 m
    inside it; the rest of the block is above it, the slab below; and the slab runs at least 3 m
    past the block downhill (room for the slides)."""
    cases = [(INCLINE, INCLINE_BLOCK, None, azimuth) for azimuth in AZIMUTHS.values()]
    cases += [(deg(a), (b, 1.0, h), regime_slab(b), 0.0) for a, _, b, h in REGIMES.values()]
    for slope, size, slab, azimuth in cases:
        kw = {} if slab is None else dict(slab=slab)
        geo = S.incline_geometry(slope, size, azimuth=azimuth, **kw)
        check_block(geo['slab'])
        check_block(geo['block'])
        top = plane_of(geo['slabTop'], geo['block'][7])
        assert abs(S.dot(top[1], geo['frame'][2]) - 1) < 1e-12
        for p in geo['blockBase']:
            assert abs(distance_to_plane(p, top)) < 1e-12
            assert margin_inside_rectangle(p, geo['slabTop']) >= 0.5
        assert all(distance_to_plane(p, top) > size[2] - 1e-12 for p in geo['block'] if p not in geo['blockBase'])
        assert all(distance_to_plane(p, top) < 1e-12 for p in geo['slab'])
        downhillEnd = max(S.dot(S.sub(p, geo['origin']), geo['frame'][0]) for p in geo['slabTop'])
        assert downhillEnd - size[0] >= 3.0 - 1e-12


def test_geometry_wedges_are_valid_and_touch_exactly():
    """The wedge's two lower faces lie on the slabs' top faces (the planes through three of each
    slab's own corners; corners to 1e-12 m), at least 0.5 m inside them; its other corner is well
    above each plane; each slab's top face reaches past the keel, where it lies under the other
    plane by more than 0.5 m (far beyond the contact distance)."""
    for name in WEDGES:
        geo, phiA, phiB, fs = wedge_case(name)
        for points in (geo['wedge'], geo['slabA'], geo['slabB']):
            check_block(points)
        _, c = S.tetrahedron_volume_centroid(geo['wedge'])
        planes = {'A': plane_of(geo['slabATop'], c), 'B': plane_of(geo['slabBTop'], c)}
        faces = {'A': (geo['slabATop'], geo['onA'], geo['nA'], 'B'),
                 'B': (geo['slabBTop'], geo['onB'], geo['nB'], 'A')}
        for key, (top, on, n, otherKey) in faces.items():
            plane = planes[key]
            assert abs(S.dot(plane[1], n) - 1) < 1e-12
            assert all(abs(distance_to_plane(p, plane)) < 1e-12 for p in top)
            for i, p in enumerate(geo['wedge']):
                d = distance_to_plane(p, plane)
                if i in on:
                    assert abs(d) < 1e-12, (name, key, i, d)
                    assert margin_inside_rectangle(p, top) >= 0.5
                else:
                    assert d > 0.5
            below = [distance_to_plane(p, planes[otherKey]) for p in top]
            assert sum(1 for d in below if d < 0) == 2 and max(d for d in below if d < 0) < -0.5


# ================================================================ scenes

@pytest.mark.parametrize('phiDeg,tolerance,azimuth', [(0.0, 0.005, 'dip-x'), (0.0, 0.005, 'dip-rotated'),
                                                       (20.0, 0.01, 'dip-x')],
                         ids=['frictionless', 'frictionless-rotated', 'phi20'])
def test_block_slides_down_incline(scene, phiDeg, tolerance, azimuth):
    """A cube released on a 30 deg incline slides s(t) = g (sin a - tan(phi) cos a) t^2/2.

    With friction the contact resists with tan(phi) N and N = m g cos(a) because
    nothing moves normal to the slope. Both forces are constant, so the
    acceleration is, and DDA's time scheme (D = v0 dt + a dt^2/2) is exact
    for constant acceleration: what is left is the settling into the penalty
    springs (normal to the slope, not measured) and the first step(s) before
    the contacts close and slide (scenes.incline_slide_distance).
    Frictionless: 0.5%; phi = 20 deg: 1%
    (s = 2.45 m and 0.906 m at t = 1 s). The block neither tips nor leaves
    the slope. The 'rotated' case turns the whole scene about z, which must
    change nothing.
    """
    geo, slab, block = S.build_incline(INCLINE, INCLINE_BLOCK, phiDeg, azimuth=AZIMUTHS[azimuth])
    O.engines = [integrator()]
    c0 = centroid(block)
    run_to(1.0)
    downhill, across, normal = geo['frame']
    d = S.sub(centroid(block), c0)
    expected = S.incline_slide_distance(INCLINE, deg(phiDeg), O.time)
    assert abs(S.dot(d, downhill) - expected) < tolerance * expected
    assert abs(S.dot(d, across)) < 1e-6
    assert abs(S.dot(d, normal)) < 1e-4
    assert S.norm(rotation_vector(block)) < 1e-3
    closed = [c for c in yade_dda.contacts() if c.state != 'open']
    assert closed and all(c.state == 'sliding' for c in closed)


def test_block_held_by_friction_on_incline(scene):
    """phi = 35 deg > 30 deg: static friction (needed tan 30 = 0.58 of N, available tan 35 = 0.70)
    holds the cube; in 2 s it moves less than 1e-4 m (elastic shear of the block and the
    shear springs: ~1e-6 m), and no contact carries more than its limit tan(phi) N.

    The springs share the downhill pull about equally (3188 N per corner), but the uphill
    corners carry 2334 N of normal force, so their limit is 1634 N: the start from rest's
    static steps with the true friction leave them at it (World::admitFriction), at rest.
    The settled state is at rest, so they start locked (World::lockSettledContacts) and stay
    so: every closed contact is locked after 2 s. (Left 'sliding', they stood at the limit
    with no slip; before admitFriction they slipped in the first step and the cube rang.)"""
    geo, slab, block = S.build_incline(INCLINE, INCLINE_BLOCK, 35.0)
    O.engines = [integrator()]
    c0 = centroid(block)
    run_to(2.0)
    assert S.norm(S.sub(centroid(block), c0)) < 1e-4
    assert S.norm(rotation_vector(block)) < 1e-4
    closed = [c for c in yade_dda.contacts() if c.state != 'open']
    mu = math.tan(math.radians(35.0))
    assert len(closed) == 4 and all(c.state == 'locked' for c in closed), [c.state for c in closed]
    assert all(S.norm(tuple(c.shearForce)) <= mu * c.normalForce * (1 + 1e-6) for c in closed)


# (case, the slope's pull over Coulomb's limit tan(a) / tan(phi), staticFrictionExcess or None for the default)
STATIC_FRICTION_CASES = [('held-within-the-excess', 1.005, None), ('slides-without-excess', 1.005, 0.0),
                         ('slides-at-coulombs-limit', 1.03, None)]


@pytest.mark.parametrize('case,pull,excess', STATIC_FRICTION_CASES, ids=[c[0] for c in STATIC_FRICTION_CASES])
def test_static_friction_holds_up_to_its_excess_and_slides_at_coulombs_limit(scene, case, pull, excess):
    """A rigid cube started at rest on a 30 deg incline whose friction angle
    gives tan(a) = pull x tan(phi). Static friction (staticFrictionExcess,
    1e-2 by default): a contact locked at the start of a step slips only
    beyond (1 + excess) tan(phi) N, and once it slips it has tan(phi) N. So
    at 1.005 the cube stays put (measured: 4e-8 m in 2 s); with the excess
    at 0 it slides at Coulomb's g (sin a - tan(phi) cos a), 4.88 cm in 2 s;
    at 1.03 it slides at that acceleration too, from its first step
    (measured: 0.28573 m, as Coulomb's to 5 digits). Rigid: a deformable
    cube's base spreads by Poisson's ratio, and its locked corners' radial
    forces take part of their limits (a 1 m cube of this rock slid at 1.005)."""
    phi = math.atan(math.tan(INCLINE) / pull)
    geo = S.incline_geometry(INCLINE, INCLINE_BLOCK)
    S.add_block(geo['slab'], S.rock(math.degrees(phi)), fixed=True)
    block = S.add_block(geo['block'], S.rock(math.degrees(phi)), rigid=True)
    O.engines = [integrator() if excess is None else integrator(staticFrictionExcess=excess)]
    c0 = centroid(block)
    run_to(2.0)
    slid = S.dot(S.sub(centroid(block), c0), geo['frame'][0])
    expected = S.incline_slide_distance(INCLINE, phi, O.time)
    print('%s: slid %.4e m, Coulomb %.4e m' % (case, slid, expected))
    if case == 'held-within-the-excess':
        assert abs(slid) < 1e-6, '%s: slid %.3e m' % (case, slid)
    else:
        assert abs(slid - expected) < 1e-4 * expected, '%s: slid %.5e m, Coulomb %.5e m' % (case, slid, expected)


@pytest.mark.parametrize('phiBlock,phiSlab', [(20.0, 45.0), (45.0, 20.0)], ids=['block-lower', 'slab-lower'])
def test_contact_takes_smaller_friction_angle(scene, phiBlock, phiSlab):
    """A contact uses the smaller friction angle of its two blocks: either way round, 20 deg
    governs and the cube slides g (sin a - tan 20 cos a) t^2/2 within 1% at t = 1 s."""
    geo, slab, block = S.build_incline(INCLINE, INCLINE_BLOCK, phiBlock, phiSlab=phiSlab)
    O.engines = [integrator()]
    c0 = centroid(block)
    run_to(1.0)
    expected = S.incline_slide_distance(INCLINE, deg(20), O.time)
    assert abs(S.dot(S.sub(centroid(block), c0), geo['frame'][0]) - expected) < 0.01 * expected


@pytest.mark.parametrize('phiDeg', [0.0, 20.0], ids=['frictionless', 'phi20'])
def test_unrelated_blocks_do_not_change_a_trajectory(scene, phiDeg):
    """The incline scene alone, and again beside a cube resting on its own floor 60 m away (added
    first, so block indices and body ids differ): the sliding block's centroid history must be the
    same to round-off (1e-12 relative) and the far cube must stay put (< 1e-5 m).

    Blocks that never come within the contact distance share no equations, so
    nothing but the (fixed) allowed displacement could couple them.
    """
    def run(withNeighbour):
        O.reset()
        if withNeighbour:
            floor, resting = S.build_resting_block(origin=(60.0, 0.0, 0.0))
        geo, slab, block = S.build_incline(INCLINE, INCLINE_BLOCK, phiDeg)
        O.engines = [integrator()]
        history = []
        for step in range(500):
            O.step()   # (O.run(n, True) costs ~40 ms of waiting per call; O.step does not)
            if step % 10 == 9:
                history.append((O.time, centroid(block)))
        rest = None
        if withNeighbour:
            rest = S.norm(S.sub(centroid(resting), (60.5, 0.5, 0.5)))
        return history, rest

    alone, _ = run(False)
    together, rest = run(True)
    assert rest < 1e-5
    assert len(alone) == len(together)
    for (t1, c1), (t2, c2) in zip(alone, together):
        assert abs(t1 - t2) <= 1e-12 * t1
        assert S.norm(S.sub(c1, c2)) <= 1e-12 * max(1.0, S.norm(c1))


def test_block_rests_on_floor(scene):
    """A 1 m cube on a fixed floor for 10 s: no drift, bounded penetration, no energy gain.

    Drift: the centroid may only settle by the block's elastic shortening
    under its weight, rho g L^2 / (2E) = 1.3e-6 m (half of it at the centroid),
    plus the springs' m g / (4 kn) = 1.6e-8 m; we allow 1e-5 m.

    Penetration: with kn = contactPenaltyFactor E L = 4e11 N/m the static penetration
    is m g / (n kn) for the load shared by n >= 1 springs, at most twice that
    for a suddenly applied load, so 2 m g / kn = 1.3e-7 m (1.3e-7 of the block
    size) bounds it with a factor >= 4 to spare when the four corners share
    the weight. Checked both as stats()['maxPenetration'] (every step) and
    geometrically (the lowest corner below z = 0).

    Energy: springs and elastic strain store energy >= 0 and the time scheme
    (gamma = 1) only dissipates, so kinetic + gravitational energy
    T + m g z_c never exceeds its initial value m g z_c0. Allowed excess:
    1e-10 m g L = 2.6e-6 J, far above the round-off of m g z_c (~1e-10 J after
    5000 steps) and far below the energies at stake (strain energy ~8e-3 J,
    spring energy ~2e-4 J). T includes rotation and strain rates
    (scenes.kinetic_energy).

    At rest the contact forces on the cube balance its weight (to 1e-3).
    """
    floor, block = S.build_resting_block()
    penaltyFactor = 40.0
    O.engines = [integrator(contactPenaltyFactor=penaltyFactor)]
    blk = yade_dda.block(block)
    mass, L = blk.mass, 1.0
    kn = penaltyFactor * S.ROCK['young'] * L
    c0 = centroid(block)
    e0 = mass * G * c0[2]
    worstGain = -math.inf
    worstPenetration = 0.0
    while O.time < 10.0 - 1e-9:
        O.step()
        kinetic = S.kinetic_energy(blk.mass, blk.volume, blk.secondMoment, blk.velocity)
        energy = kinetic + mass * G * blk.centroid[2]
        worstGain = max(worstGain, energy - e0)
        worstPenetration = max(worstPenetration, yade_dda.stats()['maxPenetration'])
    assert worstGain <= 1e-10 * mass * G * L
    assert S.norm(S.sub(centroid(block), c0)) < 1e-5
    assert worstPenetration <= 2 * mass * G / kn
    assert -min(v[2] for v in blk.vertices) <= 2 * mass * G / kn
    assert yade_dda.stats()['closedContacts'] >= 3
    f = force_on(block, floor)
    assert S.norm(S.sub(f, (0.0, 0.0, mass * G))) < 1e-3 * mass * G


def test_a_block_landing_flat_needs_no_friction_pass(scene):
    """A rigid 1 m cube dropped from 1 mm lands flat on a floor and bounces on it: its
    four corners' normal forces swing from 0 to several times its weight and back, but
    no tangential force acts (the drop is straight down), so every corner stays inside
    its friction cone, old or new, and moving its limit to its normal force moves no
    force: a pass's limits are settled without another pass (limitPasses stays 0). A
    test on the limits themselves made a pass at every step of the landing."""
    S.add_block(S.box((-2, -2, -1), (3, 3, 0)), S.rock(30.0), fixed=True)
    block = S.add_block(S.box((0, 0, 1e-3), (1, 1, 1 + 1e-3)), S.rock(30.0), rigid=True)
    O.engines = [integrator()]
    passes, forces = 0, []
    while O.time < 0.1:
        O.step()
        s = yade_dda.stats()
        passes += s['limitPasses']
        forces.append(O.forces.f(block)[2])
    weight = yade_dda.block(block).mass * G
    assert max(forces) > 2 * weight, (max(forces), weight)   # the landing loads the corners
    print('largest force / weight %.2f, limit passes %d' % (max(forces) / weight, passes))
    assert passes == 0, passes


@pytest.mark.parametrize('phiDeg', [15.0, 30.0])
def test_block_launched_along_floor_slides_to_a_stop(scene, phiDeg):
    """A 1 m cube resting on a floor, launched at v0 = 2 m/s along x, slides
    with the deceleration g tan(phi) and stops after v0^2 / (2 g tan(phi)).

    What could go wrong: its contacts with the floor are new at the first
    step and start locked; a spring holding the whole first step's slip tips
    the cube, the tipped solve's normal force (many times the weight) drives
    the friction of the next one, the cube loses 40% of its speed in one
    step and hops to a stop after 3 mm (where it should slide 0.35 m at 30
    deg). Checked: the speed at t = 0.1 s to 1e-4 of v0, the stopping
    distance to 1e-3 (it stops within one step of dt v0 = 4 mm, so the
    distance is exact to dt^2 terms), no lift-off (the centroid stays at
    0.5 m to the elastic settling), the cube does not turn, and it is at rest
    but for its tangential springs giving back the friction force they held
    when it stopped: their stored energy (mu m g)^2 / (2 k), k = 4 ks, is at
    most all kinetic, a speed of mu m g / sqrt(k m).
    """
    v0, mu = 2.0, math.tan(math.radians(phiDeg))
    floor, block = S.build_resting_block(frictionDeg=phiDeg)
    O.bodies[block].state.vel = (v0, 0, 0)
    O.engines = [integrator(dt=1e-3)]
    c0 = centroid(block)
    run_to(0.1)
    assert abs(yade_dda.block(block).velocity[0] - (v0 - G * mu * O.time)) < 1e-4 * v0
    run_to(v0 / (G * mu) + 0.05)
    c = centroid(block)
    assert abs((c[0] - c0[0]) - v0 * v0 / (2 * G * mu)) < 1e-3 * v0 * v0 / (2 * G * mu)
    assert abs(c[2] - c0[2]) < 1e-5 and abs(c[1] - c0[1]) < 1e-9
    assert yade_dda.block(block).rotation.toRotationVector().norm() < 1e-5
    mass = S.ROCK['density'] * 1.0
    ks = 0.4 * 40 * S.ROCK['young'] * 1.0   # shearStiffnessRatio x contactPenaltyFactor x E x size
    springBack = mu * mass * G / math.sqrt(4 * ks * mass)
    assert S.norm(yade_dda.block(block).velocity[0:3]) <= 1.05 * springBack


def test_tower_of_ten_cubes_stands(scene):
    """Ten identical 1 m cubes stacked with exactly coincident corners on a fixed floor stand for 5 s.

    Elastic shortening of the column: cube k (from the top, k = 1..10) carries
    (k - 1/2) m g on average, so the top settles by about
    sum (k - 1/2) rho g L^2 / E = 50 rho g L^2 / E = 1.3e-4 m, plus the springs'
    sum k m g / (4 kn) = 9e-7 m; the top cube may move 1e-3 m. The stack is
    symmetric, so no cube may tilt (rotation < 1e-4 rad, i.e. 1e-3 m over the
    10 m column) or shift sideways (< 1e-4 m).
    """
    floor = S.add_block(S.box((-2, -2, -1), (3, 3, 0)), S.rock(30.0), fixed=True)
    cubes = [S.add_block(S.box((0, 0, k), (1, 1, k + 1)), S.rock(30.0)) for k in range(10)]
    O.engines = [integrator()]
    starts = [centroid(c) for c in cubes]
    run_to(5.0)
    for cube, c0 in zip(cubes, starts):
        d = S.sub(centroid(cube), c0)
        assert math.hypot(d[0], d[1]) < 1e-4
        assert S.norm(rotation_vector(cube)) < 1e-4
    assert S.norm(S.sub(centroid(cubes[-1]), starts[-1])) < 1e-3
    assert centroid(cubes[0])[2] > 0.5 - 1e-4   # the bottom cube did not sink into the floor


@pytest.mark.parametrize('regime', list(REGIMES))
def test_block_on_incline_regime(scene, regime):
    """Stable, sliding, toppling, sliding + toppling: the regime shows in the motion after 0.5 s.

    Measured: the slip s of the block's downhill lower edge along the slope and
    the rotation theta about `across` (positive = top downhill), against the
    rigid-block model (scenes.rigid_block_on_incline), which at 0.5 s gives
        stable           s = 0,        theta = 0
        sliding          s = 0.426 m,  theta = 0   (= g (sin a - tan(phi) cos a) t^2/2)
        toppling         s = 0,        theta = 0.158 rad
        sliding+toppling s = 0.599 m,  theta = 0.203 rad.
    A motion that should be there must match the rigid model within 5%
    (sliding: 2%, the closed form); one that should not must stay below
    1e-3 m / 1e-3 rad (stable: 1e-4). The rotation must be about `across`.
    Only the sliding case has constant acceleration; in the others DDA's
    time scheme is first order, ~1e-3 relative at dt = 1e-3 s over 0.5 s.
    """
    a, phi, b, h = REGIMES[regime]
    geo, slab, block = S.build_incline(deg(a), (b, 1.0, h), phi, slab=regime_slab(b))
    O.engines = [integrator(dt=1e-3)]
    c0 = centroid(block)
    run_to(REGIME_TIME)
    downhill, across, normal = geo['frame']
    slip = S.dot(S.sub(moved(block, geo['pivot'], c0), geo['pivot']), downhill)
    rot = rotation_vector(block)
    theta = S.dot(rot, across)
    rigidSlip, rigidTheta, _ = S.rigid_block_on_incline(deg(a), deg(phi), b, h, O.time)
    if regime == 'stable':
        assert S.norm(S.sub(centroid(block), c0)) < 1e-4 and S.norm(rot) < 1e-4
        return
    if regime == 'sliding':
        assert abs(slip - rigidSlip) < 0.02 * rigidSlip
        assert S.norm(rot) < 1e-3
        return
    assert abs(theta - rigidTheta) < 0.05 * rigidTheta
    assert S.norm(S.sub(rot, S.scale(theta, across))) < 0.05 * theta
    if regime == 'toppling':
        assert abs(slip) < 1e-3
    else:
        assert abs(slip - rigidSlip) < 0.05 * rigidSlip


def build_wedge(name):
    geo, phiA, phiB, fs = wedge_case(name)
    slabA = S.add_block(geo['slabA'], S.rock(math.degrees(phiA)), fixed=True)
    slabB = S.add_block(geo['slabB'], S.rock(math.degrees(phiB)), fixed=True)
    wedge = S.add_block(geo['wedge'], S.rock(WEDGE_FRICTION_DEG))
    return geo, fs, slabA, slabB, wedge


@pytest.mark.parametrize('name', [n for n in WEDGES if WEDGES[n][-1] < 1])
def test_wedge_with_fs_below_one_slides_along_line_of_intersection(scene, name):
    """A tetrahedral wedge on two planes with FS < 1 slides down the line of intersection.

    FS = (R_A tan(phi_A) + R_B tan(phi_B)) / (W sin(psi_i)) with R_A, R_B from
    equilibrium perpendicular to the line (scenes.wedge_factor_of_safety; each
    plane's friction angle is set to give the target FS, the wedge's own angle
    is larger so each contact takes its plane's). Sliding along l, the wedge
    accelerates at g sin(psi_i) (1 - FS): after t = 1 s its centroid has moved
    within 1 deg of l, by g sin(psi_i) (1 - FS) t^2/2 within 2% (0.84 m for FS 0.7,
    0.37 m for FS 0.85; a relative friction error e changes it by e FS/(1 - FS),
    so 2% is 0.35% of friction at FS 0.85). It stays on both planes (its six contact
    corners within 1e-3 m of them) and each plane carries its normal reaction
    R W within 2% (perpendicular to l nothing accelerates).
    """
    geo, fs, slabA, slabB, wedge = build_wedge(name)
    O.engines = [integrator()]
    c0 = centroid(wedge)
    run_to(1.0)
    d = S.sub(centroid(wedge), c0)
    line = geo['line']
    _, plunge = S.wedge_line(geo['nA'], geo['nB'])
    expected = G * math.sin(plunge) * (1 - fs) * O.time ** 2 / 2
    assert math.degrees(math.acos(min(1.0, S.dot(d, line) / S.norm(d)))) < 1.0
    assert abs(S.dot(d, line) - expected) < 0.02 * expected
    for on, n in ((geo['onA'], geo['nA']), (geo['onB'], geo['nB'])):
        for i in on:
            p = moved(wedge, geo['wedge'][i], c0)
            assert abs(S.dot(S.sub(p, geo['origin']), n)) < 1e-3
    weight = yade_dda.block(wedge).mass * G
    RA, RB = S.wedge_reactions(geo['nA'], geo['nB'], weight)
    assert abs(normal_force_between(wedge, slabA) - RA) < 0.02 * RA
    assert abs(normal_force_between(wedge, slabB) - RB) < 0.02 * RB


@pytest.mark.parametrize('name', [n for n in WEDGES if WEDGES[n][-1] > 1])
def test_wedge_with_fs_above_one_stands(scene, name):
    """A wedge with FS = 1.2 or 1.5 stays: it moves less than 1e-4 m in 2 s (elastic settlement ~1e-7 m),
    resting on both planes."""
    geo, fs, slabA, slabB, wedge = build_wedge(name)
    O.engines = [integrator()]
    c0 = centroid(wedge)
    run_to(2.0)
    assert S.norm(S.sub(centroid(wedge), c0)) < 1e-4
    assert S.norm(rotation_vector(wedge)) < 1e-4
    assert normal_force_between(wedge, slabA) > 0 and normal_force_between(wedge, slabB) > 0


def test_frictional_start_up_error_is_the_penalty_springs(scene):
    """Why frictional slides get less accurate as dt shrinks (doc/benchmarks.md, "What accuracy
    costs"; bench/friction_startup.py). A rigid cube at rest on a 30 deg slope with
    20 deg friction, its contacts preloaded with its weight: with a dt that does not
    resolve the shear springs' period it slides as Coulomb friction says to within the
    springs' elasticity (the tipping moment moves normal force from the back corners
    to the front ones, and the tangential springs, which keep their stretch, take up
    the change in their limits elastically: a velocity error of order
    dN / (m omega), which falls faster than 1 / kn); with dt = 1e-5 s it leaves its
    first step too fast, by about F / (m omega), omega = sqrt(4 ks / m), so a 10 times
    stiffer penalty cuts the error by about sqrt(10). The integrator's start from
    rest (startFromRest, the default) removes it: settled with friction locked, the
    shear springs already carry the block's weight, and the error at dt = 1e-5 s is
    a tenth of the preloaded one at most."""
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', '..', '..', 'bench'))
    from friction_startup import velocityError, DURATION, G, SLOPE, FRICTION
    at = G * (math.sin(SLOPE) - math.tan(FRICTION) * math.cos(SLOPE)) * DURATION
    coarse, coarseStiffer = velocityError(1e-3, 40.0), velocityError(1e-3, 400.0)   # as placed, preloaded by hand
    assert abs(coarse) < 1e-3 * at, (coarse, at)
    assert abs(coarseStiffer) < 1e-2 * abs(coarse), (coarseStiffer, coarse)
    resolved, stiffer = velocityError(1e-5, 40.0), velocityError(1e-5, 400.0)
    assert resolved > 1e-5, resolved
    assert 2.5 < resolved / stiffer < 4.5, (resolved, stiffer)
    settled = velocityError(1e-5, 40.0, preloaded=False, startFromRest=True)
    assert abs(settled) < 0.1 * resolved, (settled, resolved)


@pytest.mark.parametrize('small', [1e-2, 1e-3, 1e-4])
def test_tiny_block_resting_on_a_huge_one(scene, small):
    """Scales over up to five decades coupled by closed contacts: a cube of side `small`
    [m] dropped onto a free 10 m block standing on a fixed floor. The two moving blocks
    form one system whose 12x12 blocks differ by (10 / small)^5 in mass; its Cholesky
    factorisation must not fail (it did, on the fuzzer's mixed-scale scenes, while open
    contacts still joined blocks into one system), and the cube must come to rest on
    the big block's top face: no NaN, no sinking beyond the penalty tolerance, not
    thrown off."""
    floor = S.add_block(S.box((-20, -20, -1), (20, 20, 0)), S.rock(30.0), fixed=True)
    big = S.add_block(S.box((-5, -5, 0), (5, 5, 10)), S.rock(30.0))
    cube = S.add_block(S.box((0, 0, 10 + small / 10), (small, small, 10 + small + small / 10)), S.rock(30.0))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(200, True)
    s = yade_dda.stats()
    assert s['largestComponent'] == 2 and s['closedContacts'] >= 8
    top = max(v[2] for v in yade_dda.block(big).vertices)
    bottom = min(v[2] for v in yade_dda.block(cube).vertices)
    weight = S.ROCK['density'] * small ** 3 * G
    kn = 40 * S.ROCK['young'] * small   # contactPenaltyFactor x E x the smaller size
    assert -2 * weight / kn - 1e-9 * 10 <= bottom - top <= 1e-9 * 10, (bottom - top, weight / kn)
    c = yade_dda.block(cube).centroid
    assert abs(c[0] - small / 2) < 1e-3 * small and abs(c[1] - small / 2) < 1e-3 * small, c   # not thrown off
    assert all(math.isfinite(x) for x in yade_dda.block(cube).velocity)
