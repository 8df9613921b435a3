"""Concave blocks (concaveBlock): convex parts with one set of unknowns, shown in YADE as a clump.

Oracles: the closed-form volume, centroid and inertia of an L of three unit
cubes; exact free fall and spin of the clump and its members (no contact
between the parts); a cube dropped into the L's inner corner, whose contacts
and O.interactions are with the foot's member only, carried by the momentum
balance; the energy account; save and load continuing bitwise; the clump's
and members' states against the core; refusals naming the problem. SI units.
"""
import math
import random

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock, concaveBlock
from yade import wrapper

from helpers import box, material, rotate

G = 9.81


def cube(lo, size=1.0):
    return box(lo, tuple(x + size for x in lo))


def l_parts(origin=(0.0, 0.0, 0.0)):
    """An L of three unit cubes: (0, 0), (1, 0) and (0, 1) in x and y, 1 m thick."""
    ox, oy, oz = origin
    return [cube((ox, oy, oz)), cube((ox + 1, oy, oz)), cube((ox, oy + 1, oz))]


L_CENTROID = (2.5 / 3, 2.5 / 3, 0.5)


def l_second_moment():
    """Integral of (x-c)(x-c)^T over the L [m^5]: each cube's I/12 plus its offset's outer product."""
    J = [[0.0] * 3 for _ in range(3)]
    for centre in ((0.5, 0.5, 0.5), (1.5, 0.5, 0.5), (0.5, 1.5, 0.5)):
        d = [centre[i] - L_CENTROID[i] for i in range(3)]
        for i in range(3):
            for j in range(3):
                J[i][j] += d[i] * d[j] + (1.0 / 12 if i == j else 0.0)
    return J


def test_an_l_is_one_block_with_exact_mass_properties(scene):
    rock = material(O, young=1e9)
    clumpId, members = O.bodies.appendClumped(concaveBlock(l_parts(), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3)]
    O.step()
    blk = yade_dda.block(clumpId)
    assert blk.partCount == 3 and len(blk.parts) == 3
    assert blk.volume == pytest.approx(3.0, abs=1e-14)
    assert blk.mass == pytest.approx(3 * 2600, abs=1e-9)
    assert max(abs(blk.centroid[i] - L_CENTROID[i]) for i in range(3)) < 1e-14
    J = l_second_moment()
    assert max(abs(blk.secondMoment[i, j] - J[i][j]) for i in range(3) for j in range(3)) < 1e-14
    # Every member shows the same block; the clump sits at its centroid.
    for member in members:
        assert yade_dda.blockOf(member) == yade_dda.blockOf(clumpId)
        assert yade_dda.block(member).volume == blk.volume
    assert max(abs(O.bodies[clumpId].state.pos[i] - L_CENTROID[i]) for i in range(3)) < 1e-14
    assert len(blk.vertices) == 24 and len(blk.faces) == 18


@pytest.mark.parametrize('rigid', [True, False])
def test_a_concave_block_falls_and_spins_exactly(scene, rigid):
    """Thrown with v0 (and, rigid, spun with w0 about a principal axis: z for the L) under gravity: the
    clump's position is c0 + v0 t + g t^2 / 2 to 1e-12, each member's its part's centroid turned with
    the block, and no contact between the parts ever forms."""
    rock = material(O, young=1e9)
    v0 = (1.5, -0.5, 4.0)
    w0 = (0.0, 0.0, 2.0) if rigid else (0.0, 0.0, 0.0)
    clumpId, members = O.bodies.appendClumped(concaveBlock(l_parts((0, 0, 10)), material=rock, rigid=rigid,
                                                           velocity=v0, angularVelocity=w0))
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), maxDisplacement=1.0)]
    O.step()
    c0 = tuple(O.bodies[clumpId].state.pos)
    t0 = O.time
    starts = [tuple(O.bodies[m].state.pos) for m in members]
    O.run(200, True)
    t = O.time - t0
    assert yade_dda.stats()['contacts'] == 0 and len(O.interactions) == 0
    v1 = [v0[i] + (-G if i == 2 else 0.0) * t0 for i in range(3)]
    expected = [c0[i] + v1[i] * t + (-G if i == 2 else 0.0) * t * t / 2 for i in range(3)]
    pos = O.bodies[clumpId].state.pos
    assert max(abs(pos[i] - expected[i]) for i in range(3)) < 1e-12 * math.sqrt(sum(e * e for e in expected))
    angle = w0[2] * t
    for member, start in zip(members, starts):
        d = [start[i] - c0[i] for i in range(3)]
        turned = rotate([d], (0, 0, 1), angle)[0] if rigid else d
        want = [expected[i] + turned[i] for i in range(3)]
        got = O.bodies[member].state.pos
        assert max(abs(got[i] - want[i]) for i in range(3)) < 1e-9, (member, got, want)
        assert tuple(O.bodies[member].state.angVel) == pytest.approx(w0, abs=1e-12)


def corner_scene(collider='MSC'):
    """A fixed floor, an L standing on it in the x-z plane (foot [1,2] x [0,1] x [0,1], wall [0,1] x [0,1] x [1,2])
    and a 0.5 m cube dropped 5 cm into the inner corner, 1 mm off the wall."""
    rock = material(O, young=1e9, frictionDeg=30)
    floor = O.bodies.append(ddaBlock(box((-2, -1.5, -1), (4, 2.5, 0)), material=rock, fixed=True))
    clumpId, members = O.bodies.appendClumped(concaveBlock(
        [cube((0, 0, 0)), cube((1, 0, 0)), cube((0, 0, 1))], material=rock))
    c = O.bodies.append(ddaBlock(box((1.001, 0.25, 1.05), (1.501, 0.75, 1.55)), material=rock))
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), collider=collider)]
    return floor, clumpId, members, c


def test_a_cube_in_the_inner_corner_rests_on_the_foot(scene):
    """The cube comes to rest on the foot (the L's inner horizontal face), not on the wall 1 mm away nor on
    the faces the parts share: every closed contact and every interaction of the cube is with the foot's
    member. Momentum: over the last 0.5 s the contacts' impulse on the cube is its weight's plus its
    momentum change (0.5 %). Energy: the account balances (1e-3 of the gravity change)."""
    floor, clumpId, members, c = corner_scene()
    foot = members[1]
    O.run(500, True)
    start = yade_dda.stats()['energy']
    vz0, t0, impulse = O.bodies[c].state.vel[2], O.time, 0.0
    for _ in range(250):
        O.step()
        dt = yade_dda.stats()['dt']
        for contact in yade_dda.contacts('closed'):
            if c in (contact.id1, contact.id2):
                assert set((contact.id1, contact.id2)) == {c, foot}, contact
                impulse += dt * (contact.force[2] if contact.id1 == c else -contact.force[2])
    T = O.time - t0
    mass = yade_dda.block(c).mass
    assert impulse == pytest.approx(mass * G * T + mass * (O.bodies[c].state.vel[2] - vz0), rel=5e-3)
    pairs = {(i.id1, i.id2) for i in O.interactions if i.isReal}
    assert (min(c, foot), max(c, foot)) in pairs
    assert all(c not in p or foot in p for p in pairs), pairs
    # The narrow phase as a functor on the members: the foot touches the cube, the wall's part does not.
    functor = yade_dda.Ig2_DDABlock_DDABlock_DDAContact()
    assert functor.go(foot, c, 0.01)['contacts'] and functor.go(members[2], c, 1e-4) is None
    assert abs(O.bodies[c].state.pos[2] - 1.25) < 2e-4
    end = yade_dda.stats()['energy']
    account = lambda e: (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping']
                         - e['loads'] - e['contactChanges'])
    assert abs(account(end) - account(start)) < 1e-3 * max(abs(end[k] - start[k]) for k in end)


@pytest.mark.parametrize('rigid', [True, False])
def test_an_l_slides_down_a_slope_at_the_closed_form_rate(scene, rigid):
    """The L of three cubes lying flat on a level floor, gravity tilted 30 degrees (a slope), joint friction
    20 degrees: it slides at a = g (sin 30 - tan 20 cos 30) (1 %), its seams (corners of two parts at one
    place, faces the parts share) adding no force: no rotation (1e-6 rad/s) and no sideways drift. The
    energy account balances."""
    rock = material(O, young=1e9, frictionDeg=20)
    O.bodies.append(ddaBlock(box((-2, -2, -1), (12, 4, 0)), material=rock, fixed=True))
    clumpId, members = O.bodies.appendClumped(concaveBlock(l_parts(), material=rock, rigid=rigid))
    theta = math.radians(30)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(G * math.sin(theta), 0, -G * math.cos(theta)))]
    O.run(50, True)
    start = yade_dda.stats()['energy']
    t0, x0, v0 = O.time, O.bodies[clumpId].state.pos[0], O.bodies[clumpId].state.vel[0]
    y0 = O.bodies[clumpId].state.pos[1]
    O.run(400, True)
    t = O.time - t0
    x = O.bodies[clumpId].state.pos[0]
    a = 2 * (x - x0 - v0 * t) / t ** 2
    expected = G * (math.sin(theta) - math.tan(math.radians(20)) * math.cos(theta))
    print('rigid %s: a = %.5f m/s^2, closed form %.5f' % (rigid, a, expected))
    assert a == pytest.approx(expected, rel=0.01)
    assert abs(O.bodies[clumpId].state.pos[1] - y0) < 1e-6
    assert max(abs(w) for w in O.bodies[clumpId].state.angVel) < 1e-6
    end = yade_dda.stats()['energy']
    account = lambda e: (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping']
                         - e['loads'] - e['contactChanges'])
    assert abs(account(end) - account(start)) < 1e-3 * max(abs(end[k] - start[k]) for k in end)


def test_a_cube_slides_across_the_seam_of_a_concave_slab_without_feeling_it(scene):
    """A free slab of two parts side by side (its seam, a face the parts share, across the path) lying on
    a floor, and a 0.5 m cube sliding over it at 1 m/s, frictionless, under gravity: crossing the seam
    neither slows the cube (its speed kept to 1e-3) nor pushes the slab (1e-3 m/s), and no contact is
    ever made on the shared face (every closed contact of the cube is on the slab's top faces, normal z)."""
    rock = material(O, young=1e9, frictionDeg=0)
    O.bodies.append(ddaBlock(box((-3, -2, -1), (7, 3, 0)), material=rock, fixed=True))
    clumpId, members = O.bodies.appendClumped(concaveBlock([box((0, 0, 0), (2, 1, 0.5)), box((2, 0, 0), (4, 1, 0.5))],
                                                           material=rock))
    c = O.bodies.append(ddaBlock(box((1.0, 0.25, 0.5), (1.5, 0.75, 1.0)), material=rock, velocity=(1, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), newmarkGamma=0.5, newmarkBeta=0.25)]
    while O.bodies[c].state.pos[0] < 3.0:
        O.step()
        for contact in yade_dda.contacts('closed'):
            if c in (contact.id1, contact.id2):
                assert abs(contact.normal[2]) > 1 - 1e-6, contact
        assert O.time < 3
    assert O.bodies[c].state.vel[0] == pytest.approx(1.0, abs=1e-3)
    assert abs(O.bodies[clumpId].state.vel[0]) < 1e-3


def test_a_concave_scene_continues_bitwise_after_save_and_load(scene, tmp_path):
    corner_scene()
    O.run(100, True)
    path = str(tmp_path / 'concave.yade.gz')
    O.save(path)
    O.run(100, True)
    ids = range(len(O.bodies))
    after = [(tuple(O.bodies[i].state.pos), tuple(O.bodies[i].state.vel)) for i in ids]
    O.load(path)
    O.engines = O.engines   # as loaded
    O.run(100, True)
    assert [(tuple(O.bodies[i].state.pos), tuple(O.bodies[i].state.vel)) for i in ids] == after


def test_bad_parts_are_refused_naming_the_problem(scene):
    rock = material(O)
    with pytest.raises(ValueError, match='overlap'):
        concaveBlock([cube((0, 0, 0)), cube((0.5, 0, 0))], material=rock)
    with pytest.raises(ValueError, match='shares no face'):
        concaveBlock([cube((0, 0, 0)), cube((2, 0, 0))], material=rock)
    with pytest.raises(ValueError, match='part 1'):
        concaveBlock([cube((0, 0, 0)), cube((1, 0, 0)) + [(1.5, 0.5, 0.5)]], material=rock)
    with pytest.raises(ValueError, match='part 0: point 0 must have 3 coordinates'):
        concaveBlock([[(0, 0)]], material=rock)
    assert len(O.bodies) == 0
    # Members appended one by one, not as a clump: refused at the first step, naming appendClumped.
    O.bodies.append(concaveBlock(l_parts(), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3)]
    with pytest.raises(ValueError, match='appendClumped'):   # the step's own exception, not YADE's RuntimeError
        O.step()


def test_stats_and_print_stats_count_blocks_not_parts(scene, capsys):
    """printStats() said "16/70 moving blocks" for 28 blocks: stats()['blocks'] counted a concave block's
    parts. It counts DDA blocks (as movingBlocks and fixedBlocks do); stats()['parts'] counts the parts."""
    rock = material(O)
    O.bodies.append(ddaBlock(box((-5, -5, -2), (5, 5, -1)), material=rock, fixed=True))
    O.bodies.appendClumped(concaveBlock(l_parts(), material=rock))
    O.bodies.appendClumped(concaveBlock(l_parts((3.0, 0.0, 0.0)), material=rock))
    O.bodies.append(ddaBlock(cube((-3.0, 0.0, 0.0)), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.step()
    s = yade_dda.stats()
    assert (s['blocks'], s['movingBlocks'], s['fixedBlocks'], s['parts']) == (4, 3, 1, 8)
    assert s['unknowns'] == 12 * 3
    yade_dda.printStats()
    assert '3/4 moving blocks (8 parts)' in capsys.readouterr().out


def test_staggered_bricks_are_split_so_that_shared_faces_match(scene):
    """Two bricks staggered by half a length share half of each top/bottom face: the upper is split along
    the lower's end face, so the block has three parts (three members), the volume of the two bricks and
    the centroid of the two (closed form), and falls as one body."""
    rock = material(O, young=1e9)
    clumpId, members = O.bodies.appendClumped(concaveBlock([box((0, 0, 0), (2, 1, 1)), box((1, 0, 1), (3, 1, 2))],
                                                           material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(10, True)
    blk = yade_dda.block(clumpId)
    assert blk.partCount == 3 and len(members) == 3
    assert blk.volume == pytest.approx(4.0, abs=1e-13)
    assert yade_dda.stats()['contacts'] == 0
    expected = (1.5, 0.5, 1.0 - 0.5 * G * O.time ** 2)   # centroid of the two bricks, in free fall
    assert max(abs(blk.centroid[i] - expected[i]) for i in range(3)) < 1e-9


def l_prism_surface(height=1.0):
    """The closed surface of the L prism over (0,0) (2,0) (2,1) (1,1) (1,2) (0,2): points and triangles."""
    polygon = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    n = len(polygon)
    points = [(x, y, 0.0) for x, y in polygon] + [(x, y, height) for x, y in polygon] + [(0.5, 0.5, 0.0),
                                                                                      (0.5, 0.5, height)]
    triangles = []
    for k in range(n):
        a, b = k, (k + 1) % n
        triangles += [(a, b, n + b), (a, n + b, n + a), (2 * n, b, a), (2 * n + 1, n + a, n + b)]
    return points, triangles


def test_a_closed_l_surface_is_split_into_convex_parts(scene):
    """concaveBlock(surface=...) on the L prism's 24 triangles (given inside out, to check the orientation is
    fixed): CGAL's decomposition gives the L's volume, centroid and inertia (closed form, 1e-12), and the
    block falls as one body. An open surface is refused by name."""
    rock = material(O, young=1e9)
    points, triangles = l_prism_surface()
    inverted = [(c, b, a) for a, b, c in triangles]
    clumpId, members = O.bodies.appendClumped(concaveBlock(surface=(points, inverted), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3)]
    O.step()
    blk = yade_dda.block(clumpId)
    assert blk.partCount >= 2 and len(members) == blk.partCount
    assert blk.volume == pytest.approx(3.0, abs=1e-12)
    assert max(abs(blk.centroid[i] - L_CENTROID[i]) for i in range(3)) < 1e-12
    J = l_second_moment()
    assert max(abs(blk.secondMoment[i, j] - J[i][j]) for i in range(3) for j in range(3)) < 1e-12
    with pytest.raises(ValueError, match='open'):
        concaveBlock(surface=(points, triangles[1:]), material=rock)
    with pytest.raises(TypeError, match='exactly one'):
        concaveBlock(l_parts(), surface=(points, triangles), material=rock)


def test_random_concave_pile_keeps_the_account_and_interactions_between_members(scene):
    """Random turned L's and T's (seed printed), some rigid, dropped on a floor with 30 degrees friction for
    1 s: the energy account balances, no interaction joins two members of one clump, and every
    interaction is between bodies that have a closed contact."""
    seed = 2026
    print('seed', seed)
    rng = random.Random(seed)
    rock = material(O, young=1e8, frictionDeg=30)
    O.bodies.append(ddaBlock(box((-1, -1, -1), (9, 9, 0)), material=rock, fixed=True))
    clumps = {}
    for k in range(8):
        centre = (2 + 4 * (k % 2) + 0.3 * rng.random(), 2 + 4 * (k // 2 % 2) + 0.3 * rng.random(),
                  2 + 3.6 * (k // 4) + 0.3 * rng.random())
        axis, angle = (rng.random() - 0.5, rng.random() - 0.5, rng.random() - 0.5), 6.3 * rng.random()
        offsets = [(0, 0, 0), (1, 0, 0), (0, 1, 0)] + ([(-1, 0, 0)] if k % 2 else [])
        parts = [rotate(box(tuple(o[i] - 0.5 for i in range(3)), tuple(o[i] + 0.5 for i in range(3))), axis, angle)
                 for o in offsets]
        parts = [[tuple(p[i] + centre[i] for i in range(3)) for p in part] for part in parts]
        clumpId, members = O.bodies.appendClumped(concaveBlock(parts, material=rock, rigid=k % 3 == 0))
        clumps[clumpId] = set(members)
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), newmarkGamma=0.5, newmarkBeta=0.25)]
    O.step()
    start = yade_dda.stats()['energy']
    touched = set()
    for _ in range(500):
        O.step()
        closed = {tuple(sorted((c.id1, c.id2))) for c in yade_dda.contacts('closed')}
        touched |= closed
        for i in O.interactions:
            if not i.isReal:
                continue
            assert not any({i.id1, i.id2} <= members for members in clumps.values())
            assert (i.id1, i.id2) in closed
    end = yade_dda.stats()['energy']
    account = lambda e: (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping']
                         - e['loads'] - e['contactChanges'])
    assert abs(account(end) - account(start)) < 1e-3 * abs(end['gravity'] - start['gravity'])
    clumpOf = {m: c for c, members in clumps.items() for m in members}
    landed = {clumpOf[i] for pair in touched for i in pair if i in clumpOf}
    assert len(landed) == len(clumps), 'blocks that never touched anything: %s' % (set(clumps) - landed)
