"""Start from rest (DDAIntegrator(startFromRest=True), the default), against
closed forms and static equilibrium (SI units).

Before the first step, blocks at rest that touch a fixed block (or carry fixed
points) are brought to static equilibrium with friction locked; the dynamics then
starts with loaded contacts and zero velocity. Oracles: the settled contacts carry
the block's weight (sum of normal forces = m g cos(slope), of shear forces = m g
sin(slope)); a block on an incline and a pushed block then follow Coulomb's closed
form whatever dt (with unloaded contacts the error grew as dt shrank: 6.5% at 1e-4
for the pushed block); a scene with nothing to settle runs bitwise as without the
settling; a scene with no equilibrium (a frictionless slope) starts as placed.
"""
import math

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator
from yade import wrapper

import scenes as S
from helpers import box

G = 9.81


def cube_on_floor(slope_deg=0.0, friction_deg=30.0, load=None, dt=1e-3, **engine):
    """A 1 m cube (2600 kg/m^3, E = 10 GPa) laid flush on a fixed floor, gravity
    tilted by slope_deg about y; optional point load (point, force) [m, N]."""
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e10, poisson=0.25,
                                                   frictionAngle=math.radians(friction_deg)))
    O.bodies.append(yade_dda.ddaBlock(box((-5, -2, -1), (20, 2, 0)), material=rock, fixed=True))
    cube = O.bodies.append(yade_dda.ddaBlock(box((0, -.5, 0), (1, .5, 1)), material=rock,
                                             loads=[load] if load else []))
    a = math.radians(slope_deg)
    O.engines = [DDAIntegrator(dt=dt, gravity=(G * math.sin(a), 0, -G * math.cos(a)), label='dda', **engine)]
    return cube


@pytest.mark.parametrize('slope', [0.0, 20.0])
def test_settled_contacts_carry_the_weight(scene, slope):
    """After the settling (first step) the cube's contacts carry its weight: the
    normal forces sum to m g cos(slope) and the shear forces to m g sin(slope)
    within 1e-6 (static equilibrium, friction locked at 30 deg > slope), and the
    cube has not moved by more than its contacts' compression (1e-6 m)."""
    cube = cube_on_floor(slope_deg=slope)
    O.run(1, True)
    s = yade_dda.stats()
    assert s['settleConverged'] and s['settledBlocks'] == 1 and s['settleSteps'] >= 1, s
    # Every static step makes at least one solve, and a pass is at least one.
    assert s['settleSolves'] >= s['settleSteps'] + s['settleLimitPasses'], s
    mass = yade_dda.block(cube).mass
    closed = yade_dda.contacts('closed')
    assert len(closed) == 4
    normal = sum(c.normalForce for c in closed)
    shear = sum(c.shearForce[0] for c in closed)  # on id1: the floor's side or the cube's
    a = math.radians(slope)
    assert abs(normal - mass * G * math.cos(a)) < 1e-6 * mass * G, (normal, mass * G * math.cos(a))
    assert abs(abs(shear) - mass * G * math.sin(a)) < 1e-6 * mass * G + 1e-9, (shear, mass * G * math.sin(a))


def test_settled_block_does_not_ring(scene):
    """A cube laid on a floor: with the settling it stays put (vertical speed below
    1e-9 m/s over 200 steps at dt 1e-4); as placed (startFromRest=False) it sinks
    into its unloaded springs and rings (speed above 1e-5 m/s), so the test tells."""
    speeds = {}
    for start in (True, False):
        O.reset()
        cube = cube_on_floor(dt=1e-4, startFromRest=start)
        fastest = 0.0
        for _ in range(20):
            O.run(10, True)
            fastest = max(fastest, abs(yade_dda.block(cube).velocity[2]))
        speeds[start] = fastest
    print(speeds)
    assert speeds[True] < 1e-9 and speeds[False] > 1e-5, speeds


@pytest.mark.parametrize('dt', [1e-2, 1e-3, 1e-4])
def test_pushed_block_follows_coulomb_whatever_dt(scene, dt):
    """Pushed at its centroid by 1.05 x its friction limit (30 deg), the cube accelerates
    at 0.05 mu g: its displacement between 0.1 s and 0.5 s is the closed form
    0.05 mu g (t2^2 - t1^2)/2 within 2% at every dt (measured +0.01%, +0.3%, +0.5%; as
    placed it was +0.1%, +0.9% and +6.5%), no step is cut (O.time reaches 0.5 s) and it
    moves less than 1e-9 m sideways (the set-up is symmetric in y)."""
    mu = math.tan(math.radians(30))
    cube = cube_on_floor(load=((0.5, 0.0, 0.5), (1.05 * mu * 2600 * G, 0, 0)), dt=dt)
    O.run(int(round(0.1 / dt)), True)
    t1, c1 = O.time, yade_dda.block(cube).centroid
    O.run(int(round(0.4 / dt)), True)
    t2, c2 = O.time, yade_dda.block(cube).centroid
    assert abs(t2 - 0.5) < 1e-9   # no step was cut
    expected = 0.5 * 0.05 * mu * G * (t2 ** 2 - t1 ** 2)
    print('dt', dt, 'relative error', (c2[0] - c1[0]) / expected - 1)
    assert abs((c2[0] - c1[0]) - expected) < 0.02 * expected, (c2[0] - c1[0], expected)
    assert abs(c2[1]) < 1e-9


@pytest.mark.parametrize('dt', [1e-3, 1e-4])
def test_incline_slide_follows_coulomb_whatever_dt(scene, dt):
    """A cube on a 30 deg incline with 20 deg friction slides g (sin a - tan phi cos a)
    t^2/2 in 0.5 s within 0.5% at dt 1e-3 and 1e-4 (measured 0.01% at both)."""
    geo, slab, block = S.build_incline(math.radians(30), (1.0, 1.0, 1.0), 20.0)
    O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), label='dda')]
    c0 = yade_dda.block(block).centroid
    O.run(int(round(0.5 / dt)), True)
    moved = S.norm(S.sub(yade_dda.block(block).centroid, c0))
    expected = S.incline_slide_distance(math.radians(30), math.radians(20), O.time)
    print('dt', dt, 'relative error', moved / expected - 1)
    assert abs(moved - expected) < 0.005 * expected, (moved, expected)


def test_nothing_to_settle_runs_bitwise_as_placed(scene):
    """Cubes falling from rest onto a floor, none touching at the start: the
    settling finds nothing (settleSteps 0) and the run is bitwise the one without
    it."""
    runs = {}
    for start in (True, False):
        O.reset()
        rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e9, poisson=0.25,
                                                       frictionAngle=math.radians(30)))
        O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (4, 4, 0)), material=rock, fixed=True))
        cubes = [O.bodies.append(yade_dda.ddaBlock(box((x, 0, 0.3 + x), (x + 1, 1, 1.3 + x)), material=rock))
                 for x in (0.0, 1.5)]
        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), startFromRest=start)]
        O.run(1, True)
        if start:
            s = yade_dda.stats()
            assert s['settleSteps'] == s['settleSolves'] == s['settleLimitPasses'] == 0, s
        O.run(400, True)
        runs[start] = [tuple(yade_dda.block(c).centroid) + tuple(yade_dda.block(c).velocity) for c in cubes]
    assert runs[True] == runs[False]


def test_block_without_equilibrium_starts_as_placed(scene):
    """A cube on a frictionless 20 deg slope has no static equilibrium: the
    settling gives up (settleConverged False) and the run is bitwise the one
    without it."""
    runs = {}
    for start in (True, False):
        O.reset()
        cube = cube_on_floor(slope_deg=20.0, friction_deg=0.0, startFromRest=start)
        O.run(1, True)
        if start:
            s = yade_dda.stats()
            assert not s['settleConverged'] and s['settledBlocks'] == 0, s
        O.run(100, True)
        runs[start] = tuple(yade_dda.block(cube).centroid) + tuple(yade_dda.block(cube).velocity)
    assert runs[True] == runs[False]


def test_settling_names_the_blocks_it_cannot_hold(scene):
    """stats()['unsettledBlocks']: beside a cube on a floor (held), a cube on a 30 deg
    incline with 20 deg of friction (must slide: the locked state is kept, the
    settling converged) and, in a second scene, a cube on a frictionless 20 deg slope
    (no equilibrium even locked: started as placed) are named; a held cube is not."""
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e10, poisson=0.25,
                                                   frictionAngle=math.radians(20)))
    a = math.radians(30)
    up = (math.cos(a), 0, math.sin(a))      # the incline's frame: x up the slope, normal (-sin a, 0, cos a)
    normal = (-math.sin(a), 0, math.cos(a))
    def on_incline(x0, sx, sz):
        return [tuple(x0[i] + u * up[i] + w * normal[i] for i in range(3)) for u in sx for w in sz]
    slab = [tuple(p[i] + y * (i == 1) for i in range(3)) for p in on_incline((0, 0, 0), (-6, 6), (-1, 0))
            for y in (-2, 2)]
    O.bodies.append(yade_dda.ddaBlock(slab, material=rock, fixed=True))
    cube = [tuple(p[i] + y * (i == 1) for i in range(3)) for p in on_incline((0, 0, 0), (0, 1), (0, 1))
            for y in (-0.5, 0.5)]
    sliding = O.bodies.append(yade_dda.ddaBlock(cube, material=rock))
    O.bodies.append(yade_dda.ddaBlock(box((20, -2, -1), (26, 2, 0)), material=rock, fixed=True))
    held = O.bodies.append(yade_dda.ddaBlock(box((22, -.5, 0), (23, .5, 1)), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
    O.run(1, True)
    s = yade_dda.stats()
    assert s['settleConverged'] and s['unsettledBlocks'] == [sliding], (s['settleConverged'], s['unsettledBlocks'])
    assert held not in s['unsettledBlocks']
    O.reset()
    cube = cube_on_floor(slope_deg=20.0, friction_deg=0.0)
    O.run(1, True)
    s = yade_dda.stats()
    assert not s['settleConverged'] and s['unsettledBlocks'] == [cube], s['unsettledBlocks']
    O.reset()
    cube = cube_on_floor()
    O.run(1, True)
    assert yade_dda.stats()['unsettledBlocks'] == []


def test_energy_account_starts_at_the_settled_state(scene):
    """The account starts after the settling: its contact term holds the settled
    springs' energy, N^2/(2 kn) + |S|^2/(2 ks) over the contacts (the deformable
    cube's base spreads by Poisson's effect and its locked corners hold it, so the
    shear springs carry some), at least the four corners' m g / 4 each; and over 1 s
    at rest the account's sum stays within 1e-6 of that energy."""
    cube = cube_on_floor()
    O.run(1, True)
    e = yade_dda.stats()['energy']
    mass = yade_dda.block(cube).mass
    kn = 40 * 1e10 * 1.0
    ks = 0.4 * kn
    springs = sum(c.normalForce ** 2 / (2 * kn) + sum(f * f for f in c.shearForce) / (2 * ks)
                  for c in yade_dda.contacts('closed'))
    assert abs(e['contact'] - springs) < 1e-6 * springs, (e['contact'], springs)
    assert springs >= 4 * 0.5 * (mass * G / 4) ** 2 / kn * (1 - 1e-6)
    start = dict(e)
    O.run(999, True)
    e = yade_dda.stats()['energy']
    total = lambda a: (a['kinetic'] + a['gravity'] + a['strain'] + a['contact'] + a['friction'] + a['damping']
                       - a['loads'] - a['contactChanges'])
    assert abs(total(e) - total(start)) < 1e-6 * springs + 1e-9, (e, start)


def test_settling_never_adds_energy(scene):
    """Each static step minimises the potential energy plus a positive inertia term
    with D = 0 admissible, so the settled state cannot hold more energy than the
    placed one: a stack of three deformable cubes (1, 0.8, 0.6 m) on a floor and a
    cube on a 20 deg slope (30 deg friction), E = 1 GPa; after the first step the
    kinetic + gravity + strain + contact energy is below its placed value (gravity
    alone: the placed springs are unloaded, the blocks unstressed and at rest)."""
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e9, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (6, 3, 0)), material=rock, fixed=True))
    stack, z = [], 0.0
    for side in (1.0, 0.8, 0.6):
        stack.append(O.bodies.append(yade_dda.ddaBlock(box((-side / 2, -side / 2, z), (side / 2, side / 2, z + side)),
                                                       material=rock)))
        z += side
    geo, slab, onSlope = S.build_incline(math.radians(20), (1.0, 1.0, 1.0), 30.0, origin=(0.0, 10.0, 0.0))
    blocks = stack + [onSlope]
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
    placed = sum(-yade_dda.block(b).mass * -G * yade_dda.block(b).centroid[2] for b in blocks)
    O.run(1, True)
    s = yade_dda.stats()
    assert s['settleConverged'] and s['settledBlocks'] == 4, s
    e = s['energy']
    settled = e['kinetic'] + e['gravity'] + e['strain'] + e['contact']
    print('placed', placed, 'settled', settled, 'difference', settled - placed)
    assert settled < placed + 1e-8, (settled, placed)
    assert e['strain'] > 0 and e['contact'] > 0   # the stack carries its weight


@pytest.mark.parametrize('penalty', [1.0, 40.0, 4000.0])
@pytest.mark.parametrize('rigid', [False, True], ids=['deformable', 'rigid'])
def test_settling_converges_whatever_the_stiffness_ratio(scene, penalty, rigid):
    """The static steps' inertia is sized by both the contacts' and the block's own
    stiffness, so a 10 GPa cube on a 30 deg slope (20 deg friction) settles in a few
    steps whether its contacts are 1 or 4000 times stiffer than E x size (sized by
    the contacts alone, a deformable block at penalty 1000 did not settle in 12
    steps: its strain modes were held back by inertia as large as their stiffness).
    The cube must slide (tan 20 deg < tan 30 deg), so the friction stage gives up on it
    once two static steps in a row repeat the move before: at most 6 locked steps, the
    5 steps of the friction ramp and 3 at the true friction, the cube named as unsettled."""
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e10, poisson=0.25,
                                                   frictionAngle=math.radians(20)))
    O.bodies.append(yade_dda.ddaBlock(box((-1, -1.5, -1), (5, 1.5, 0)), material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((-.5, -.5, 0), (.5, .5, 1)), material=rock, rigid=rigid))
    O.engines = [DDAIntegrator(dt=1e-4, gravity=(G * 0.5, 0, -G * math.sqrt(0.75)), contactPenaltyFactor=penalty,
                               maxDisplacement=0.01)]
    O.run(1, True)
    s = yade_dda.stats()
    assert s['settleConverged'] and s['settleSteps'] <= 6 + 5 + 3, s
    assert list(s['unsettledBlocks']) == [1], s['unsettledBlocks']


def test_blocks_in_flight_keep_their_motion_while_others_settle(scene):
    """A cube resting on a floor settles while a cube thrown elsewhere at (2, 0, 3)
    m/s does not: the thrown cube's flight is bitwise the one without the settling
    (it touches nothing, so no step of the resting cube may change it), and its
    velocity after 100 steps is v0 + g t to round-off."""
    runs = {}
    for start in (True, False):
        O.reset()
        rest = cube_on_floor(startFromRest=start)
        rock = O.materials[0]
        thrown = O.bodies.append(yade_dda.ddaBlock(box((10, -0.5, 5), (11, 0.5, 6)), material=rock,
                                                   velocity=(2, 0, 3)))
        O.run(100, True)
        if start:
            assert yade_dda.stats()['settledBlocks'] == 1  # the resting cube (every step reports the settling)
        b = yade_dda.block(thrown)
        runs[start] = tuple(b.centroid) + tuple(b.velocity)
        assert abs(b.velocity[0] - 2) < 1e-12 and abs(b.velocity[2] - (3 - G * O.time)) < 1e-9, b.velocity
    assert runs[True] == runs[False]


def test_a_frictionless_scene_makes_no_friction_ramp(scene):
    """The settling releases locked friction in five static steps (friction x 100, 10, 3,
    1.5, 1.2) before the true friction; a scene whose contacts have no friction has
    nothing to release and makes none of them: a cube settling on a floor takes exactly
    five static steps more with 30 deg of friction than without (both settle on a flat
    floor the same way)."""
    steps = {}
    for phi in (0.0, 30.0):
        O.reset()
        S.build_resting_block(frictionDeg=phi)
        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
        O.run(1, True)
        s = yade_dda.stats()
        assert s['settleConverged'] and not s['unsettledBlocks'], s
        steps[phi] = s['settleSteps']
    assert steps[30.0] == steps[0.0] + 5, steps
