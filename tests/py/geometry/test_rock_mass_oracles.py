"""Seeded jointed rock masses (rockmass_scenes.py) against oracles that need no
stored answer (SI units: m, s, kg, J). Every failure message names the case
(rockmass_scenes.describe: the seed and the joint sets reproduce it).

- The exact overlap of two convex blocks: rockmass_scenes.separation, a numpy
  separating-axis value over every face normal of both blocks and every cross
  product of an edge of each. Checked here against closed forms (cubes
  overlapping along x, a turned cube at a known distance, two crossing ridges
  that only an edge-edge axis parts) and against the hard-case suite's own
  implementation (hardguards.overlap_depth) on random turned boxes.
- No sub-contact is deeper than its pair's exact overlap: after every step,
  each sub-contact of contacts() (kept from the last step or new) has a gap
  [at the start of the step] >= -(the exact overlap of its two blocks on the
  corners read before that step) - (1e-9 m + 1e-9 x the largest corner
  coordinate); a free block's corner on a held block may be as deep as it
  lies in the held mass (rockmass_scenes.FixedMass: at a seam of two held
  blocks the pair's overlap measures only the way out across the joint,
  into the neighbour). And none is deeper than 0.1 mm at E = 1e9 Pa.
- The energy account balances: kinetic + gravity + strain + contact + friction
  + damping - loads - contactChanges stays at its value before the first step
  (the placed mass at rest: the free blocks' m g z) to 1e-6 of the largest
  term and to 1e-3 of the largest change of any term (the criterion of
  solver/test_energy_and_creep.py, whose helpers are reused); and contact
  changes between steps add no more than max(1 J, 1e-3 x the step's change of
  the gravity term).
- Every collider engine (DESS, MSC, NBS, AllPairs) gives bitwise the all-pairs
  sub-contacts at every step and the same final blocks.
- 1 and 2 threads give bitwise the same blocks.

The runs start from the placed geometry (startFromRest=False) at dt = 1e-3 s
for a few tens of steps: they test contacts and the account, not settling.
The default run covers 4 m cubes (about 110 to 135 blocks); more seeds and
12 m cubes (about 2,000 blocks) are marked slow.
"""
import functools
import math
import os
import random
import sys

import numpy as np
import pytest

import yade_dda
from yade_dda import O, DESSCollider, MSCCollider, NBSCollider, AllPairsCollider

import rockmass_scenes as R
from rockmass_scenes import Convex, separation, penetration, depth_violations, describe
from helpers import box, rotate
from hardguards import overlap_depth, Topology

_SOLVER_TESTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'solver')
if _SOLVER_TESTS not in sys.path:
    sys.path.insert(0, _SOLVER_TESTS)
from test_energy_and_creep import account, largest  # noqa: E402  (the suite's energy account helpers)

DT = 1e-3            # [s]
MAX_DEPTH = 1e-4     # [m] deepest sub-contact allowed at E = 1e9 Pa
KNOWN_EXCESS = 1e-6  # [m] the open sub-micrometre excesses over the exact overlap (see the depth test)
SIDE = 4.0           # [m] default cube
SPACING = 1.0        # [m]

# (kind, seed, side [m], steps): the default cases, then the slow sweep. A step of a 12 m cube
# (about 2,000 blocks, 1,000 to 1,450 of them free in one connected mass) takes 2 to 4 minutes
# on 2 cores from the placed geometry, so those runs are a few steps long.
RUNS = ([('junctions', 0, 5.0, 10)]
        + [(kind, seed, SIDE, 30) for kind in ('oblique', 'orthogonal') for seed in (1, 2, 3)]
        + [pytest.param(kind, seed, SIDE, 40, marks=pytest.mark.slow)
           for kind in ('oblique', 'orthogonal') for seed in range(4, 11)]
        + [pytest.param(kind, 1, 12.0, 2, marks=pytest.mark.slow) for kind in ('oblique', 'orthogonal')])


def run_id(kind, seed, side, steps):
    return '%s-seed%d-%gm-%dsteps' % (kind, seed, side, steps)


RUN_IDS = [run_id(*(r.values if hasattr(r, 'values') else r)) for r in RUNS]


def case_of(kind, seed, side):
    if kind == 'junctions':
        return R.JUNCTIONS_CASE
    return R.draw_case(seed, kind=kind, side=side, spacing=SPACING)


# ================================================================ exact overlap: closed forms (no stepping)

UNIT_CUBE_FACES = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
"""Faces of helpers.box's corner order (corner i: x from bit 0, y bit 1, z bit 2)."""


def cube(lo, hi):
    return Convex(box(lo, hi), UNIT_CUBE_FACES)


def turned(shape, axis, angle, about):
    return shape.moved(rotate([tuple(v) for v in shape.vertices], axis, angle, about=about))


def test_two_cubes_overlapping_along_x_overlap_by_that_depth():
    """Unit cubes [0, 1]^3 and [1 - d, 2 - d] x [0.4, 1.4] x [-0.3, 0.7]: the
    projections overlap by d on x, 0.6 on y, 0.7 on z, so the depth is d."""
    a = cube((0, 0, 0), (1, 1, 1))
    for d in (0.03, 0.25, 1e-6):
        b = cube((1 - d, 0.4, -0.3), (2 - d, 1.4, 0.7))
        assert penetration(a, b) == pytest.approx(d, rel=1e-9, abs=1e-15), d
        assert separation(a, b) == pytest.approx(-d, rel=1e-9, abs=1e-15)
        assert penetration(b, a) == pytest.approx(d, rel=1e-9, abs=1e-15)
    # touching (d = 0) and apart by 0.2 m along x
    assert penetration(a, cube((1, 0.4, -0.3), (2, 1.4, 0.7))) == 0.0
    assert separation(a, cube((1.2, 0.4, -0.3), (2.2, 1.4, 0.7))) == pytest.approx(0.2, rel=1e-12)


def test_a_cube_turned_45_deg_stands_apart_by_its_edge_distance():
    """A unit cube turned 45 deg about z, centred at x = 1 + s + sqrt(2)/2: its
    vertical edge nearest the unit cube [0, 1]^3 lies at x = 1 + s, so the two
    are apart by s (face x = 1 to that edge); sunk by -s < 0 they overlap by s."""
    a = cube((0, 0, 0), (1, 1, 1))
    h = math.sqrt(2) / 2
    for s in (0.1, 1e-3, -1e-3, -0.05):
        cx = 1 + s + h
        b = turned(cube((cx - .5, 0, 0), (cx + .5, 1, 1)), (0, 0, 1), math.pi / 4, (cx, .5, .5))
        assert min(b.vertices[:, 0]) == pytest.approx(1 + s, abs=1e-14)
        assert separation(a, b) == pytest.approx(s, abs=1e-14), s
        assert penetration(a, b) == pytest.approx(max(0.0, -s), abs=1e-14)


def test_crossing_ridges_are_parted_only_by_the_edge_edge_axis():
    """A unit cube turned 45 deg about x (a ridge along x on top, at z = sqrt(2)/2)
    under one turned 45 deg about y centred at height h (a ridge along y below, at
    z = h - sqrt(2)/2): the ridges cross, and the edge-edge axis x cross y = z
    gives the depth p = sqrt(2) - h (or distance -p). Every face axis overlaps by
    more than 0.35 m, so without the edge-edge axes the value would be wrong."""
    h2 = math.sqrt(2) / 2
    a = turned(cube((-.5, -.5, -.5), (.5, .5, .5)), (1, 0, 0), math.pi / 4, (0, 0, 0))
    for p in (0.01, 1e-5, -0.02):
        h = math.sqrt(2) - p
        b = turned(cube((-.5, -.5, h - .5), (.5, .5, h + .5)), (0, 1, 0), math.pi / 4, (0, 0, h))
        assert max(a.vertices[:, 2]) == pytest.approx(h2, abs=1e-15)
        assert min(b.vertices[:, 2]) == pytest.approx(h - h2, abs=1e-15)
        assert separation(a, b) == pytest.approx(-p, abs=1e-14), p
        assert penetration(a, b) == pytest.approx(max(0.0, p), abs=1e-14)
        faces_only = a.moved(a.vertices)
        faces_only.edges = a.edges[:0]     # no edge axes: the face axes alone
        if p > 0:
            assert separation(faces_only, b) < -0.35


def test_exact_overlap_agrees_with_the_hard_case_suites_depth():
    """Random pairs of turned boxes near each other: rockmass_scenes.penetration and
    hardguards.overlap_depth (another numpy separating-axis code) agree to 1e-12 m
    where the boxes overlap."""
    seed = 20260101
    rng = random.Random(seed)
    compared = 0
    for k in range(200):
        boxes = []
        for _ in range(2):
            lo = [rng.uniform(-.3, .3) for _ in range(3)]
            hi = [lo[i] + rng.uniform(.2, 1.0) for i in range(3)]
            c = [(lo[i] + hi[i]) / 2 for i in range(3)]
            axis = (rng.random(), rng.random(), rng.random())
            boxes.append(turned(cube(lo, hi), axis, rng.uniform(-math.pi, math.pi), c))
        a, b = boxes
        theirs = overlap_depth(a.vertices, Topology(a.faces, a.edges), b.vertices, Topology(b.faces, b.edges))
        if theirs > 0:
            compared += 1
            assert penetration(a, b) == pytest.approx(theirs, abs=1e-12), 'seed %d, pair %d' % (seed, k)
    assert compared > 50, 'seed %d: only %d overlapping pairs' % (seed, compared)


def test_neighbours_of_a_cut_mass_touch_with_no_overlap(scene):
    """Blocks as cutRockMass gives them (read before any step) share faces bit for
    bit: every pair of neighbours has separation 0 to round-off (|value| <=
    1e-12 m), so exact_penetration is 0 and no pair overlaps."""
    case = case_of('oblique', 1, SIDE)
    ids, _, _ = R.build_scene(case, dt=DT, startFromRest=False)
    shapes = R.snapshot(ids)
    lo = {i: s.vertices.min(axis=0) for i, s in shapes.items()}
    hi = {i: s.vertices.max(axis=0) for i, s in shapes.items()}
    touching = 0
    for x, i in enumerate(ids):
        for j in ids[x + 1:]:
            if np.all(lo[i] <= hi[j] + 1e-9) and np.all(lo[j] <= hi[i] + 1e-9):
                value = separation(shapes[i], shapes[j])
                assert value >= -1e-12, '%s: blocks %d and %d overlap by %g m' % (describe(case), i, j, -value)
                touching += abs(value) <= 1e-12
    assert touching > len(ids), describe(case)
    assert R.exact_penetration(ids[0], ids[1]) == 0.0


# ================================================================ the depth check itself (synthetic)

def test_depth_check_flags_contacts_deeper_than_their_pairs_overlap():
    """depth_violations on made-up contacts: cubes 1 and 2 overlap by 1 mm along x,
    cube 3 is 10 mm from cube 1. Contacts 0.5 mm deep and 1 mm deep (+ 1e-9 m,
    within the tolerance 1e-9 m + 1e-9 x 2 m) pass; one 1 mm + 10 nm deep, one 2 mm
    deep (either id order) and one 1 um deep between the parted cubes 1 and 3 are
    flagged, the largest excess first."""
    shapes = {1: cube((0, 0, 0), (1, 1, 1)), 2: cube((0.999, 0, 0), (1.999, 1, 1)),
              3: cube((-1.01, 0, 0), (-0.01, 1, 1))}
    assert penetration(shapes[1], shapes[2]) == pytest.approx(1e-3, abs=1e-15)
    ok = [(1, 2, -0.5e-3, 'ok'), (2, 1, -1e-3 - 1e-9, 'ok'), (1, 3, 5e-3, 'ok')]
    assert depth_violations(ok, shapes) == []
    bad = ok + [(1, 2, -1e-3 - 1e-8, 'just'), (2, 1, -2e-3, 'deep'), (3, 1, -1e-6, 'parted')]
    found = depth_violations(bad, shapes)
    assert [v[2] for v in found] == ['deep', 'parted', 'just']
    assert found[0][4] == pytest.approx(1e-3, abs=1e-15) and found[1][4] == 0.0
    assert found[2][5] == pytest.approx(1e-9 + 1e-9 * 1.999)


def test_depth_check_allows_a_corner_as_deep_as_it_lies_in_the_held_mass():
    """Held cubes A = [0,1]^3 and B = [1,2] x [0,1] x [0,1] meet flush at x = 1 (the
    seam); a free block's lowest corner q sits 0.1 mm past the seam in B and 1 mm below
    the mass's top. Against A's top face its gap is -1 mm while the pair (free, A)
    only touches: allowed, since q lies 1 mm deep in the held mass (FixedMass: its
    nearest exposed face is the top; the seam faces are covered). A gap of -2 mm, or
    -1 mm for a corner on the top surface, is flagged; so is the -1 mm contact when no
    held mass is given."""
    A, B = cube((0, 0, 0), (1, 1, 1)), cube((1, 0, 0), (2, 1, 1))
    held = R.FixedMass({1: A, 2: B})
    assert len(held.exposed) == 10      # the two seam faces cover each other
    q = (1.0001, 0.5, 0.999)
    corners = [q, (1.3, 0.6, 1.5), (1.2, 0.2, 1.5), (1.5, 0.4, 1.6)]
    free = Convex(corners, [(0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)])
    on_top = Convex([(1.5, 0.5, 1.0)] + corners[1:], [(0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)])
    shapes = {1: A, 2: B, 3: free, 4: on_top}
    assert penetration(free, A) == 0.0
    seam = [(3, 1, -1e-3, 'VF/VF locked', q)]
    assert depth_violations(seam, shapes, fixed_mass=held) == []
    assert [v[2] for v in depth_violations(seam, shapes)] == ['VF/VF locked']
    deep = [(3, 1, -2e-3, 'VF/VF deep', q), (4, 1, -1e-3, 'VF/VF surface', (1.5, 0.5, 1.0))]
    assert sorted(v[2] for v in depth_violations(deep, shapes, fixed_mass=held)) == ['VF/VF deep', 'VF/VF surface']


# ================================================================ seeded runs

@functools.lru_cache(maxsize=None)
def recorded_run(kind, seed, side, steps):
    """Runs the case `steps` steps from its placed geometry; after each step records
    the sub-contacts deeper than their pair's exact overlap on the corners read
    before the step, the deepest gap, and the energy account. Cached: the depth
    and energy tests read one run. Leaves O reset."""
    O.reset()
    case = case_of(kind, seed, side)
    ids, fixed, free = R.build_scene(case, dt=DT, startFromRest=False)
    start = R.rest_account(free)
    shapes = R.snapshot(ids)          # the first step's start
    held = R.FixedMass({i: shapes[i] for i in fixed})   # held blocks never move
    steps_seen = []
    for step in range(1, steps + 1):
        O.step()
        contacts = [(c.id1, c.id2, c.gap, '%s/%s %s' % (c.kind, c.type, c.state), tuple(c.point))
                    for c in yade_dda.contacts()]
        violations = depth_violations(contacts, shapes, fixed_mass=held)
        steps_seen.append(dict(step=step, contacts=len(contacts), violations=len(violations),
                               worst=violations[:3], deepest=max([-c[2] for c in contacts] + [0.0]),
                               energy=dict(yade_dda.stats()['energy'])))
        shapes = R.snapshot(ids, shapes)   # the next step's start
    O.reset()
    return case, start, steps_seen


@pytest.mark.parametrize('kind, seed, side, steps', RUNS, ids=RUN_IDS)
def test_no_sub_contact_is_deeper_than_its_pairs_exact_overlap(scene, kind, seed, side, steps):
    case, _, seen = recorded_run(kind, seed, side, steps)
    print(describe(case))
    assert sum(s['contacts'] for s in seen) > 0, describe(case)
    bad = [s for s in seen if s['violations']]
    if bad:
        worst = min((v for s in bad for v in s['worst']), key=lambda v: v[3] + v[4])
        excess = -(worst[3] + worst[4])
        first = bad[0]
        message = ('%s: sub-contacts deeper than their pair\'s exact overlap after %d of %d steps (%d in all; '
                   'first at step %d: %s); largest excess %.3g m: bodies %d-%d %s, gap %.3g m, exact overlap '
                   '%.3g m, tol %.2g m' % (describe(case), len(bad), len(seen), sum(s['violations'] for s in bad),
                                           first['step'], _fmt(first['worst'][0]), excess, worst[0], worst[1],
                                           worst[2], worst[3], worst[4], worst[5]))
        if excess > KNOWN_EXCESS:
            pytest.fail(message)
        # Open: excesses of a tenth of a micrometre (up to 1.4e-7 m in the
        # default runs), on pairs of the EEp and VV types, where the exact
        # separation comes from an edge pair the narrow phase treats as
        # parallel (within its angle tolerance) and a corner stands for the
        # edges' contact along the entrance face. Reported, never beyond
        # KNOWN_EXCESS.
        pytest.xfail(message)


def _fmt(v):
    return 'bodies %d-%d %s gap %.3g m, overlap %.3g m' % (v[0], v[1], v[2], v[3], v[4])


@pytest.mark.parametrize('kind, seed, side, steps', RUNS, ids=RUN_IDS)
def test_no_sub_contact_is_deeper_than_a_tenth_of_a_millimetre(scene, kind, seed, side, steps):
    """At E = 1e9 Pa and a few hundred kPa of overburden the springs sink by
    micrometres; 0.1 mm would be a contact far off its pair."""
    case, _, seen = recorded_run(kind, seed, side, steps)
    print(describe(case))
    deepest = max(seen, key=lambda s: s['deepest'])
    assert deepest['deepest'] <= MAX_DEPTH, '%s: a sub-contact %.3g m deep at step %d' % (
        describe(case), deepest['deepest'], deepest['step'])


def account_drifts(start, energies, relative=1e-6, relative_to_change=1e-3):
    """Steps whose energy account (account() - contactChanges, the terms of
    stats()['energy']) is off its start by more than `relative` x the largest term's
    magnitude or `relative_to_change` x the largest change of any term since the
    start: a list of (step, drift [J], largest term [J], largest change [J]).
    Within the round-off of adding each step's terms to totals of that magnitude
    (4 ulps a step) and of summing the seven terms for the start and for the step
    (half an ulp of a partial sum up to twice the magnitude per addition: 14 ulps)
    the account balances whatever the change: a mass at rest changes by less than
    that."""
    zero = account(start) - start['contactChanges']
    out = []
    for step, e in enumerate(energies, 1):
        drift = account(e) - e['contactChanges'] - zero
        magnitude = max(abs(v) for v in list(e.values()) + list(start.values()))
        change = largest(e, start)
        roundoff = (4 * step + 14) * sys.float_info.epsilon * magnitude
        if abs(drift) > relative * magnitude or abs(drift) > max(relative_to_change * change, roundoff):
            out.append((step, drift, magnitude, change))
    return out


def contact_change_gains(start, energies, absolute=1.0, relative=1e-3):
    """Steps in which contactChanges rose by more than max(absolute [J], relative x
    |the step's change of the gravity term|): a list of (step, rise [J], allowed [J])."""
    out, last = [], start
    for step, e in enumerate(energies, 1):
        rise = e['contactChanges'] - last['contactChanges']
        allowed = max(absolute, relative * abs(e['gravity'] - last['gravity']))
        if rise > allowed:
            out.append((step, rise, allowed))
        last = e
    return out


def assert_account_balances(case, start, energies):
    drifts = account_drifts(start, energies)
    assert not drifts, '%s: the account drifts at %d steps; first: step %d, %.3g J (largest term %.3g J, largest ' \
        'change %.3g J)' % ((describe(case), len(drifts)) + drifts[0])


def assert_no_contact_change_gain(case, start, energies):
    gains = contact_change_gains(start, energies)
    assert not gains, '%s: contact changes added energy at %d steps; largest: step %d, %.3g J (allowed %.3g J)' % (
        (describe(case), len(gains)) + max(gains, key=lambda g: g[1] - g[2]))


def test_energy_checks_flag_a_drift_and_a_gain():
    """account_drifts and contact_change_gains on made-up accounts: a balanced
    exchange of gravity for kinetic energy passes; 5 J appearing from nowhere,
    and 2 J of contactChanges in one step where gravity changed by 100 J, are
    flagged (a contact change of 2 J is booked, so the account still balances)."""
    zero = dict(kinetic=0.0, gravity=1e6, strain=0.0, contact=0.0, friction=0.0, damping=0.0, loads=0.0,
                contactChanges=0.0)
    fine = [dict(zero, kinetic=60.0, gravity=1e6 - 100.0, friction=40.0),
            dict(zero, kinetic=50.0, gravity=1e6 - 200.0, friction=150.0)]
    assert account_drifts(zero, fine) == [] and contact_change_gains(zero, fine) == []
    drifting = fine + [dict(zero, kinetic=55.0, gravity=1e6 - 200.0, friction=150.0)]
    assert [d[0] for d in account_drifts(zero, drifting)] == [3]
    gaining = fine + [dict(zero, kinetic=52.0, gravity=1e6 - 200.0, friction=150.0, contactChanges=2.0)]
    assert account_drifts(zero, gaining) == []
    assert contact_change_gains(zero, gaining) == [(3, 2.0, 1.0)]


@pytest.mark.parametrize('kind, seed, side, steps', RUNS, ids=RUN_IDS)
def test_the_energy_account_balances(scene, kind, seed, side, steps):
    case, start, seen = recorded_run(kind, seed, side, steps)
    print(describe(case))
    assert_account_balances(case, start, [s['energy'] for s in seen])


@pytest.mark.parametrize('kind, seed, side, steps', RUNS, ids=RUN_IDS)
def test_contact_changes_add_no_energy(scene, kind, seed, side, steps):
    case, start, seen = recorded_run(kind, seed, side, steps)
    print(describe(case))
    assert_no_contact_change_gain(case, start, [s['energy'] for s in seen])


# ================================================================ at rest after the start from rest

# Joints dipping below the friction angle hold: a confined mass settled from rest must stay there.
AT_REST_SPEED = 1e-3   # [m/s] every free block slower than this at the end
REST_RUNS = ([('junctions', 0, 5.0, 0.2), ('oblique', 1, SIDE, 0.2)]
             + [pytest.param(kind, seed, SIDE, 0.5, marks=pytest.mark.slow)
                for kind in ('oblique', 'orthogonal') for seed in (1, 2, 3, 4, 5)]
             + [pytest.param('junctions', 0, 5.0, 0.5, marks=pytest.mark.slow)]
             + [pytest.param(kind, 1, 6.0, 0.5, marks=pytest.mark.slow) for kind in ('oblique', 'orthogonal')]
             + [pytest.param('orthogonal', 1, 8.0, 0.2, marks=pytest.mark.slow)]
             + [pytest.param('orthogonal', 1, 10.0, 0.5, marks=pytest.mark.slow)])
# The start from rest's static steps: at most this many open-close solves each on average. With
# friction locked or ramped a static step is one pass of Newton solves (World::staticStep; 10 to 15
# on the masses here, where limits settled pass by pass within each step took 60 to 80).
SETTLE_SOLVES_PER_STEP = 25


@functools.lru_cache(maxsize=None)
def rest_run(kind, seed, side, duration):
    """Starts the case from rest (DDAIntegrator's default) at dt = 1e-3 s and runs it
    for `duration` [s]; returns the case, the first step's stats, the per-step
    energies, solves and cuts, and the free blocks' largest speed at the end."""
    O.reset()
    case = case_of(kind, seed, side)
    ids, _, free = R.build_scene(case, dt=DT)
    O.step()
    first = dict(yade_dda.stats())
    energies, solves, cuts = [dict(first['energy'])], [first['openCloseIterations']], [first['stepCuts']]
    while O.time < duration:
        O.step()
        s = yade_dda.stats()
        energies.append(dict(s['energy']))
        solves.append(s['openCloseIterations'])
        cuts.append(s['stepCuts'])
    speed = max(O.bodies[i].state.vel.norm() for i in free)
    result = (case, first, len(free), energies, solves, cuts, speed)
    O.reset()
    return result


@pytest.mark.parametrize('kind, seed, side, duration', REST_RUNS)
def test_a_confined_mass_settles_and_stays_at_rest(scene, kind, seed, side, duration):
    case, first, free, energies, solves, cuts, speed = rest_run(kind, seed, side, duration)
    print(describe(case), 'settle steps', first['settleSteps'], 'settle solves', first['settleSolves'],
          'mean solves %.2f' % (sum(solves) / len(solves)), 'cuts', sum(cuts), 'largest speed %.3g m/s' % speed)
    assert first['settleConverged'] and first['settledBlocks'] == free, (
        '%s: start from rest: converged %s, %d of %d free blocks settled in %d static steps'
        % (describe(case), first['settleConverged'], first['settledBlocks'], free, first['settleSteps']))
    # Settled with the true friction, not left in the locked state: no block the
    # friction could not hold (every joint dips below the friction angle).
    assert not first['unsettledBlocks'], '%s: start from rest left blocks %s unsettled' % (
        describe(case), list(first['unsettledBlocks']))
    assert speed < AT_REST_SPEED, '%s: a free block at %.3g m/s after %g s' % (describe(case), speed, duration)
    assert first['settleSolves'] <= SETTLE_SOLVES_PER_STEP * first['settleSteps'], (
        '%s: start from rest made %d open-close solves in %d static steps' % (
            describe(case), first['settleSolves'], first['settleSteps']))


# The settled state is an equilibrium: the first step starts every block at rest, so a block's speed
# at its end is its out-of-balance acceleration at the settled state times dt (reactions that build
# within the step only resist). The settling's quiet test admits 1e-4 g (kSettleQuietAcceleration);
# this bound is 50 times looser, for contacts that close within the step. Seed 2 of the 6 m oblique
# mass, when the static steps kept friction on contacts that had opened, started with a block 0.18 g
# out of balance; seed 1 of the 5 m one, settled without the final passes that settle the limits
# within a step, 8.7e-3 g. The cost bound is the one above: with their limits settled pass by pass
# in every static step, the true friction's steps made 80 solves each (seed 2, 6 m).
UNBALANCED = 5e-3    # [g]
BALANCE_RUNS = ([('oblique', 2, 6.0), ('oblique', 1, 5.0)]
                + [pytest.param('oblique', 1, 7.0, marks=pytest.mark.slow),
                   pytest.param('oblique', 1, 9.0, marks=[pytest.mark.slow, pytest.mark.xfail(
                       strict=False, reason='a 3.2 t block starts 1e-2 g out of balance (the quiet test is '
                       'relative to the largest first move) and comes to rest within 0.1 s')])])


@pytest.mark.parametrize('kind, seed, side', BALANCE_RUNS)
def test_the_settled_state_leaves_no_block_out_of_balance(scene, kind, seed, side):
    O.reset()
    case = case_of(kind, seed, side)
    _, _, free = R.build_scene(case, dt=DT)
    O.step()
    first = yade_dda.stats()
    speed, body = max((O.bodies[i].state.vel.norm(), i) for i in free)
    print(describe(case), 'settle steps', first['settleSteps'], 'solves', first['settleSolves'],
          'first step: largest speed %.3g m/s (body %d)' % (speed, body))
    O.reset()
    assert first['settleConverged'], describe(case)
    assert first['settleSolves'] <= SETTLE_SOLVES_PER_STEP * first['settleSteps'], (
        '%s: start from rest made %d open-close solves in %d static steps' % (
            describe(case), first['settleSolves'], first['settleSteps']))
    assert speed <= UNBALANCED * R.G * DT, (
        '%s: body %d at %.3g m/s after the first step: %.3g g out of balance at the settled state'
        % (describe(case), body, speed, speed / (R.G * DT)))


@pytest.mark.parametrize('kind, seed, side, duration', REST_RUNS)
def test_a_settled_mass_keeps_its_energy_account(scene, kind, seed, side, duration):
    case, first, _, energies, _, _, _ = rest_run(kind, seed, side, duration)
    assert_account_balances(case, energies[0], energies[1:])
    assert_no_contact_change_gain(case, energies[0], energies[1:])


@pytest.mark.parametrize('kind, seed, side, duration', REST_RUNS)
def test_a_settled_mass_needs_few_solves_and_no_cut(scene, kind, seed, side, duration):
    """At most 5 open-close solves a step on average, the time step at its maximum."""
    case, _, _, _, solves, cuts, _ = rest_run(kind, seed, side, duration)
    mean = sum(solves) / len(solves)
    assert mean <= 5 and sum(cuts) == 0, '%s: %.2f open-close solves a step on average (most %d), %d step cuts in %d steps' % (
        describe(case), mean, max(solves), sum(cuts), len(solves))


QUIET_CONTACTS = 1e-6  # contact changes of a mass at rest, as a fraction of its contacts' energy


@pytest.mark.parametrize('kind, seed, side, duration', REST_RUNS)
def test_a_settled_mass_keeps_its_contacts(scene, kind, seed, side, duration):
    """A mass at rest keeps its sub-contacts from step to step: the energy that
    contacts appearing, vanishing or changing between steps add (contactChanges)
    stays within a millionth of what its springs hold. A contact that comes back
    compressed every other step adds its spring's energy each time (1e-5 J a
    step at a free corner meeting a junction of held blocks, in a 4 m mass whose
    springs hold 0.3 J) and keeps the mass ringing."""
    case, _, _, energies, _, _, _ = rest_run(kind, seed, side, duration)
    added = energies[-1]['contactChanges'] - energies[0]['contactChanges']
    held = energies[-1]['contact']
    print(describe(case), 'contact changes %.3g J, springs %.3g J' % (added, held))
    assert abs(added) <= QUIET_CONTACTS * held, '%s: contact changes %.3g J against %.3g J in the springs' % (
        describe(case), added, held)


# ================================================================ colliders and threads

def contact_set():
    return sorted((c.id1, c.id2, c.kind, c.type, c.state, tuple(c.point), c.gap) for c in yade_dda.contacts())


def blocks_bits(ids):
    """Every block's corners, centroid and velocity as raw float64 bytes."""
    out = []
    for i in ids:
        b = yade_dda.block(i)
        values = [x for v in b.vertices for x in v] + list(b.centroid) + list(b.velocity)
        out.append(np.asarray(values, dtype=np.float64).tobytes())
    return out


def bodies_bits():
    """What YADE's bodies show of the motion: position, velocity, angular velocity, as raw bytes.
    (Not the orientation: a fixed body's state.ori, from YADE's Polyhedra at ddaBlock, differs by
    an ulp or so between two builds of the same mass in one process, threads or not.)"""
    return [np.asarray(list(b.state.pos) + list(b.state.vel) + list(b.state.angVel), dtype=np.float64).tobytes()
            for b in O.bodies]


COLLIDERS = (('AllPairs', AllPairsCollider), ('DESS', DESSCollider), ('MSC', MSCCollider), ('NBS', NBSCollider))
COLLIDER_RUNS = ([('oblique', 1, SIDE, 5), ('orthogonal', 2, SIDE, 5)]
                 + [pytest.param('oblique', seed, SIDE, 10, marks=pytest.mark.slow) for seed in (3, 4, 5)]
                 + [pytest.param('oblique', 1, 12.0, 2, marks=pytest.mark.slow)])   # some 20 minutes


def collider_run(case, make, steps):
    O.reset()
    ids, _, _ = R.build_scene(case, dt=DT, startFromRest=False)
    O.engines = [make()] + list(O.engines)
    sets = []
    for _ in range(steps):
        O.step()
        sets.append(contact_set())
    return sets, blocks_bits(ids)


@pytest.mark.parametrize('kind, seed, side, steps', COLLIDER_RUNS,
                         ids=[run_id(*(r.values if hasattr(r, 'values') else r)) for r in COLLIDER_RUNS])
def test_every_collider_gives_the_all_pairs_contacts(scene, kind, seed, side, steps):
    """The same seeded mass under each collider engine placed before the integrator:
    at every step the sub-contacts (ids, kind, type, state, point, gap) equal
    AllPairs' exactly, and the blocks end bitwise where AllPairs' do."""
    case = case_of(kind, seed, side)
    print(describe(case))
    results = {name: collider_run(case, make, steps) for name, make in COLLIDERS}
    reference, final = results['AllPairs']
    assert sum(len(s) for s in reference) > 0, describe(case)
    for name, (sets, blocks) in results.items():
        for step, (a, b) in enumerate(zip(reference, sets), 1):
            if a != b:
                only_ref, only_here = sorted(set(a) - set(b)), sorted(set(b) - set(a))
                pytest.fail('%s: %s differs from AllPairs at step %d (%d vs %d sub-contacts; AllPairs only: %s; %s '
                            'only: %s)' % (describe(case), name, step, len(a), len(b), only_ref[:2], name,
                                           only_here[:2]))
        moved = [i for i, (x, y) in enumerate(zip(final, blocks)) if x != y]
        assert not moved, '%s: under %s %d blocks end elsewhere than under AllPairs' % (
            describe(case), name, len(moved))


THREAD_RUNS = ([('oblique', 1, SIDE, 10), ('orthogonal', 1, SIDE, 10), ('oblique', 1, 7.0, 5)]
               + [pytest.param('oblique', seed, SIDE, 10, marks=pytest.mark.slow) for seed in (2, 3, 4)]
               + [pytest.param('orthogonal', 1, 12.0, 2, marks=pytest.mark.slow)])    # some 15 to 20 minutes


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason='needs 2 processors')
@pytest.mark.parametrize('kind, seed, side, steps', THREAD_RUNS,
                         ids=[run_id(*(r.values if hasattr(r, 'values') else r)) for r in THREAD_RUNS])
def test_one_and_two_threads_give_the_same_bits(scene, kind, seed, side, steps):
    """The same seeded mass on 1 and 2 threads: after every step the blocks'
    corners, centroids and velocities, and YADE's bodies' positions and
    velocities, are bitwise equal.
    (The narrow phase runs threaded at any size; the iterative solve's block
    rows from 128 blocks in one component, which the 7 m cube reaches: 155
    free blocks, here with the coarse level from 64 blocks; the loops over
    contacts from 2,048 contacts and over moving blocks from 1,024, which
    only the 12 m orthogonal cube reaches: 1,452 free blocks, some 32,000
    sub-contacts.)"""
    case = case_of(kind, seed, side)
    print(describe(case))
    runs = []
    for threads in (1, 2):
        O.reset()
        coarse = dict(iterativeCoarseBlocks=64) if side == 7 else {}
        ids, _, _ = R.build_scene(case, dt=DT, startFromRest=False, threads=threads, **coarse)
        seen, iterated, aggregates = [], 0, 0
        for _ in range(steps):
            O.step()
            seen.append((blocks_bits(ids), bodies_bits()))
            iterated += yade_dda.stats()['iterativeComponents']
            aggregates += yade_dda.stats()['coarseAggregates']
        runs.append(seen)
        if side >= 7:
            assert iterated > 0, '%s: the iterative solve was not taken' % describe(case)
            assert aggregates > 0, '%s: the coarse level was not taken' % describe(case)
    for step, ((blocks1, bodies1), (blocks2, bodies2)) in enumerate(zip(*runs), 1):
        differ = [ids[k] for k, (x, y) in enumerate(zip(blocks1, blocks2)) if x != y]
        assert not differ, '%s: step %d, %d blocks differ on 1 and 2 threads (first body %d)' % (
            describe(case), step, len(differ), differ[0])
        assert bodies1 == bodies2, "%s: step %d, YADE's bodies differ on 1 and 2 threads" % (describe(case), step)
