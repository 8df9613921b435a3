"""The energy account, energy-safe contacts and holding slopes, against
oracles rather than replayed scenes: the account's own conservation law, free-fall
speed bounds, closed forms, and random piles with a printed seed (SI units).

The account (stats()['energy'], World::accountStep) books each term from its own
formula: kinetic 1/2 v^T M v, gravity -m g . c, strain V/2 sigma^T E^-1 sigma, the
contact springs' energy, and, summed over steps, what friction and the time scheme
dissipate and what loads do. Their sum minus the loads, less the energy contact
changes between steps add (contactChanges), is conserved to round-off: a drift is a
bug. Before the contact law was rewritten, a pile of 200 stiff cubes gained up to
36% of its energy (contacts held closed in tension) and slopes with a factor of
safety above 1 crept for ever (springs reset to zero when a slipping contact stuck).
"""
import math
import os
import random

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator
from yade import wrapper

import scenes as S
from helpers import box, rotate

G = 9.81
SEED = int(os.environ.get('YADE_DDA_ENERGY_SEED', '20261125'))


def account(e):
    """The seven terms' sum minus the loads [J] (conserved up to contactChanges)."""
    return e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']


def largest(e, e0):
    """The largest change of any term since e0 [J] (the potential's zero is arbitrary)."""
    return max(abs(e[k] - e0[k]) for k in e)


def pile(n, young, seed, friction=30.0, spacing=1.2, turn=0.1, side=3):
    """n turned 1 m cubes in layers of side x side over a fixed floor (cube k's corner at
    spacing x its grid position, turned by up to `turn` rad about a random axis)."""
    rng = random.Random(seed)
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=math.radians(friction)))
    extent = spacing * side + 2
    O.bodies.append(yade_dda.ddaBlock(box((-2, -2, -1), (extent, extent, 0)), material=rock, fixed=True))
    cubes = []
    for k in range(n):
        i, j, layer = k % side, (k // side) % side, k // (side * side)
        x, y, z = 0.1 + spacing * i, 0.1 + spacing * j, 0.2 + spacing * layer
        pts = rotate(box((x, y, z), (x + 1, y + 1, z + 1)), (rng.random(), rng.random(), rng.random()),
                     rng.uniform(-turn, turn), about=(x + .5, y + .5, z + .5))
        cubes.append(O.bodies.append(yade_dda.ddaBlock(pts, material=rock)))
    return cubes


def translational(cubes):
    """Kinetic (translation) plus potential energy of the cubes [J], and the fastest centroid speed [m/s]."""
    energy, fastest = 0.0, 0.0
    for b in cubes:
        blk = yade_dda.block(b)
        v = blk.velocity
        speed2 = v[0] ** 2 + v[1] ** 2 + v[2] ** 2
        energy += blk.mass * G * blk.centroid[2] + 0.5 * blk.mass * speed2
        fastest = max(fastest, math.sqrt(speed2))
    return energy, fastest


def watch_drop(blocks, until, every):
    """Runs a dropped pile (its engines set, not yet stepped) to `until` s, `every` steps at
    a time, asserting at each sample: no block faster than a fall from the top of the pile
    allows; damping and friction never negative; the account balanced (its sum minus
    loads minus contactChanges) to 1e-3 of the largest change of any term. Returns the
    largest rise of kinetic (translation) plus potential energy over its start (relative)
    and the largest share of contactChanges in that change, with its time."""
    O.run(1, True)
    e0, _ = translational(blocks)
    top = max(yade_dda.block(b).centroid[2] for b in blocks)
    vmax = math.sqrt(2 * G * top)
    a0 = yade_dda.stats()['energy']
    worst, changes = 0.0, []
    while O.time < until:
        O.run(every, True)
        e, fastest = translational(blocks)
        assert math.isfinite(e) and fastest <= vmax, (O.time, fastest, vmax)
        worst = max(worst, (e - e0) / abs(e0))
        a = yade_dda.stats()['energy']
        assert a['damping'] >= 0 and a['friction'] >= 0
        scale = largest(a, a0)
        drift = account(a) - account(a0) - (a['contactChanges'] - a0['contactChanges'])
        assert abs(drift) <= 1e-3 * scale, (O.time, drift, scale)
        changes.append(((a['contactChanges'] - a0['contactChanges']) / scale, O.time))
    share, when = max(changes)
    return worst, share, when


@pytest.mark.parametrize('young', [1e5, 1e11])
def test_dropped_pile_never_gains_energy(scene, young):
    """30 turned cubes dropped onto a floor, every setting at its default. Oracles:
    kinetic plus potential energy never rises above its start by more than 0.1%
    (with the hold-closed rule it rose 5-36% for 200 cubes at 1e11 Pa); no cube is
    faster than a free fall from the top of the pile to the floor allows; the
    energy account balances to 1e-3 of its largest change, at 1e11 Pa (strains of
    1e-6) and at 1e5 Pa, where the cubes strain by 25% and more under their own
    weight (the block's finite-strain terms are exact: BlockEquations.hpp, "Finite
    strain"). Contact changes between steps must add no energy beyond 1e-3 of the
    largest change; at 1e5 Pa they do (0.55% by 0.6 s: the soft penalty springs
    let the cubes overlap by 32 mm, and sub-contacts found between steps start
    compressed), which is reported as an expected failure, not hidden."""
    print('seed', SEED)
    cubes = pile(30, young, SEED, spacing=1.1)
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), label='dda')]
    worst, share, when = watch_drop(cubes, 0.6, 20)
    assert worst <= 1e-3, worst
    if share > 1e-3 and young < 1e9:
        pytest.xfail('contact changes between steps added %.2g of the largest change by t = %.2f s (soft '
                     'penalty, deep overlaps; see the docstring)' % (share, when))
    assert share <= 1e-3, (share, when)


def hull_pile(n, young, seed, friction=30.0, width=3.0):
    """n blocks, each the convex hull of 4 to 12 random points in a 0.8 x 0.8 x 0.7 m box,
    in layers of 3 x 3 over the floor of a fixed open box `width` m wide (walls 3 m high):
    shapes nobody designed, with triangles, short edges and faces at every angle."""
    rng = random.Random(seed)
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=math.radians(friction)))
    W = width
    for lo, hi in [((-.5, -.5, -.5), (W + .5, W + .5, 0)), ((-.5, -.5, 0), (0, W + .5, 3)),
                   ((W, -.5, 0), (W + .5, W + .5, 3)), ((0, -.5, 0), (W, 0, 3)), ((0, W, 0), (W, W + .5, 3))]:
        O.bodies.append(yade_dda.ddaBlock(box(lo, hi), material=rock, fixed=True))
    blocks = []
    for k in range(n):
        c = (0.5 + k % 3, 0.5 + k // 3 % 3, 0.6 + 0.9 * (k // 9))
        pts = [(c[0] + rng.uniform(-.4, .4), c[1] + rng.uniform(-.4, .4), c[2] + rng.uniform(-.35, .35))
               for _ in range(rng.randint(4, 12))]
        blocks.append(O.bodies.append(yade_dda.ddaBlock(pts, material=rock, hull=True)))
    return blocks


@pytest.mark.parametrize('young', [1e9, 1e11])
def test_random_hulls_dropped_into_a_box_keep_the_energy_account(scene, young):
    """27 convex hulls of random points dropped into a fixed box, every setting at its
    default (an unseen scene: the README's own kind of script). Oracles: every hull is
    accepted; no block is faster than a fall from the top of the pile allows; kinetic
    plus potential energy never rises above its start by 0.1%; damping and friction
    never negative; the account balances to 1e-3 of the largest change. Contact changes
    between steps should add no energy beyond 1e-3 of the largest change. They do not
    (bench/energy.py --hulls 8: up to 1.1% of it at 1e9 Pa, 10 to 77% at 1e11
    Pa, seeds 1 to 8, 1 s), mostly from contacts kept from step to step whose next start,
    on the moved geometry, is deeper than the step's linear gap said (an edge-edge gap at
    a small crossing angle is far from linear in the blocks' turns: -10.7 um at the next
    start where the step's model ended at -0.01 um); see doc/benchmarks.md, "Energy of
    random hulls". Reported as an expected failure while it is so, not hidden."""
    print('seed', SEED)
    blocks = hull_pile(27, young, SEED)
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), label='dda')]
    worst, share, when = watch_drop(blocks, 1.0, 25)
    assert worst <= 1e-3, worst
    if share > 1e-3:
        pytest.xfail('contact changes between steps added %.2g of the largest change by t = %.2f s (random '
                     'hulls at %g Pa; see the docstring)' % (share, when, young))


@pytest.mark.slow
@pytest.mark.parametrize('young', [1e5, 1e7, 1e9, 1e11])
def test_pile_of_200_cubes_never_gains_energy(scene, young):
    """200 slightly turned 1 m cubes in 8 layers of 5 x 5 dropped
    onto a fixed floor, every setting at its default: kinetic plus potential energy
    never above its start by more than 0.1%, both with the centroids' kinetic energy
    and with the account's (rotation and strain rates too), and no cube faster than
    a fall from the top of the pile allows (on the earlier contact law one left at
    28.6 m/s with a free-fall bound of 14 m/s, and the energy rose 5-36% at 1e11 Pa).
    Checked every 10 steps until 0.25 s after the last cube has left its free fall
    (vertical speed 1% off g t), at most 1.5 s: every layer lands and the pile takes
    the impacts. And the energy account balances (its sum minus loads and contact
    changes) to 1e-3 of the largest change of any term. At 1e5 Pa seven layers press
    the bottom one with 1.8e5 Pa: the bottom cubes lose over half their volume, so
    this case tests the finite-strain step (BlockEquations.hpp; before it, their
    rates ran away at 1.09 s and the account's kinetic plus potential energy rose
    89%). Measured with bench/energy.py --pile200 (the same pile), see doc/benchmarks.md,
    "Energy of a dropped pile". At 1e9 and 1e11 Pa the contact changes between
    steps must add no more than 1e-3 of the largest change (at 1e5 Pa sub-contacts
    of deeply overlapping soft cubes do add energy: see the 30-cube test). The
    four cases take about 5 minutes."""
    print('seed', SEED)
    cubes = pile(200, young, SEED, side=5)
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), label='dda')]
    O.step()  # O.step() is synchronous; O.run(n, True) waits some 40 ms per call
    e0, _ = translational(cubes)
    a0 = yade_dda.stats()['energy']
    full0 = a0['kinetic'] + a0['gravity']
    top = max(yade_dda.block(b).centroid[2] for b in cubes)
    vmax = math.sqrt(2 * G * top)
    smallest = 1.0
    landed = set()
    end, lastLanding = 1.5, None
    while O.time < end:
        for _ in range(10):
            O.step()
        e, fastest = translational(cubes)
        a = yade_dda.stats()['energy']
        assert e <= e0 * (1 + 1e-3), (O.time, e, e0)
        assert a['kinetic'] + a['gravity'] <= full0 * (1 + 1e-3), (O.time, a, full0)
        assert fastest <= vmax, (O.time, fastest, vmax)
        drift = account(a) - account(a0) - (a['contactChanges'] - a0['contactChanges'])
        assert abs(drift) <= 1e-3 * largest(a, a0), (O.time, drift, largest(a, a0))
        for b in cubes:
            if b not in landed and abs(yade_dda.block(b).velocity[2] + G * O.time) > 0.01 * G * O.time:
                landed.add(b)
                if len(landed) == len(cubes):
                    lastLanding = O.time
                    end = min(end, O.time + 0.25)
        if young >= 1e9:
            # Stiff contacts: detection adds no energy between steps (a corner
            # of a kept entrance face 0.43 mm deep between cubes 1.8 um into
            # each other added 17% of the largest change at 0.28 s, core 90eae68).
            added = a['contactChanges'] - a0['contactChanges']
            assert added <= 1e-3 * largest(a, a0), (O.time, added, largest(a, a0))
    a = yade_dda.stats()['energy']
    print('last landing', lastLanding, 'end %.3f s, %d steps; contact changes %.2g of the largest change' %
          (O.time, O.iter, (a['contactChanges'] - a0['contactChanges']) / largest(a, a0)))


def test_energy_account_balances_on_a_sliding_block(scene):
    """A 1 m cube sliding down a 30 deg incline with 20 deg friction for 1 s: the
    seven terms minus the loads stay constant to 1e-3 of the largest term (friction
    and gravity, several kJ), friction dissipates, and the kinetic energy is the
    closed form's 1/2 m (a t)^2 within 1%."""
    geo, slab, block = S.build_incline(math.radians(30), (1.0, 1.0, 1.0), 20.0)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
    O.run(1, True)
    t0 = O.time
    a0 = yade_dda.stats()['energy']
    O.run(999, True)
    a = yade_dda.stats()['energy']
    assert abs(account(a) - account(a0)) <= 1e-3 * largest(a, a0), (a0, a)
    assert a['friction'] - a0['friction'] > 0.1 * largest(a, a0)
    acc = G * (0.5 - math.tan(math.radians(20)) * math.sqrt(0.75))
    mass = yade_dda.block(block).mass
    assert abs(a['kinetic'] - 0.5 * mass * (acc * O.time) ** 2) < 0.01 * a['kinetic'], (a['kinetic'], O.time, t0)


def cube_on_slope(fs, pushed=False):
    """A 1 m cube on a floor, with gravity tilted 30 deg (a slope) and friction for
    the factor of safety `fs`; or, `pushed`, on a level floor with 30 deg friction
    and a constant horizontal load fs x its friction limit at its centroid."""
    if pushed:
        mu, grav = math.tan(math.radians(30)), (0, 0, -G)
    else:
        mu, grav = fs * math.tan(math.radians(30)), (G * 0.5, 0, -G * math.sqrt(0.75))
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e10, poisson=0.25,
                                                   frictionAngle=math.atan(mu)))
    O.bodies.append(yade_dda.ddaBlock(box((-5, -2, -1), (20, 2, 0)), material=rock, fixed=True))
    loads = [((0.5, 0.0, 0.5), (fs * mu * 2600 * G, 0, 0))] if pushed else []
    cube = O.bodies.append(yade_dda.ddaBlock(box((0, -.5, 0), (1, .5, 1)), material=rock, loads=loads))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=grav, label='dda')]
    return cube


@pytest.mark.parametrize('case', [('slope', 1.02), ('slope', 1.078), ('pushed', 0.95), ('pushed', 0.98)])
def test_block_that_must_hold_does_not_creep(scene, case):
    """A cube on a slope with FS 1.02 and 1.078, and one pushed at 0.95 and 0.98 of its
    friction limit: no steady motion, less than 5 um between 0.5 s and 1 s (it crept
    0.2 mm/s on the slope at FS 1.078 and 0.26 mm/s pushed at 0.95 when a slipping
    contact that stuck again restarted from an unloaded spring)."""
    kind, fs = case
    cube = cube_on_slope(fs, pushed=kind == 'pushed')
    O.run(500, True)
    c1 = yade_dda.block(cube).centroid
    O.run(500, True)
    c2 = yade_dda.block(cube).centroid
    assert S.norm(S.sub(c2, c1)) < 5e-6, (c1, c2)


def wedge_scene(geo, fs, ratio=1.0, dt=2e-3):
    """Two fixed slabs and the free wedge of `geo` (scenes.wedge_geometry's dict), each
    plane's friction set for the factor of safety fs with tan(phi_B)/tan(phi_A) = ratio
    (the wedge's own 60 deg is larger, so each contact takes its plane's), gravity
    along -z, the integrator at dt [s] with 0.02 m of vertex motion per step. Returns
    the wedge's id and the planes' friction angles [rad]."""
    phiA, phiB = S.friction_for_wedge_fs(geo['nA'], geo['nB'], fs, ratio)
    S.add_block(geo['slabA'], S.rock(math.degrees(phiA)), fixed=True)
    S.add_block(geo['slabB'], S.rock(math.degrees(phiB)), fixed=True)
    wedge = S.add_block(geo['wedge'], S.rock(60.0))
    O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.02, label='dda')]
    return wedge, phiA, phiB


def run_until(t):
    """Runs whole steps of the integrator's dt up to time t [s]; fails if a step was cut
    (O.time would miss t)."""
    O.run(int(round((t - O.time) / O.engines[0].dt)), True)
    assert abs(O.time - t) < 1e-9, (O.time, t, yade_dda.stats()['stepCuts'])


def motion_between(body, t1, t2):
    """Centroid [m] of `body` at t1 and at t2 [s]."""
    run_until(t1)
    c1 = yade_dda.block(body).centroid
    run_until(t2)
    return c1, yade_dda.block(body).centroid


@pytest.mark.parametrize('fs', [1.02, 1.078])
@pytest.mark.parametrize('shape', [(35.0, 90.0, 90.0, 0.3, 1.0), (30.0, 100.0, 75.0, 2.0, 1.5)],
                         ids=['symmetric', 'tilted'])
def test_wedge_that_must_hold_does_not_creep(scene, shape, fs):
    """A tetrahedral wedge on two planes (plunge of their line, the planes' angles xi
    and beta, azimuth, tan(phi_B)/tan(phi_A), as test_contact_physics.WEDGES) with
    each plane's friction set for the Hoek-Bray factor of safety fs: no steady
    motion, less than 20 um between 0.5 s and 1 s (the wedge given by dips below crept at
    2.1 mm/s at FS 1.078 on the earlier contact law)."""
    plunge, xi, beta, azimuth, ratio = shape
    geo = S.wedge_geometry(math.radians(plunge), math.radians(xi), math.radians(beta), azimuth=azimuth,
                           origin=(3.0, -2.0, 10.0))
    wedge, _, _ = wedge_scene(geo, fs, ratio)
    c1, c2 = motion_between(wedge, 0.5, 1.0)
    assert S.norm(S.sub(c2, c1)) < 2e-5, (c1, c2)


# A Hoek-Bray wedge given the way rock engineers give it: joint planes A and
# B by dip / dip direction [deg] (clockwise from north = +y; x = east), equal friction.
WEDGE_DIPS = (40.0, 130.0, 60.0, 220.0)
WEDGE_ORIGIN = (3.0, -2.0, 10.0)


def wedge_of_dips(order=WEDGE_DIPS):
    """scenes.wedge_from_dips for planes (dip A, dip direction A, dip B, dip direction B) [deg]."""
    return S.wedge_from_dips(*[math.radians(a) for a in order], origin=WEDGE_ORIGIN)


def outward_normal(face, inside):
    """Unit normal of the plane through the first three corners of `face`, pointing away
    from the point `inside` (a corner of the block the face belongs to)."""
    n = S.unit(S.cross(S.sub(face[1], face[0]), S.sub(face[2], face[0])))
    return S.scale(-1.0, n) if S.dot(S.sub(inside, face[0]), n) > 0 else n


def test_closed_form_wedge_from_dips_is_the_requested_wedge():
    """scenes.wedge_from_dips builds the wedge the dips describe (no DDA).

    For the planes of WEDGE_DIPS (40/130 as A, 60/220 as B, and the other way round) and
    300 random two-plane wedges: the top face of each fixed slab, its normal taken
    from the slab's own corners and pointing out of the slab (up), has the requested
    dip and dip direction to 1e-12 rad; so do the returned nA, nB. The wedge sits ON
    both planes as a Hoek-Bray wedge does: its two lower faces lie in them (1e-12 m),
    its other corners and centroid above both (the valley z > max(z_A, z_B)), both
    slabs below, both reactions compressive, and its lowest corner on the keel, which
    runs downhill along the line of intersection with the stereonet trend and plunge
    (1e-12). Which plane carries more follows from Lami's theorem in the section
    perpendicular to the line: the weight's component there, w, balances R_A n_A and
    R_B n_B, so R_A / R_B = sin(angle(w, n_B)) / sin(angle(w, n_A)), computed from
    angles only (wedge_reactions solves the 2x2 system instead). For that
    wedge the 40 deg plane's normal is 16 deg from w, the 60 deg plane's 51 deg, so
    the gentler plane A carries 2.8 times B's reaction.
    """
    rng = random.Random(SEED)
    cases, refused = [WEDGE_DIPS, WEDGE_DIPS[2:] + WEDGE_DIPS[:2]], 0
    while len(cases) < 302:
        case = (rng.uniform(10, 80), rng.uniform(0, 360), rng.uniform(10, 80), rng.uniform(0, 360))
        if abs(math.sin(math.radians(case[1] - case[3]))) < 0.2:
            continue          # nearly parallel strikes: the line of intersection is nearly horizontal
        nA, nB = S.upward_normal(*map(math.radians, case[:2])), S.upward_normal(*map(math.radians, case[2:]))
        RA, RB = S.wedge_reactions(nA, nB)
        if min(RA, RB) <= 0:    # slides on one plane and leaves the other: refused
            with pytest.raises(ValueError):
                S.wedge_from_dips(*map(math.radians, case))
            refused += 1
        elif min(RA, RB) > 0.05 and S.wedge_line(nA, nB)[1] > math.radians(5):
            cases.append(case)
    assert refused > 0
    for case in cases:
        geo = wedge_of_dips(case)
        want = [math.radians(a) for a in case]
        _, c = S.tetrahedron_volume_centroid(geo['wedge'])
        for key, n, (dip, direction) in (('A', geo['nA'], want[:2]), ('B', geo['nB'], want[2:])):
            slab, top = geo['slab' + key], geo['slab' + key + 'Top']
            face = outward_normal(top, [p for p in slab if p not in top][0])
            for normal in (face, n):
                got = S.dip_and_direction(normal)
                assert abs(got[0] - dip) < 1e-12, (case, key, got)
                assert abs(math.remainder(got[1] - direction, 2 * math.pi)) < 1e-12, (case, key, got)
            assert S.norm(S.sub(face, n)) < 1e-12 and n[2] > 0
            on = geo['on' + key]
            for i, p in enumerate(geo['wedge']):
                d = S.dot(S.sub(p, top[0]), face)
                assert (abs(d) < 1e-12) if i in on else (d > 1e-6), (case, key, i, d)
            assert S.dot(S.sub(c, top[0]), face) > 1e-6
            assert all(S.dot(S.sub(p, top[0]), face) < 1e-12 for p in slab)
        line = geo['line']
        assert min(p[2] for p in geo['wedge']) == geo['wedge'][1][2]          # the keel's lower end
        assert abs(S.dot(S.sub(geo['wedge'][1], geo['wedge'][0]), line) - S.norm(S.sub(geo['wedge'][1],
                                                                                   geo['wedge'][0]))) < 1e-12
        assert abs(S.dot(line, geo['nA'])) < 1e-12 and abs(S.dot(line, geo['nB'])) < 1e-12
        trend, plunge = S.intersection_from_dips(*want)
        assert abs(math.asin(-line[2]) - plunge) < 1e-12
        assert abs(math.remainder(math.atan2(line[0], line[1]) - trend, 2 * math.pi)) < 1e-12
        RA, RB = S.wedge_reactions(geo['nA'], geo['nB'])
        w = S.unit(S.sub((0.0, 0.0, 1.0), S.scale(line[2], line)))   # the reactions balance W along w
        angle = {k: math.acos(S.dot(w, geo[k])) for k in ('nA', 'nB')}
        assert RA > 0 and RB > 0
        assert abs(RA / RB - math.sin(angle['nB']) / math.sin(angle['nA'])) < 1e-10 * RA / RB
        if case == WEDGE_DIPS:
            print('wedge of dips: trend %.3f plunge %.3f xi %.3f beta %.3f deg, R_A %.4f W, R_B %.4f W, '
                  'normals %.2f and %.2f deg from the weight'
                  % tuple([math.degrees(geo[k]) for k in ('trend', 'plunge', 'xi', 'beta')] + [RA, RB]
                          + [math.degrees(angle['nA']), math.degrees(angle['nB'])]))
            assert RA > 2 * RB and angle['nA'] < angle['nB']


@pytest.mark.parametrize('order', ['A=40/130', 'A=60/220'])
def test_closed_form_wedge_of_dips_factor_of_safety_is_hoek_bray(order):
    """The vector FS of the dip-built wedge (scenes.wedge_factor_of_safety: reactions from
    equilibrium perpendicular to the line, friction R tan(phi) against W sin(psi_i))
    equals the textbook Hoek-Bray form FS = sin(beta) / sin(xi/2) tan(phi) / tan(psi_i)
    with the wedge's xi, beta and psi_i to 1e-12 (relative), for friction angles from 10
    to 50 deg; and the friction scenes.friction_for_wedge_fs finds for FS 0.9, 1.02 and
    1.078 (equal on both planes, or tan(phi_B) = 1.5 tan(phi_A)) gives back that FS to
    1e-12 (no DDA)."""
    geo = wedge_of_dips(WEDGE_DIPS if order == 'A=40/130' else WEDGE_DIPS[2:] + WEDGE_DIPS[:2])
    nA, nB = geo['nA'], geo['nB']
    for phiDeg in range(10, 51, 5):
        phi = math.radians(phiDeg)
        vector = S.wedge_factor_of_safety(nA, nB, phi, phi)
        textbook = S.hoek_bray_factor_of_safety(geo['xi'], geo['beta'], geo['plunge'], phi)
        assert abs(vector - textbook) < 1e-12 * textbook, (phiDeg, vector, textbook)
    for fs in (0.9, 1.02, 1.078):
        for ratio in (1.0, 1.5):
            phiA, phiB = S.friction_for_wedge_fs(nA, nB, fs, ratio)
            assert abs(math.tan(phiB) - ratio * math.tan(phiA)) < 1e-12
            assert abs(S.wedge_factor_of_safety(nA, nB, phiA, phiB) - fs) < 1e-12 * fs
            if ratio == 1.0:
                assert abs(S.hoek_bray_factor_of_safety(geo['xi'], geo['beta'], geo['plunge'], phiA) - fs) < 1e-12
    print('wedge of dips: phi = %.4f deg for FS 1.078' % math.degrees(S.friction_for_wedge_fs(nA, nB, 1.078)[0]))


@pytest.mark.parametrize('fs', [1.02, 1.078])
def test_wedge_given_by_dips_holds(scene, fs):
    """The wedge of WEDGE_DIPS (planes 40/130 and 60/220, built from the dips by
    scenes.wedge_from_dips) with equal friction on both planes for the Hoek-Bray
    factor of safety fs: no steady motion, less than 20 um of centroid motion between
    0.5 s and 1 s (on the earlier contact law it slid 2.1 mm/s at FS 1.078)."""
    geo = wedge_of_dips()
    wedge, phiA, phiB = wedge_scene(geo, fs)
    c1, c2 = motion_between(wedge, 0.5, 1.0)
    moved = S.norm(S.sub(c2, c1))
    print('FS %.3f (phi %.3f deg): %.3g m between 0.5 s and 1 s, %.3g m since the start'
          % (S.wedge_factor_of_safety(geo['nA'], geo['nB'], phiA, phiB), math.degrees(phiA), moved,
             S.norm(S.sub(c2, S.tetrahedron_volume_centroid(geo['wedge'])[1]))))
    assert moved < 2e-5, (c1, c2)


@pytest.mark.parametrize('dt', [2e-3, 1e-3])
def test_wedge_given_by_dips_below_fs_one_slides_as_coulomb_says(scene, dt):
    """The same wedge at FS 0.9 slides (so the hold test above can fail), as a rigid
    wedge sliding down the line of intersection l with Coulomb friction on both planes:
    perpendicular to l nothing accelerates, which gives the reactions R_A, R_B
    (scenes.wedge_reactions), and along l
        a = g (sin psi_i - (R_A tan phi_A + R_B tan phi_B) / W)   (0.591 m/s^2),
    so between t1 = 0.3 s and t2 = 0.8 s the centroid moves a (t2^2 - t1^2) / 2 along l
    (0.163 m), its velocity along l grows by a (t2 - t1), and it moves nothing across l.

    Measured (this wedge: 2 m keel, 1 m arms, E = 1e10 Pa): the displacement is
    0.028% too large at dt 2e-3 s and 0.049% at 1e-3 s (0.094% at 1e-4 s). The
    excess is a velocity gained in the first 20 ms, while the unloaded contacts take
    up the weight (9e-5 m/s at dt 2e-3 s, 1.6e-4 m/s at 1e-3 s); from 0.3 s to 0.8 s
    the acceleration is a within 3e-6 (relative). The test allows 0.5% on the
    displacement, ten times the worst measured; since the displacement changes by
    FS / (1 - FS) = 9 times a relative error in tan(phi), that still catches friction
    0.06% off. The velocity gain is held to 0.05%, the motion across l to 1e-3 of the
    slide.
    """
    geo = wedge_of_dips()
    wedge, phiA, phiB = wedge_scene(geo, 0.9, dt=dt)
    RA, RB = S.wedge_reactions(geo['nA'], geo['nB'])
    acc = G * (math.sin(geo['plunge']) - (RA * math.tan(phiA) + RB * math.tan(phiB)))
    line = geo['line']
    at = {}
    for t in (0.3, 0.8):
        run_until(t)
        blk = yade_dda.block(wedge)
        at[t] = (blk.centroid, S.dot(tuple(blk.velocity), line))
    (c1, v1), (c2, v2) = at[0.3], at[0.8]
    d = S.sub(c2, c1)
    along = S.dot(d, line)
    across = S.norm(S.sub(d, S.scale(along, line)))
    expected = acc * (0.8 ** 2 - 0.3 ** 2) / 2
    stats = yade_dda.stats()
    print('FS %.3f, dt %g s: %.6f m along the line (closed form %.6f m, error %+.3f%%), velocity gain %+.2e '
          'relative, %.2g m across; %d step cuts, %d contacts, %d sliding'
          % (S.wedge_factor_of_safety(geo['nA'], geo['nB'], phiA, phiB), dt, along, expected,
             100 * (along - expected) / expected, (v2 - v1) / (acc * 0.5) - 1, across, stats['stepCuts'],
             stats['contacts'], stats['slidingContacts']))
    assert abs(along - expected) < 5e-3 * expected
    assert abs((v2 - v1) - acc * 0.5) < 5e-4 * acc * 0.5
    assert across < 1e-3 * expected


@pytest.mark.parametrize('zeta', [0.0, 0.5], ids=['undamped', 'viscous'])
@pytest.mark.parametrize('scheme', [(0.5, 1.0), (0.25, 0.5)])
def test_energy_account_is_exact_for_a_block_vibrating_at_finite_strain(scene, scheme, zeta):
    """A free deformable block released from a random initial stress up to 0.3 E
    (strains of 30%, volume swinging by 15-20% without strain viscosity) and spun at
    a random rate, no gravity and no contacts, 1000 steps under Shi's scheme and under
    average acceleration, without and with strain viscosity (strainDamping 0.5).
    Oracle: the account's sum (kinetic + strain + damping) stays its start value to
    1e-10 of the largest term: the step changes the strain energy V0/2 tau E^-1 tau
    by exactly the elastic work, the viscosity's work is booked as damping, and the
    rates' kinetic energy carries over to the moved block exactly (BlockEquations.hpp,
    "Finite strain"). Before, the account drifted by up to 44% of the strain energy
    here."""
    rng = random.Random(SEED + 17)
    print('seed', SEED + 17)
    mat = O.materials.append(wrapper.PolyhedraMat(density=1000, young=1e6, poisson=0.3))
    stress = [rng.uniform(-3e5, 3e5) for _ in range(6)]
    pts = rotate(box((0, 0, 0), (1, 0.7, 0.5)), (rng.random(), rng.random(), rng.random()), rng.uniform(0, 3))
    b = O.bodies.append(yade_dda.ddaBlock(pts, material=mat, stress=stress))
    yade_dda.setVelocity(b, (0, 0, 0), [rng.uniform(-3, 3) for _ in range(3)])
    beta, gamma = scheme
    O.engines = [DDAIntegrator(gravity=(0, 0, 0), dt=1e-3, newmarkBeta=beta, newmarkGamma=gamma, strainDamping=zeta)]
    O.step()
    a0 = yade_dda.stats()['energy']
    volumes, biggest, worst = [], 0.0, 0.0
    for _ in range(1000):
        O.step()
        a = yade_dda.stats()['energy']
        volumes.append(yade_dda.block(b).volume)
        biggest = max(biggest, a['strain'], a['kinetic'])
        worst = max(worst, abs(account(a) - account(a0)))
    assert max(volumes) - min(volumes) > (0.1 if zeta == 0 else 0.02) * 0.35, (min(volumes), max(volumes))  # finite strain indeed
    assert worst <= 1e-10 * biggest, (worst, biggest)


def _prestressed_soft_block(cuts):
    """A free 1 m cube with E = 1 kPa released from a tensile stress of 10 kPa in every
    direction, no gravity, dt = 1 s and no displacement control: unchecked, its first
    step's strain increment (about -4 per axis) would turn it inside out."""
    mat = O.materials.append(wrapper.PolyhedraMat(density=1000, young=1e3, poisson=0.25))
    b = O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=mat, stress=(1e4, 1e4, 1e4, 0, 0, 0)))
    O.engines = [DDAIntegrator(gravity=(0, 0, 0), dt=1.0, maxDisplacement=1e9, maxStepCuts=cuts)]
    return b


def test_no_step_turns_a_block_inside_out(scene):
    """Oracle: a step shrinks no deformable block below half its volume (World::solveStep
    cuts dt until det(I + S) >= 0.5), so the volume stays positive however the block is
    loaded, and the energy account stays exact while it shrinks (Hencky's law: the
    stored energy grows without bound as the volume goes to zero)."""
    b = _prestressed_soft_block(5)
    volume = yade_dda.block(b).volume
    O.step()
    cut = yade_dda.stats()['stepCuts']
    v = yade_dda.block(b).volume
    assert 0 < v and v >= 0.5 * volume * (1 - 1e-12), (O.iter, v, volume)
    volume = v
    a0 = yade_dda.stats()['energy']
    for _ in range(20):
        O.step()
        cut += yade_dda.stats()['stepCuts']
        v = yade_dda.block(b).volume
        assert 0 < v and v >= 0.5 * volume * (1 - 1e-12), (O.iter, v, volume)
        volume = v
        a = yade_dda.stats()['energy']
        assert abs(account(a) - account(a0)) <= 1e-9 * max(a['strain'], a['kinetic']), (a, a0)
    assert cut > 0


def test_a_step_that_would_turn_a_block_inside_out_is_refused_by_name(scene):
    """With no step cuts allowed, the same step is refused with an error naming the block
    and the volume ratio, and the block is left as it was."""
    b = _prestressed_soft_block(0)
    before = yade_dda.block(b).vertices
    with pytest.raises(RuntimeError, match=r'shrink block 0 to .* of its volume'):
        O.step()
    assert yade_dda.block(b).vertices == before
