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
  exceed the bound in the last half second); it does not turn by more than the bound
  over the footprint's narrowest width; the contact forces on it balance its weight
  (1e-3 of m g).
- FS in 0.2..0.8 ('slide'): the prism slides down the dip direction with
  a = g (sin theta - tan(phi) cos theta): the velocity gain along the dip from 0.3 s to
  1 s is a x 0.7 s within 1e-3, the displacement a t^2 / 2 within 1e-3; across the
  dip and along the normal it moves less than the settlement bound, and turns less
  than the bound over the narrowest width (a translating block feels no moment: the
  contact force passes through the centroid); every closed contact is sliding (every
  point of the base slips at the block's velocity); the normal forces sum to
  m g cos(theta) and the friction to tan(phi) times that (1e-3 of m g); friction
  dissipates tan(phi) m g cos(theta) x the distance slid (1e-3), and the kinetic
  energy is m (a t)^2 / 2 (1e-3).
- Both: the energy account (stats()['energy']) balances: its terms' change minus the
  loads, less what contact changes between steps add (contactChanges), stays within
  1e-6 of the scale (the largest change of any term, or, at rest, where the settling
  happened in the first step, m g times the settlement bound); contactChanges adds no
  more than 1e-3 of that scale; friction never negative; kinetic plus potential energy
  never above its value after the first step (by 1e-3 of the scale).

The tolerances are not fitted to DDA: 1e-3 on a constant acceleration is far above
what an exact-for-constant-acceleration scheme with stiff penalty springs leaves and
far below what a wrong friction law gives (a 1% error in tan(phi) changes a by
FS / (1 - FS) %, at least 0.25 %). Default run: SEEDS (two regimes each, about 20 s);
`-m slow` sweeps SLOW_SEEDS.
"""
import math

import numpy as np
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator

import random_slopes as R

SEEDS = range(1, 7)
SLOW_SEEDS = range(7, 67)
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


def run_case(case):
    """Builds the case, runs it to 1 s stopping at SAMPLES, and returns what the oracles need:
    the prism's centroid, velocity (translation) and rotation vector at each sample (c0 at the
    start, c1 after the first step), the account after the first step and at each sample, the largest rise of
    kinetic plus potential energy over its value after the first step, and the prism's mass."""
    slab, prism = R.build(case)
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -R.G), maxDisplacement=0.02, label='dda')]
    blk = yade_dda.block(prism)
    c0 = np.array(blk.centroid)
    O.run(1, True)

    def mechanical():
        v = np.array(blk.velocity[0:3])
        return blk.mass * R.G * blk.centroid[2] + 0.5 * blk.mass * v @ v

    e1, a1 = mechanical(), dict(yade_dda.stats()['energy'])
    out = dict(prism=prism, slab=slab, mass=blk.mass, c0=c0, c1=np.array(blk.centroid), a1=a1, at={}, rise=0.0, frictionMin=0.0)
    for t in SAMPLES:
        O.run(int(round((t - O.time) / DT)), True)
        assert abs(O.time - t) < 1e-9, (R.describe(case), O.time, t, yade_dda.stats()['stepCuts'])
        a = dict(yade_dda.stats()['energy'])
        out['at'][t] = dict(c=np.array(blk.centroid), v=np.array(blk.velocity[0:3]),
                            rot=np.array(blk.rotation.toRotationVector()), energy=a)
        out['rise'] = max(out['rise'], mechanical() - e1)
        out['frictionMin'] = min(out['frictionMin'], a['friction'] - a1['friction'])
    out['force'] = force_on(prism)
    out['states'] = sorted(c.state for c in yade_dda.contacts() if prism in (c.id1, c.id2))
    return out


def energy_report(case, run, scale):
    """(drift, added) [J]: the account's imbalance and what contact changes added since the first step;
    asserts both within their share of `scale` (module docstring), friction never negative and no
    rise of kinetic plus potential energy."""
    a1, a = run['a1'], run['at'][SAMPLES[-1]]['energy']
    added = a['contactChanges'] - a1['contactChanges']
    drift = account(a) - account(a1) - added
    where = R.describe(case)
    assert abs(drift) <= 1e-6 * scale, (where, 'account imbalance', drift, scale)
    assert added <= 1e-3 * scale, (where, 'contact changes added energy', added, scale)
    assert run['frictionMin'] >= 0, (where, 'friction negative', run['frictionMin'])
    assert run['rise'] <= 1e-3 * scale, (where, 'kinetic + potential rose', run['rise'], scale)
    return drift, added


def check_hold(case, run):
    """The oracles of a case with FS >= 1.25 (module docstring); returns the printed numbers."""
    where = R.describe(case)
    bound = R.settlement_bound(case)
    width = R.polygon_shape(case['footprint'])[3]
    end, half = run['at'][1.0], run['at'][0.5]
    moved = np.linalg.norm(end['c'] - run['c0'])
    late = np.linalg.norm(end['c'] - half['c'])
    speed = np.linalg.norm(end['v'])
    turn = np.linalg.norm(end['rot'])
    weight = run['mass'] * R.G
    assert moved < bound, (where, 'moved', moved, 'bound', bound)
    assert late < bound and speed < bound / 0.5, (where, 'creeps', late, speed, bound)
    assert turn < bound / width, (where, 'turned', turn, bound / width)
    assert np.linalg.norm(run['force'] - np.array([0, 0, weight])) < 1e-3 * weight, (where, run['force'], weight)
    a1, a = run['a1'], end['energy']
    scale = max(max(abs(a[k] - a1[k]) for k in a), weight * bound)
    drift, added = energy_report(case, run, scale)
    return ('%s\n  moved %.3g m (bound %.3g m), %.3g m from 0.5 s to 1 s, speed %.2g m/s, turned %.2g rad; '
            'account imbalance %.2g J, contact changes %.2g J (scale %.3g J); contacts %s'
            % (where, moved, bound, late, speed, turn, drift, added, scale, states_summary(run)))


def states_summary(run):
    return ', '.join('%d %s' % (run['states'].count(s), s) for s in sorted(set(run['states'])))


def check_slide(case, run):
    """The oracles of a case with FS <= 0.8 (module docstring); returns the printed numbers."""
    where = R.describe(case)
    downhill, across, normal = case['frame']
    acc = R.sliding_acceleration(case)
    bound = R.settlement_bound(case)
    width = R.polygon_shape(case['footprint'])[3]
    start, end = run['at'][0.3], run['at'][1.0]
    gain = (end['v'] - start['v']) @ downhill
    d = end['c'] - run['c0']
    along, expected = d @ downhill, acc * 1.0 ** 2 / 2
    assert abs(gain - acc * 0.7) < 1e-3 * acc * 0.7, (where, 'acceleration', gain / 0.7, acc)
    assert abs(along - expected) < 1e-3 * expected, (where, 'slid', along, expected)
    assert abs(d @ across) < bound and abs(d @ normal) < bound, (where, 'off the dip', d @ across, d @ normal, bound)
    turn = np.linalg.norm(end['rot'])
    assert turn < bound / width, (where, 'turned', turn, bound / width)
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
    drift, added = energy_report(case, run, scale)
    return ('%s\n  acceleration %.6f m/s^2 (closed form %.6f, %+.2e), slid %.5f m (%+.2e), across %.2g m, '
            'normal %.2g m (bound %.2g), turned %.2g rad; friction work %+.2e of the closed form; account '
            'imbalance %.2g J, contact changes %.2g J (scale %.4g J); contacts %s'
            % (where, gain / 0.7, acc, gain / 0.7 / acc - 1, along, along / expected - 1, d @ across, d @ normal,
               bound, turn, dissipated / closedForm - 1, drift, added, scale, states_summary(run)))


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


@pytest.mark.slow
@pytest.mark.parametrize('seed', SLOW_SEEDS)
@pytest.mark.parametrize('regime', ['hold', 'slide'])
def test_random_prism_on_random_incline_sweep(scene, regime, seed):
    """The same oracles on 60 more seeds per regime."""
    check(regime, seed)
