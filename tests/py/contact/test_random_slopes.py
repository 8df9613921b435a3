"""Random convex prisms on random inclines, against closed forms and the energy account
(scenes nobody designed; random_slopes.py draws them, seeded, the seed in every message).

Each case (random_slopes.draw_case) is a fixed slab whose top face dips at theta (10 to
35 deg) towards a random azimuth, and on it a free prism: a random convex footprint of
5 to 9 corners (slivers refused), a random spin about the incline's normal, a height
that keeps it from toppling, its bottom face exactly on the slab's top face. The
contact's friction angle phi sets the factor of safety FS = tan(phi) / tan(theta); phi
is the smaller of the two materials' angles, the slab's or the prism's at random.
Every setting of DDAIntegrator is at its default (start from rest included) except
dt = 1e-3 s, gravity and 0.02 m of allowed step displacement.

Oracles, per case, over 1 s:

- FS in 1.25..2.0 ('hold'): the prism does not creep. Its centroid moves less than
  random_slopes.settlement_bound (the contact springs' compression and stretch as if
  one spring carried the whole weight, the tilt that follows, and the block's own
  uniform strain under the contact forces' first moment: closed forms of the drawn
  geometry, 1e-6 m-ish); between 0.5 s and 1 s it moves less than that bound too, and
  its speed at 1 s is below the bound over 0.5 s (a steady creep at that speed would
  exceed the bound in the last half second); the contact forces on it balance its
  weight (1e-3 of m g).
- FS in 0.2..0.8 ('slide'): the prism slides down the dip direction with
  a = g (sin theta - tan(phi) cos theta): the velocity gain along the dip from 0.3 s to
  1 s is a x 0.7 s within 1e-3, the displacement a t^2 / 2 within 1e-3; across the
  dip and along the normal it moves less than the settlement bound (a translating block
  feels no moment: the contact force passes through the centroid); every closed contact
  is sliding (every
  point of the base slips at the block's velocity); the normal forces sum to
  m g cos(theta) and the friction to tan(phi) times that (1e-3 of m g); friction
  dissipates tan(phi) m g cos(theta) x the distance slid (1e-3), and the kinetic
  energy is m (a t)^2 / 2 (1e-3).
- Both: it tilts by no more than the settlement bound over the footprint's narrowest
  width, and spins about the normal by no more than the stored elastic energy allows
  (check_rotation). The energy account (stats()['energy']) balances: its terms' change minus the
  loads, less what contact changes between steps add (contactChanges), stays within
  1e-6 of the scale (the largest change of any term, or, at rest, where the settling
  happened in the first step, m g times the settlement bound) plus the round-off of
  the gaps (4 ulps of the scene's coordinates times the weight, per step); contactChanges adds no
  more than 1e-3 of that scale; friction never negative; kinetic plus potential energy
  never above its value after the first step (by 1e-3 of the scale).

The tolerances are not fitted to DDA: 1e-3 on a constant acceleration is far above
what an exact-for-constant-acceleration scheme with stiff penalty springs leaves and
far below what a wrong friction law gives (a 1% error in tan(phi) changes a by
FS / (1 - FS) %, at least 0.25 %). Default run: SEEDS (two regimes each) and FOUND, the
three seeds the sweep found failing (10 s idle, 25 s on the loaded machine); `-m slow`
sweeps SLOW_SEEDS (about 3 minutes).

What the sweep found. Held prisms rang after a start-up lurch (seeds 11, 33): start from
rest left shear springs beyond Coulomb's limit (ringing_at_rest says how), fixed by letting
the settling end with the true friction (World::admitFriction). One slide stalled (seed 51):
a step accepted with its friction limits unsettled tipped the prism into rocking
(stalled_slide); fixed by ending such limits Coulomb-safe (OpenClose.cpp, closePasses). A
slide that misses its closed form this way is still an expected failure, recognised by its
mechanism and reported with its numbers, not by its seed. And 14 of the 132 prisms were not settled at
all: laid exactly flush, every corner's gap came out +1e-16 to +1e-15 m (round-off), not
touching; fixed (Settling.cpp, flushGap).
"""
import math

import numpy as np
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator

import random_slopes as R

SEEDS = range(1, 7)
SLOW_SEEDS = range(7, 67)
FOUND = [('hold', 11), ('hold', 33), ('slide', 51)]    # SLOW_SEEDS the sweep found failing (test_cases_the_sweep_found)
DT = 1e-3
SAMPLES = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)   # times [s] the run stops to check


def account(e):
    """The account's terms' sum minus the loads [J] (conserved up to contactChanges)."""
    return e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']


def force_on(body):
    """Total contact force [N] on `body` from the closed contacts (a contact's forces act on id1,
    its normal points from id2 to id1)."""
    total = np.zeros(3)
    for c in yade_dda.contacts('closed'):
        if body in (c.id1, c.id2):
            f = np.array(c.normal) * c.normalForce + np.array(c.shearForce)
            total += f if c.id1 == body else -f
    return total


def run_to(t):
    """Runs whole steps of DT up to time t [s], the last one trimmed; step cuts (the integrator's
    adaptive dt) only add steps. Returns the number of steps beyond round(t / DT)."""
    dda = O.engines[0]
    n = int(math.floor((t - O.time) / DT + 1e-9))
    if n > 0:
        O.run(n, True)
    while O.time < t - 1e-12:
        dda.dt = min(DT, t - O.time)
        O.run(1, True)
    dda.dt = DT
    return O.iter - int(round(t / DT))


def spin_inertia(prism, normal):
    """Moment of inertia [kg m^2] of the prism about the incline's normal through its centroid,
    rho (tr J - n^T J n) with J its second moment of volume."""
    blk = yade_dda.block(prism)
    J = np.array([[blk.secondMoment[i][j] for j in range(3)] for i in range(3)])
    return blk.mass / blk.volume * (np.trace(J) - normal @ J @ normal)


def run_case(case):
    """Builds the case, runs it to 1 s stopping at SAMPLES, and returns what the oracles need:
    the prism's centroid, velocity (translation) and rotation vector at each sample (c0 at the
    start, c1 after the first step), the account after the first step and at each sample, the
    largest rise of kinetic plus potential energy over its value after the first step, the
    prism's mass and spin inertia, and the extra steps step cuts took."""
    slab, prism = R.build(case)
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -R.G), maxDisplacement=0.02, label='dda')]
    blk = yade_dda.block(prism)
    c0 = np.array(blk.centroid)
    O.run(1, True)

    def mechanical():
        v = np.array(blk.velocity[0:3])
        return blk.mass * R.G * blk.centroid[2] + 0.5 * blk.mass * v @ v

    e1, a1 = mechanical(), dict(yade_dda.stats()['energy'])
    first = [c for c in yade_dda.contacts('closed') if prism in (c.id1, c.id2)]
    firstStep = dict(speed=np.linalg.norm(blk.velocity[0:3]), closed=len(first),
                     sliding=sum(1 for c in first if c.state == 'sliding'))
    out = dict(prism=prism, slab=slab, mass=blk.mass, c0=c0, c1=np.array(blk.centroid), a1=a1, at={}, rise=0.0,
               frictionMin=0.0, spinInertia=spin_inertia(prism, case['frame'][2]), firstStep=firstStep)
    for t in SAMPLES:
        out['extraSteps'] = run_to(t)
        a = dict(yade_dda.stats()['energy'])
        out['at'][t] = dict(c=np.array(blk.centroid), v=np.array(blk.velocity[0:3]),
                            rot=np.array(blk.rotation.toRotationVector()), energy=a)
        out['rise'] = max(out['rise'], mechanical() - e1)
        out['frictionMin'] = min(out['frictionMin'], a['friction'] - a1['friction'])
    out['force'] = force_on(prism)
    out['states'] = sorted(c.state for c in yade_dda.contacts() if prism in (c.id1, c.id2))
    return out


def check_rotation(case, run):
    """Tilt and spin of the prism at 1 s; asserts both within their bounds and returns them.

    Tilt (the rotation about in-plane axes): the base is a plane on springs that sink by at most
    the settlement bound, so it turns by at most that over the narrowest width. Spin (about the
    normal): a rigid block feels no moment about it (the friction forces are parallel), but a
    deformable one whose base expands by Poisson's ratio under its weight does while its
    friction turns from restraining that expansion to opposing the slide; its spin's kinetic
    energy I_n w^2 / 2 can come from no more than the elastic energy (contact springs and
    strain) the account held after the first step, so |w| <= sqrt(2 E / I_n) and the spin
    after 1 s is at most that times 1 s.
    """
    normal = case['frame'][2]
    rot = run['at'][1.0]['rot']
    spin = abs(rot @ normal)
    tilt = np.linalg.norm(rot - (rot @ normal) * normal)
    elastic = run['a1']['contact'] + run['a1']['strain']
    spinBound = math.sqrt(2 * elastic / run['spinInertia']) * 1.0
    tiltBound = R.settlement_bound(case) / R.polygon_shape(case['footprint'])[3]
    where = R.describe(case)
    assert tilt < tiltBound, (where, 'tilted', tilt, tiltBound)
    assert spin < spinBound, (where, 'spun', spin, spinBound)
    return tilt, tiltBound, spin, spinBound


def energy_report(case, run, scale):
    """(drift, added) [J]: the account's imbalance and what contact changes added since the first step;
    asserts both within their share of `scale` (module docstring), friction never negative and no
    rise of kinetic plus potential energy."""
    a1, a = run['a1'], run['at'][SAMPLES[-1]]['energy']
    added = a['contactChanges'] - a1['contactChanges']
    drift = account(a) - account(a1) - added
    where = R.describe(case)
    # Round-off: each step's gaps are differences of coordinates as large as the scene's
    # (|x| up to ~15 m), a few ulps of |x| each, times the contact forces (about the weight):
    # at rest that is nearly all the account sees (the imbalance is then -contactChanges).
    reach = max(np.abs(np.array(case['slab'])).max(), np.abs(np.array(case['prism'])).max())
    roundOff = 4 * O.iter * run['mass'] * R.G * np.finfo(float).eps * reach
    assert abs(drift) <= 1e-6 * scale + roundOff, (where, 'account imbalance', drift, scale, roundOff)
    assert added <= 1e-3 * scale, (where, 'contact changes added energy', added, scale)
    assert run['frictionMin'] >= 0, (where, 'friction negative', run['frictionMin'])
    assert run['rise'] <= 1e-3 * scale, (where, 'kinetic + potential rose', run['rise'], scale)
    return drift, added, roundOff


def check_hold(case, run):
    """The oracles of a case with FS >= 1.25 (module docstring); returns the printed numbers."""
    where = R.describe(case)
    bound = R.settlement_bound(case)
    end, half = run['at'][1.0], run['at'][0.5]
    moved = np.linalg.norm(end['c'] - run['c0'])
    late = np.linalg.norm(end['c'] - half['c'])
    weight = run['mass'] * R.G
    assert moved < bound, (where, 'moved', moved, 'bound', bound)
    assert late < bound, (where, 'creeps', late, bound)
    tilt, tiltBound, spin, spinBound = check_rotation(case, run)
    assert np.linalg.norm(run['force'] - np.array([0, 0, weight])) < 1e-3 * weight, (where, run['force'], weight)
    a1, a = run['a1'], end['energy']
    scale = max(max(abs(a[k] - a1[k]) for k in a), weight * bound)
    drift, added, roundOff = energy_report(case, run, scale)
    speed = np.linalg.norm(end['v'])
    if speed >= bound / 0.5:
        ringing_at_rest(case, run, speed, bound, late)
    return ('%s\n  moved %.3g m (bound %.3g m), %.3g m from 0.5 s to 1 s, speed %.2g m/s (bound %.2g), tilt %.2g rad '
            '(bound %.2g), spin %.2g rad (bound %.2g); account imbalance %.2g J, contact changes %.2g J (scale %.3g '
            'J, round-off allowance %.2g J); first step %d of %d closed contacts sliding; contacts at 1 s %s'
            % (where, moved, bound, late, speed, bound / 0.5, tilt, tiltBound, spin, spinBound, drift, added, scale,
               roundOff,
               run['firstStep']['sliding'], run['firstStep']['closed'], states_summary(run)))


def ringing_at_rest(case, run, speed, bound, late):
    """A held prism whose speed at 1 s exceeds bound / 0.5 s fails, with what tells its cause.

    Found by this sweep (seeds 11 and 33) and fixed in World::admitFriction: start from rest
    settled the prism with friction locked, and the locked shear springs held its deformable
    base's Poisson spread back with forces beyond Coulomb's limit (seed 11: radial forces of
    175 to 330 N at corners whose limit tan(phi) N is 121 to 489 N), so the first dynamic step
    slipped every corner and the prism lurched (8e-5 m/s); the contacts locked again, but Shi's
    scheme kept a velocity flipping sign every step (v_{n+1} = 2 d / dt - v_n with d ~ 0): still
    3.07e-6 m/s at 1 s while the centroid moved 1.5e-12 m from 0.5 s to 1 s. The message says
    whether the velocity flips in the next step and how many contacts slid in the first one.
    """
    blk = yade_dda.block(run['prism'])
    v0 = np.array(blk.velocity[0:3])
    O.run(1, True)
    v1 = np.array(blk.velocity[0:3])
    first = run['firstStep']
    pytest.fail('%s: speed %.3g m/s at 1 s > settlement bound / 0.5 s = %.3g m/s; the centroid moved %.3g m from '
                '0.5 s to 1 s; the velocity %s in the next step (%.3g m/s); in the first step %d of %d closed '
                'contacts slid and the speed became %.3g m/s'
                % (R.describe(case), speed, bound / 0.5, late, 'reverses' if v0 @ v1 < 0 else 'does not reverse',
                   np.linalg.norm(v1), first['sliding'], first['closed'], first['speed']))


def states_summary(run):
    return ', '.join('%d %s' % (run['states'].count(s), s) for s in sorted(set(run['states'])))


def first_unsettled_step(case):
    """Runs the case again step by step to 1 s and returns (step, time, open-close iterations, the
    largest |shear force| / (tan(phi) N) of its closed contacts, states, earlier unsettled steps) at
    the first step the open-close iteration accepted with its friction limits unsettled
    (stats()['limitsUnsettled']) and a closed contact's friction more than 10% off its limit
    tan(phi) N, or None."""
    O.reset()
    slab, prism = R.build(case)
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -R.G), maxDisplacement=0.02, label='dda')]
    mu = math.tan(case['phi'])
    earlier = 0
    while O.time < 1.0 - 1e-9:
        O.step()
        s = yade_dda.stats()
        if s['limitsUnsettled']:
            closed = [c for c in yade_dda.contacts('closed') if c.normalForce > 0]
            ratio = max(np.linalg.norm(c.shearForce) / (mu * c.normalForce) for c in closed)
            if ratio > 1.1:
                states = ''.join(c.state[0] for c in yade_dda.contacts())
                return O.iter, O.time, s['openCloseIterations'], ratio, states, earlier
            earlier += 1
    return None


def stalled_slide(case, what, measured, expected):
    """A sliding prism whose acceleration or distance misses the closed form fails, unless it is
    the diagnosed stall (then an expected failure, with the numbers):

    From some step the open-close iteration's friction limits do not settle: the normal forces
    shift between the corners pass after pass (friction at the base tips the prism, which moves
    the normal force downhill, which raises those corners' limits) and, three quarters of
    maxOpenCloseIterations spent, the step is accepted with its limits unsettled (OpenClose.cpp,
    closePasses: energy-safe, every limit >= 0 dissipates). Measured, seed 51 (FS 0.673): step 11
    accepted after 32 solves with a sliding corner at 2.66 tan(phi) N; the excess friction tips
    the prism (angular speed from 1e-5 to 5e-3 rad/s), its uphill corners lift, and it rocks and
    chatters from then on: 7.8 mm slid in 1 s instead of 641 mm; at dt = 2e-4 s it slides the
    closed form's distance to 2e-4. Since such limits end Coulomb-safe (closePasses) a dynamic
    step no longer counts limitsUnsettled, so a miss fails; seed 51 slides within 1e-3.
    """
    found = first_unsettled_step(case)
    message = ('%s: %s %.6g, closed form %.6g (%+.2e)' % (R.describe(case), what, measured, expected,
                                                           measured / expected - 1))
    if found is None:
        pytest.fail(message + '; no step had friction limits unsettled by more than 10%')
    step, t, iterations, ratio, states, earlier = found
    pytest.xfail(message + '; step %d (t = %.3f s) was accepted after %d open-close solves with its friction limits '
                 'unsettled, a closed contact at %.2f x tan(phi) N (states %s; %d earlier steps unsettled by less); '
                 'see stalled_slide' % (step, t, iterations, ratio, states, earlier))


def check_slide(case, run):
    """The oracles of a case with FS <= 0.8 (module docstring); returns the printed numbers."""
    where = R.describe(case)
    downhill, across, normal = case['frame']
    acc = R.sliding_acceleration(case)
    bound = R.settlement_bound(case)
    start, end = run['at'][0.3], run['at'][1.0]
    gain = (end['v'] - start['v']) @ downhill
    d = end['c'] - run['c0']
    along, expected = d @ downhill, acc * 1.0 ** 2 / 2
    if abs(gain - acc * 0.7) >= 1e-3 * acc * 0.7:
        stalled_slide(case, 'acceleration from 0.3 s to 1 s', gain / 0.7, acc)
    if abs(along - expected) >= 1e-3 * expected:
        stalled_slide(case, 'distance slid in 1 s', along, expected)
    assert abs(d @ across) < bound and abs(d @ normal) < bound, (where, 'off the dip', d @ across, d @ normal, bound)
    tilt, tiltBound, spin, spinBound = check_rotation(case, run)
    assert 'locked' not in run['states'] and 'sliding' in run['states'], (where, run['states'])
    weight = run['mass'] * R.G
    N, friction = run['force'] @ normal, -run['force'] @ downhill
    assert abs(N - weight * math.cos(case['theta'])) < 1e-3 * weight, (where, 'normal force', N)
    assert abs(friction - math.tan(case['phi']) * N) < 1e-3 * weight, (where, 'friction', friction, N)
    a1, a = run['a1'], end['energy']
    slid = (end['c'] - run['c1']) @ downhill      # since the first step, as the account's a1
    dissipated = a['friction'] - a1['friction']
    closedForm = math.tan(case['phi']) * weight * math.cos(case['theta']) * slid
    assert abs(dissipated - closedForm) < 1e-3 * closedForm, (where, 'friction work', dissipated, closedForm)
    kinetic = 0.5 * run['mass'] * (acc * 1.0) ** 2
    assert abs(a['kinetic'] - kinetic) < 1e-3 * kinetic, (where, 'kinetic', a['kinetic'], kinetic)
    scale = max(abs(a[k] - a1[k]) for k in a)
    drift, added, _ = energy_report(case, run, scale)
    return ('%s\n  acceleration %.6f m/s^2 (closed form %.6f, %+.2e), slid %.5f m (%+.2e), across %.2g m, '
            'normal %.2g m (bound %.2g), tilt %.2g rad (bound %.2g), spin %.2g rad (bound %.2g); friction work '
            '%+.2e of the closed form; account imbalance %.2g J, contact changes %.2g J (scale %.4g J); %d extra '
            'steps from cuts; contacts %s'
            % (where, gain / 0.7, acc, gain / 0.7 / acc - 1, along, along / expected - 1, d @ across, d @ normal,
               bound, tilt, tiltBound, spin, spinBound, dissipated / closedForm - 1, drift, added, scale,
               run['extraSteps'], states_summary(run)))


def check(regime, seed):
    case = R.draw_case(seed, regime)
    run = run_case(case)
    print((check_hold if regime == 'hold' else check_slide)(case, run))


# ================================================================ the generator (no DDA)

@pytest.mark.parametrize('seed', list(SEEDS) + list(SLOW_SEEDS))
def test_generator_draws_valid_scenes(seed):
    """Each drawn case is what the module docstring says, checked from its corners (no DDA):
    the prism's bottom corners lie on the plane of the slab's top corners (1e-12 m), its top
    corners h above it; the footprint is convex with 5..9 corners, no slivers; the gravity line
    through the centroid meets the base inside it with the margin; the slab's top face holds the
    footprint and the longest slide; the friction angles give the drawn FS in its range and the
    smaller one is the contact's; the same seed draws the same case."""
    for regime in ('hold', 'slide'):
        case = R.draw_case(seed, regime)
        where = R.describe(case)
        downhill, across, normal = case['frame']
        slab, prism, k = np.array(case['slab']), np.array(case['prism']), len(case['footprint'])
        top = slab[[i for i in range(8) if i & 4]]
        n = np.cross(top[1] - top[0], top[2] - top[0])
        n /= np.linalg.norm(n)
        assert abs(abs(n @ normal) - 1) < 1e-12, where
        heights = (prism - top[0]) @ normal
        assert np.abs(heights[:k]).max() < 1e-12 and np.abs(heights[k:] - case['height']).max() < 1e-12, where
        poly = case['footprint']
        hull = R.convex_hull_2d([tuple(p) for p in poly])     # every corner on it, counter-clockwise
        assert 5 <= k <= 9 and hull == [(hull[0] + i) % k for i in range(k)], where
        diameter, shortest, turn, width = R.polygon_shape(poly)
        assert shortest >= R.MIN_EDGE * diameter and turn >= math.radians(R.MIN_TURN_DEG) - 1e-12, where
        assert width >= R.MIN_WIDTH * diameter, where
        assert np.abs(R.polygon_area_centroid(poly)[1]).max() < 1e-12, where
        foot = np.array([case['height'] / 2 * math.tan(case['theta']), 0.0])
        assert R.inside_distance(poly, foot) >= R.TOPPLE_MARGIN * width - 1e-12, where
        assert R.MIN_HEIGHT <= case['height'] <= R.MAX_HEIGHT, where
        slabX, slabY = (top - case['origin']) @ downhill, (top - case['origin']) @ across
        room = slabX.max() - np.abs(poly[:, 0]).max() - R.G * math.sin(case['theta']) / 2
        assert slabX.min() < -np.abs(poly).max() and room >= 1.0 - 1e-9, where
        assert slabY.min() < -np.abs(poly[:, 1]).max() and slabY.max() > np.abs(poly[:, 1]).max(), where
        assert abs(math.tan(min(case['phiSlab'], case['phiPrism'])) / math.tan(case['theta']) - case['fs']) < 1e-12
        assert R.FS_RANGE[regime][0] <= case['fs'] <= R.FS_RANGE[regime][1], where
        again = R.draw_case(seed, regime)
        assert again['prism'] == case['prism'] and again['phi'] == case['phi'], where


def test_closed_forms_of_the_generator():
    """The sliding acceleration is g cos(theta) tan(theta) (1 - FS) (negative when it holds); a
    footprint's centroid and inside distance on a unit square; the tallest prism on a square
    of side b at slope theta is (b/2 - margin) 2 / tan(theta) (the gravity line reaching the
    downhill edge less the margin)."""
    for seed in SEEDS:
        for regime in ('hold', 'slide'):
            case = R.draw_case(seed, regime)
            expected = R.G * math.cos(case['theta']) * math.tan(case['theta']) * (1 - case['fs'])
            assert abs(R.sliding_acceleration(case) - expected) < 1e-12 * R.G
            assert (R.sliding_acceleration(case) > 0) == (regime == 'slide')
    square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    area, centroid = R.polygon_area_centroid(square + [2.0, 3.0])
    assert abs(area - 1) < 1e-15 and np.abs(centroid - [2.0, 3.0]).max() < 1e-15
    assert abs(R.inside_distance(square, np.array([0.3, 0.1])) - 0.2) < 1e-15
    theta = math.radians(30)
    expected = 2 * (0.5 - R.TOPPLE_MARGIN * 1.0) / math.tan(theta)
    assert abs(R.largest_height(square, theta) - expected) < 1e-12


# ================================================================ DDA

@pytest.mark.parametrize('seed', SEEDS)
@pytest.mark.parametrize('regime', ['hold', 'slide'])
def test_random_prism_on_random_incline(scene, regime, seed):
    """A random prism with FS >= 1.25 holds, with FS <= 0.8 slides at Coulomb's rate, the energy
    account balanced (module docstring)."""
    check(regime, seed)


@pytest.mark.parametrize('regime,seed', FOUND)
def test_cases_the_sweep_found(scene, regime, seed):
    """The sweep's seeds that failed, run by default so what they found stays found: a held
    prism that rang after a start-up lurch (hold 11, 33; fixed in World::admitFriction,
    ringing_at_rest says what it looked like) and the slide stalled by a step accepted with
    its friction limits unsettled (slide 51; fixed by the Coulomb-safe passes of
    OpenClose.cpp, closePasses; stalled_slide says what it looked like)."""
    check(regime, seed)


@pytest.mark.slow
@pytest.mark.parametrize('seed', SLOW_SEEDS)
@pytest.mark.parametrize('regime', ['hold', 'slide'])
def test_random_prism_on_random_incline_sweep(scene, regime, seed):
    """The same oracles on 60 more seeds per regime."""
    check(regime, seed)
