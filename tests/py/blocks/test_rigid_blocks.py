"""Rigid blocks (ddaBlock(..., rigid=True)): 6 unknowns instead of 12.

Closed forms for free flight and sliding, agreement with a very stiff
deformable block within a tolerance derived from its strain, a mixed pile under
the hard-case guards, the counters that show the strain unknowns are not
solved, and bad input. SI units throughout.
"""
import math

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock, rigidBlock
from yade import wrapper

import scenes as S
from hardguards import Guard
from helpers import box, material, rotate

G = 9.81


def counters_match(rigid, deformable):
    """The step's unknowns are 6 per moving rigid block and 12 per deformable one, the solver
    factorised exactly that many, and only the deformable blocks brought strain unknowns."""
    s = yade_dda.stats()
    assert s['rigidBlocks'] == rigid
    assert s['unknowns'] == 6 * rigid + 12 * deformable
    assert s['solvedUnknowns'] == s['unknowns']
    assert s['strainUnknowns'] == 6 * deformable


def assert_unstrained(body):
    blk = yade_dda.block(body)
    assert blk.rigid
    assert tuple(blk.strain) == (0.0,) * 6 and tuple(blk.stress) == (0.0,) * 6
    assert tuple(blk.velocity)[6:] == (0.0,) * 6


def test_rigid_cube_falls_and_spins_exactly(scene):
    """A rigid 1 m cube thrown with v0 and spun with w0 under gravity: c(t) = c0 + v0 t + g t^2/2
    (exact for Shi's scheme, 1e-12 relative) and, its inertia being isotropic, a steady spin: it
    has turned by |w0| t about w0 (1e-10 rad). Its strain, stress, strain rates stay exactly 0
    and its volume exactly 1 m^3. A deformable block beside it keeps 12 unknowns."""
    rock = material(O, young=1e9)
    v0, w0 = (1.5, -0.5, 4.0), (0.3, -1.2, 2.0)
    b = O.bodies.append(rigidBlock(box((0, 0, 10), (1, 1, 11)), material=rock, velocity=v0, angularVelocity=w0))
    other = O.bodies.append(ddaBlock(box((5, 0, 10), (6, 1, 11)), material=rock))
    c0 = tuple(yade_dda.block(b).centroid)
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), maxDisplacement=1.0)]
    O.run(250, True)
    t = O.time
    expected = [c0[i] + v0[i] * t + (-G if i == 2 else 0.0) * t * t / 2 for i in range(3)]
    pos = O.bodies[b].state.pos
    assert max(abs(pos[i] - expected[i]) for i in range(3)) < 1e-12 * S.norm(expected)
    turned = yade_dda.block(b).rotation.toRotationVector()
    wt = [w * t for w in w0]
    assert max(abs(turned[i] - wt[i]) for i in range(3)) < 1e-10
    assert tuple(O.bodies[b].state.angVel) == pytest.approx(w0, abs=1e-12)
    assert_unstrained(b)
    assert yade_dda.block(b).volume == 1.0
    counters_match(rigid=1, deformable=1)
    assert not yade_dda.block(other).rigid


@pytest.mark.parametrize('phiDeg, tolerance', [(0.0, 1e-6), (20.0, 0.01)])
def test_rigid_block_slides_down_incline(scene, phiDeg, tolerance):
    """A rigid cube on a fixed 30 deg incline slides s(t) = g (sin a - tan(phi) cos a) t^2/2
    (scenes.incline_slide_distance; the tolerances of the deformable block's test in
    test_contact_physics.py: exact without friction up to the contacts settling, 1% with
    friction for the normal force's start-up), neither tips nor leaves the slope, and stays
    unstrained with 6 unknowns throughout."""
    slope = math.radians(30)
    geo = S.incline_geometry(slope, (1.0, 1.0, 1.0))
    S.add_block(geo['slab'], S.rock(phiDeg), fixed=True)
    b = S.add_block(geo['block'], S.rock(phiDeg), rigid=True)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01)]
    c0 = tuple(yade_dda.block(b).centroid)
    O.run(1000, True)
    downhill, across, normal = geo['frame']
    d = S.sub(tuple(yade_dda.block(b).centroid), c0)
    expected = S.incline_slide_distance(slope, math.radians(phiDeg), O.time)
    assert abs(S.dot(d, downhill) - expected) < tolerance * expected
    assert abs(S.dot(d, across)) < 1e-6 and abs(S.dot(d, normal)) < 1e-4
    assert yade_dda.block(b).rotation.toRotationVector().norm() < 1e-3
    assert_unstrained(b)
    counters_match(rigid=1, deformable=0)


def stack_on_slope(youngA, rigidA, t_end=0.35):
    """A 1 m cube A on a fixed floor, a 1 m cube B on A, gravity tilted 30 deg along x (a slope).
    A's joints have 40 deg of friction (A holds on the floor: tan 40 > tan 30, locked), B's
    none (B slides on A). A's material has E = youngA; only its `rigid` flag changes between
    runs. Every contact stiffness is 40 x the smaller E x size of its pair: the floor's
    (1e10 Pa x 3.8 m) and B's (1e10 Pa x 1 m) whenever youngA >= 3.8e10 Pa, so the contacts are
    the same in both runs. Returns B's and A's final centroids and A's largest stress [Pa]."""
    O.reset()
    hard = material(O, young=1e10, frictionDeg=40)
    stiff = material(O, young=youngA, frictionDeg=40)
    slippery = material(O, young=1e10, frictionDeg=0)
    O.bodies.append(ddaBlock(box((-3, -3, -1), (6, 3, 0)), material=hard, fixed=True))
    a = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=stiff, rigid=rigidA))
    b = O.bodies.append(ddaBlock(box((0, 0, 1), (1, 1, 2)), material=slippery))
    slope = math.radians(30)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(G * math.sin(slope), 0, -G * math.cos(slope)),
                               maxDisplacement=0.005)]
    largest = 0.0
    for _ in range(int(round(t_end / 1e-3))):
        O.step()
        largest = max(largest, max(abs(x) for x in yade_dda.block(a).stress))
    return tuple(yade_dda.block(b).centroid), tuple(yade_dda.block(a).centroid), largest


def test_rigid_block_agrees_with_a_very_stiff_deformable_one(scene):
    """The same stack with A rigid and with A deformable, at E = 1e12 and 1e13 Pa.

    What differs is A's strain, at most sigma/E with sigma its largest stress
    (about the static (m_A + m_B) g cos(30) / 1 m^2 = 4.4e4 Pa; the load
    arrives at once): it moves A's top face, hence B, by at most
    sigma/E x L (L = 1 m), and A's elastic start-up, which the rigid block
    does not have, by as much again. So every centroid must agree within
    2 sigma_max / E x L: 7e-8 m at 1e12 Pa, 7e-9 m at 1e13 Pa (measured:
    0.42 and 0.44 of that). The difference must fall with 1/E: ten times
    stiffer, at least 3 times closer (it is 9.5). B slides frictionless on A
    by g sin(30) t^2/2 (1e-6 relative, the contacts settling; measured 1e-8),
    for 0.35 s, while its centroid is still above A.

    Sliding friction is left out here: its force uses the normal force of
    the solve before, which the open-close iteration settles only to 1e-4 of
    the largest normal force (doc/DESIGN.md), a difference of its own (about
    2e-8 m in this stack whatever E) that does not fall with 1/E."""
    differences = {}
    for young in (1e12, 1e13):
        rigidB, rigidA, rigidSigma = stack_on_slope(young, True)
        assert rigidSigma == 0.0
        expected = S.incline_slide_distance(math.radians(30), 0.0, O.time)
        assert abs((rigidB[0] - 0.5) - expected) < 1e-6 * expected
        stiffB, stiffA, sigma = stack_on_slope(young, False)
        difference = max(S.norm(S.sub(stiffB, rigidB)), S.norm(S.sub(stiffA, rigidA)))
        tolerance = 2 * sigma / young * 1.0
        assert 1e4 < sigma < 2e5, 'A carries the stack: %g Pa' % sigma
        assert difference < tolerance, 'E = %g Pa: %g m apart (tolerance %g m)' % (young, difference, tolerance)
        differences[young] = difference
    assert differences[1e13] < differences[1e12] / 3


def test_mixed_pile_of_rigid_and_deformable_blocks_is_stable(scene):
    """Eight 1 m cubes in two layers, every other one rigid, turned a little and dropped 1 cm
    onto a floor and onto each other: under the hard-case guards (hardguards.Guard: finite
    state, no overlap beyond the penalty tolerance, no energy gain, converged open-close
    iteration) every 300 steps; the rigid ones stay unstrained, and the counters show 6
    unknowns per rigid block in every step.

    Stacked equal cubes were the hard case of the open-close iteration: before cycling
    contacts were held closed (World::step, kHoldClosedFraction), 300 steps of this scene
    (cubes 5 cm apart, so that none overlaps another as it enters the scene) cut dt 38
    times with every other cube rigid, 34 all deformable, 40 all rigid; now 1, 1 and 3.
    The guard's default bound of 5% of the steps applies. (This scene also found the
    narrow-phase fault of edge entrances giving their crossing only: a cube rocking onto
    its neighbour sank 1.2 mm into it; test_contact_detection.cpp,
    EdgeEntranceAlsoGivesTheFarCornersWithinContactDistance.)"""
    rock = material(O, young=1e9, frictionDeg=30)
    floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (4, 4, 0)), material=rock, fixed=True))
    bodies, rigid = [floor], []
    k = 0
    for layer in range(2):
        for i in range(2):
            for j in range(2):
                lo = (1.05 * i + 0.01 * layer, 1.05 * j, 0.01 + 1.05 * layer)
                corners = rotate(box(lo, (lo[0] + 1, lo[1] + 1, lo[2] + 1)), (0.3, 0.5, 1.0), 0.02 * (k % 3 - 1),
                                 about=(lo[0] + 0.5, lo[1] + 0.5, lo[2] + 0.5))
                body = O.bodies.append(ddaBlock(corners, material=rock, rigid=(k % 2 == 0)))
                bodies.append(body)
                if k % 2 == 0:
                    rigid.append(body)
                k += 1
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.002)]
    O.step()
    guard = Guard(bodies, (0, 0, -G))
    guard.check()
    guard.run(299, every=lambda step: counters_match(rigid=4, deformable=4))
    for body in rigid:
        assert_unstrained(body)
    assert yade_dda.stats()['closedContacts'] > 0
    assert yade_dda.stats()['effects']['rigidBlocks'] == 4


def test_rigid_must_be_a_bool(scene):
    """rigid='yes', 1 or None are TypeErrors naming rigid; nothing is added."""
    for bad in ('yes', 1, None, 0.0):
        with pytest.raises(TypeError, match='rigid must be True or False'):
            ddaBlock(box((0, 0, 0), (1, 1, 1)), rigid=bad)
    assert len(O.bodies) == 0
    scene_ = yade_dda.scene.current(create=False)
    assert scene_ is None or not scene_.pending


def test_rigid_block_with_initial_stress_is_an_error_naming_it(scene):
    """A rigid block has no strain, so no stress: ddaBlock(rigid=True, stress=...) raises a
    ValueError that says so and adds nothing; a zero stress is accepted (no stress)."""
    rock = material(O)
    before = len(O.bodies)
    with pytest.raises(ValueError, match='rigid block .* carries no stress.*rigid=True'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock, rigid=True, stress=(-1e5, 0, 0, 0, 0, 0))
    assert len(O.bodies) == before
    scene_ = yade_dda.scene.current(create=False)
    assert scene_ is None or not scene_.pending
    b = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock, rigid=True, stress=(0, 0, 0, 0, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-3)]
    O.step()
    assert_unstrained(b)


def test_fixed_rigid_block_has_no_unknowns(scene):
    """rigid=True on a fixed block changes nothing: it has no unknowns and is not counted."""
    rock = material(O)
    O.bodies.append(ddaBlock(box((0, 0, -1), (4, 4, 0)), material=rock, fixed=True, rigid=True))
    O.bodies.append(ddaBlock(box((0, 0, 0.001), (1, 1, 1.001)), material=rock, rigid=True))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(20, True)
    counters_match(rigid=1, deformable=0)
