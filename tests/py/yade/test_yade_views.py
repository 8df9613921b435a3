"""What YADE sees of a DDA scene: O.interactions, O.forces, O.energy (yade_dda/views.py).

Oracles: the contact pairs of yade_dda.contacts(), the stack's weight, the
sub-contacts' forces, the energy account of stats(), YADE's own meaning of
O.forces (a sphere under NewtonIntegrator), and the DDA motion itself (bitwise
the same whether YADE's views are kept or not).
"""
import hashlib
import math

import pytest

import yade_dda
from yade import utils, wrapper
from yade_dda import O
from yade_dda import views

from helpers import box, material

G = 9.81
WEIGHT = 2600.0 * G   # a 1 m cube of density 2600 kg/m^3 [N]


@pytest.fixture(autouse=True)
def _fresh(scene):
    views.setEnabled(True)
    yield
    views.setEnabled(True)


def _stack(n=5, young=1e10, friction=30, **engine):
    """n 1 m cubes standing on a fixed floor (body 0), touching: start from rest settles them."""
    rock = material(O, young=young, frictionDeg=friction)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    for k in range(n):
        O.bodies.append(yade_dda.ddaBlock(box((0, 0, k), (1, 1, k + 1)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda', **engine)]


def _closedPairs():
    return {(min(c.id1, c.id2), max(c.id1, c.id2)) for c in yade_dda.contacts('closed')}


def _realPairs():
    return {(i.id1, i.id2) for i in O.interactions if i.isReal}


def test_settled_stack_interactions_forces_energy():
    _stack()
    O.trackEnergy = True
    O.run(1000, True)   # 1 s
    pairs = _closedPairs()
    assert pairs == {(k, k + 1) for k in range(5)}
    assert _realPairs() == pairs
    assert len(O.interactions) == O.interactions.countReal() == len(pairs)
    for i in O.interactions:
        assert isinstance(i.geom, wrapper.PolyhedraGeom) and isinstance(i.phys, wrapper.PolyhedraPhys)
    # The floor carries the stack: normal force from id1 (floor) to id2 equals the weight.
    floor = O.interactions[0, 1]
    assert floor.geom.normal.dot((0, 0, 1)) > 1 - 1e-12
    assert floor.phys.normalForce.dot(floor.geom.normal) == pytest.approx(5 * WEIGHT, rel=0.02)
    # Each interaction's normal force is the sum of its sub-contacts' (they share the normal here).
    for i in O.interactions:
        subs = [c for c in yade_dda.contacts('closed') if {c.id1, c.id2} == {i.id1, i.id2}]
        assert len(subs) >= 3
        total = sum(c.normalForce for c in subs)
        assert i.phys.normalForce.norm() == pytest.approx(total, rel=1e-12)
        assert abs(i.phys.shearForce.dot(i.geom.normal)) <= 1e-9 * total
        # the force on id2 is normalForce + shearForce: the sub-contacts' forces on id2
        onId2 = subs[0].force * 0
        for c in subs:
            onId2 += c.force * (1 if c.id1 == i.id2 else -1)
        assert (i.phys.normalForce + i.phys.shearForce - onId2).norm() <= 1e-12 * total
    # O.forces of a resting block: its contact resultant, +m g up (gravity is not in O.forces, as for spheres).
    for k in range(1, 6):
        assert O.forces.f(k) == pytest.approx((0, 0, WEIGHT), abs=0.02 * WEIGHT)
    assert O.forces.f(0)[2] == pytest.approx(-5 * WEIGHT, rel=0.02)   # the floor's reaction
    assert utils.unbalancedForce() < 0.05
    # O.energy is the core's account, signed so that total() is the conserved balance.
    account = yade_dda.stats()['energy']
    energy = dict(O.energy.items())
    assert set(energy) == {name for _, name, _ in views.ENERGY_NAMES}
    for key, name, sign in views.ENERGY_NAMES:
        assert energy[name] == sign * account[key]
    balance = sum(account[k] for k in ('kinetic', 'gravityChange', 'strain', 'contact', 'friction', 'damping')) \
        - account['loads'] - account['contactChanges']
    assert O.energy.total() == pytest.approx(balance, rel=1e-12)


def test_energy_total_is_conserved_while_blocks_fall_and_land():
    rock = material(O, young=1e9, frictionDeg=20)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0.3), (1, 1, 1.3)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
    O.trackEnergy = True
    O.step()
    start = O.energy.total()
    O.run(500, True)
    assert O.energy['ddaDamping'] > 0   # it landed
    assert O.energy.total() == pytest.approx(start, abs=1e-3 * 2600 * G * 0.3)   # 1e-3 of m g h


def test_energy_gravity_is_measured_from_where_the_blocks_were_made(tmp_path):
    """O.energy's gravity is the work gravity did since the blocks were made,
    as YADE's gravWork: a block released from rest 2 m above the floor reads
    -m g (z0 - z) in free fall (closed form, z from the body), and total()
    starts at 0 instead of the absolute potential m g z (5.2e4 J here). A save
    and load keeps the origin."""
    rock = material(O, young=1e9)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    falling = O.bodies.append(yade_dda.ddaBlock(box((0, 0, 2), (1, 1, 3)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.trackEnergy = True
    mass = O.bodies[falling].state.mass
    O.run(100, True)
    drop = 2.5 - O.bodies[falling].state.pos[2]
    assert drop == pytest.approx(0.5 * G * 0.1 ** 2, rel=1e-6)
    assert O.energy['ddaGravity'] == pytest.approx(-mass * G * drop, rel=1e-9)
    assert yade_dda.stats()['energy']['gravity'] == pytest.approx(mass * G * (2.5 - drop), rel=1e-12)
    assert abs(O.energy.total()) < 1e-9 * mass * G * drop
    path = str(tmp_path / 'falling.yade')
    O.save(path)
    O.load(path)
    O.run(50, True)
    assert O.energy['ddaGravity'] == pytest.approx(-mass * G * (2.5 - O.bodies[falling].state.pos[2]), rel=1e-9)


def test_free_fall_force_is_what_yade_gives_a_sphere():
    """A free-falling sphere under NewtonIntegrator has O.forces.f = 0 (YADE adds gravity to the
    acceleration, not to O.forces); so has a free-falling DDA block, while the contact pairs of
    its neighbours still show."""
    rock = material(O, young=1e9)
    block = O.bodies.append(yade_dda.ddaBlock(box((0, 0, 10), (1, 1, 11)), material=rock, mask=2))
    sphere = O.bodies.append(utils.sphere((5, 0, 10), 0.5, mask=1))
    O.engines = [wrapper.ForceResetter(), wrapper.NewtonIntegrator(gravity=(0, 0, -G), mask=1),
                 yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]
    O.dt = 1e-3
    O.run(100, True)
    assert O.bodies[sphere].state.vel[2] < -0.5   # both fall (O.dt is DDA's adaptive step)
    assert O.bodies[block].state.vel[2] < -0.5
    assert tuple(O.forces.f(sphere)) == (0, 0, 0)
    assert tuple(O.forces.f(block)) == (0, 0, 0)
    assert tuple(O.forces.t(block)) == (0, 0, 0)
    assert len(O.interactions) == 0


def test_separated_blocks_have_no_interaction_and_thrown_block_loses_it():
    _stack(n=2)
    rock = O.bodies[1].material
    O.bodies.append(yade_dda.ddaBlock(box((2, 0, 0.5), (3, 1, 1.5)), material=rock, fixed=True))   # apart, fixed
    O.bodies.append(yade_dda.ddaBlock(box((-2.5, 0, 0), (-1.5, 1, 1)), material=rock))   # on the floor
    O.run(100, True)
    assert _realPairs() == _closedPairs() == {(0, 1), (1, 2), (0, 4)}
    assert not O.interactions.has(0, 3) and not O.interactions.has(1, 3) and not O.interactions.has(2, 3)
    # Throw the top block up: its interaction goes at the next sync.
    yade_dda.setVelocity(2, (0, 0, 5))
    O.run(50, True)
    assert O.bodies[2].state.pos[2] > 1.6   # its bottom 0.1 m above block 1
    assert _realPairs() == _closedPairs() == {(0, 1), (0, 4)}
    assert not O.interactions.has(1, 2)   # erased, not left as a virtual interaction
    assert len(O.interactions) == 2
    assert tuple(O.forces.f(2)) == (0, 0, 0)
    # ... and comes back when it lands again.
    O.run(1500, True)
    assert (1, 2) in _closedPairs() and _realPairs() == _closedPairs()


def _sphereOnWall(withDDA, polyhedraFunctor=False):
    """A YADE sphere on a YADE wall, beside a DDA block on a floor when withDDA; polyhedraFunctor: YADE's
    InteractionLoop also has a geometry functor for Polyhedra (masks keep YADE's collider off the blocks)."""
    if withDDA:
        rock = material(O, young=1e10)
        O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True, mask=2))
        O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock, mask=2))
    soft = O.materials.append(wrapper.FrictMat(young=1e7, density=1000))
    wall = O.bodies.append(utils.wall(-5, axis=2, mask=1, material=soft))
    sphere = O.bodies.append(utils.sphere((10, 0, -4.5), 0.5, mask=1, material=soft))
    O.engines = [wrapper.ForceResetter(), wrapper.InsertionSortCollider([wrapper.Bo1_Sphere_Aabb(), wrapper.Bo1_Wall_Aabb()]),
                 wrapper.InteractionLoop([wrapper.Ig2_Wall_Sphere_ScGeom()] +
                                         ([wrapper.Ig2_Polyhedra_Polyhedra_PolyhedraGeom()] if polyhedraFunctor else []),
                                         [wrapper.Ip2_FrictMat_FrictMat_FrictPhys()],
                                         [wrapper.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 wrapper.NewtonIntegrator(gravity=(0, 0, -G), mask=1, damping=0.4)]
    if withDDA:
        O.engines = O.engines + [yade_dda.DDAIntegrator(dt=1e-4, gravity=(0, 0, -G), label='dda')]
    O.dt = 1e-4
    O.run(2000, True)
    return wall, sphere


def test_mixed_scene_keeps_yade_forces():
    """A YADE sphere resting on a YADE wall beside a DDA block: its interaction and O.forces are
    YADE's, bitwise those of the same YADE scene without DDA; the DDA pair is in O.interactions too,
    real, with DDA's geometry and forces (YADE's InteractionLoop, with no functor for Polyhedra, leaves
    it alone), and the block's force is in O.forces."""
    wall, sphere = _sphereOnWall(True)
    assert _realPairs() == {(wall, sphere), (0, 1)}
    dda = O.interactions[0, 1]
    assert type(dda.geom) is wrapper.PolyhedraGeom and type(dda.phys) is wrapper.PolyhedraPhys
    assert dda.phys.normalForce[2] == pytest.approx(WEIGHT, rel=1e-3)   # the force on id2, the block
    i = O.interactions[wall, sphere]
    assert type(i.phys) is wrapper.FrictPhys
    assert O.forces.f(sphere)[2] > 0   # the wall pushes it (it is still bouncing a little)
    assert O.forces.f(1) == pytest.approx((0, 0, WEIGHT), rel=1e-3)
    force, torque, pos = tuple(O.forces.f(sphere)), tuple(O.forces.t(sphere)), tuple(O.bodies[sphere].state.pos)
    O.reset()
    wall, sphere = _sphereOnWall(False)
    assert (tuple(O.forces.f(sphere)), tuple(O.forces.t(sphere)), tuple(O.bodies[sphere].state.pos)) == (force, torque, pos)


def test_a_yade_loop_with_a_polyhedra_functor_keeps_no_dda_interactions():
    """The same mixed scene with a Polyhedra geometry functor in YADE's InteractionLoop: it would compute
    YADE's own contact on a DDA pair put into O.interactions, so none is kept; the block's force is still
    in O.forces."""
    wall, sphere = _sphereOnWall(True, polyhedraFunctor=True)
    assert _realPairs() == {(wall, sphere)}
    assert O.forces.f(1) == pytest.approx((0, 0, WEIGHT), rel=1e-3)


def _fingerprint():
    digest = hashlib.sha256(('%d %s' % (O.iter, float(O.time).hex())).encode())
    for body in O.bodies:
        index = yade_dda.blockOf(body.id)
        if index is None:
            continue
        b = yade_dda.block(body.id)
        for v in b.vertices:
            digest.update(' '.join(float(x).hex() for x in v).encode())
        digest.update(' '.join(float(x).hex() for x in b.velocity).encode())
    return digest.hexdigest()


def _run_pile(keep):
    views.setEnabled(keep)
    rock = material(O, young=1e9, frictionDeg=25)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    for k in range(4):
        x = 0.3 * k
        O.bodies.append(yade_dda.ddaBlock(box((x, 0.1 * k, 1.1 * k + 0.2), (x + 1, 0.1 * k + 1, 1.1 * k + 1.2)),
                                          material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda', syncPeriod=1)]
    O.trackEnergy = True
    O.run(600, True)
    return _fingerprint(), len(O.interactions)


def test_keeping_views_does_not_change_the_dda_motion():
    """Bitwise: syncing every step with interactions, forces and energy kept, and without."""
    withViews, count = _run_pile(True)
    assert count > 0
    O.reset()
    withoutViews, none = _run_pile(False)
    assert none == 0
    assert withViews == withoutViews


def test_unbalanced_force_is_yades_with_ddas_gravity():
    """Oracle: YADE's own unbalancedForce, given DDA's gravity through a NewtonIntegrator that never
    runs, equals the replacement without one, in mid-fall (where it is large) and at rest."""
    from yade_dda import hooks
    _stack(n=3)
    ratios = []
    for steps in (1, 400):
        O.run(steps, True)
        ours = utils.unbalancedForce()
        engines = list(O.engines)
        O.engines = engines + [wrapper.NewtonIntegrator(dead=True, mask=0, gravity=(0, 0, -G))]
        yades = hooks.unbalancedForce._yadeDDA()
        O.engines = engines
        assert ours == pytest.approx(yades, rel=1e-12, abs=1e-15)
        ratios.append(ours)
    assert ratios[-1] < 0.05
    import yade.utils
    assert yade.utils.unbalancedForce is hooks.unbalancedForce


def test_unbalanced_force_falls_beside_a_fixed_concave_block():
    """A cube resting on a floor beside a fixed L-shaped block: the L's clump is
    not dynamic (as its members and every fixed block), so neither YADE's
    unbalancedForce nor ours counts its weight as an unbalanced force; the
    resting cube reads about 0 (it read 1.4 when the clump counted)."""
    from yade_dda import hooks
    rock = material(O, young=1e8)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    parts = [box((1.2, 0, 0), (2.2, 1, 1)), box((1.2, 1, 0), (2.2, 2, 1)), box((2.2, 1, 0), (3, 2, 1))]
    clump, _ = O.bodies.appendClumped(yade_dda.concaveBlock(parts, material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(300, True)
    assert not O.bodies[clump].dynamic
    assert utils.unbalancedForce() < 0.05
    O.engines = O.engines + [wrapper.NewtonIntegrator(dead=True, mask=0, gravity=(0, 0, -G))]
    assert hooks.unbalancedForce._yadeDDA() == pytest.approx(utils.unbalancedForce(), rel=1e-12)


def test_a_loaded_fixed_concave_block_is_not_dynamic(tmp_path):
    """A file whose fixed concave block's clump is dynamic (saved before clumps of fixed blocks were
    made static) loads with the clump static, so unbalancedForce falls there too."""
    rock = material(O, young=1e8)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    parts = [box((1.2, 0, 0), (2.2, 1, 1)), box((1.2, 1, 0), (2.2, 2, 1))]
    clump, _ = O.bodies.appendClumped(yade_dda.concaveBlock(parts, material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(200, True)
    O.bodies[clump].dynamic = True   # as such a file has it
    path = str(tmp_path / 'old.yade')
    O.save(path)
    O.load(path)
    assert not O.bodies[clump].dynamic
    O.run(100, True)
    assert utils.unbalancedForce() < 0.05


def test_a_dda_step_leaves_yades_thread_count_alone():
    """A DDA step with threads=1 taken by O.step() (in the calling thread) once left OpenMP's thread
    count at 1 there; O.reset() then made a scene whose ForceContainer YADE sized for one thread, and
    YADE's InteractionLoop, run by O.run with the default two, wrote past it: a segfault in the mixed
    scene below (it crashed the whole test run when an earlier test had stepped that way). The count a
    step asks for holds for that step only."""
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, threads=1)]
    O.step()
    O.reset()
    wall, sphere = _sphereOnWall(True)
    assert _realPairs() == {(wall, sphere), (0, 1)}
