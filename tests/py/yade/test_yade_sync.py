"""The C++ sync (pkg/py/YadeSync.hpp) keeps YADE's objects it wrote to; what it shows must stay true
whatever a script does to YADE's containers between steps.

Oracle: after every step, YADE's bodies, O.interactions and O.forces are compared with the DDA core
read independently (yade_dda.block, yade_dda.contacts), while a seeded random script (seed printed)
replaces body states and shapes, erases and clears interactions, resets O.forces, sets permanent
forces and puts a ForceResetter in and out of O.engines.
"""
import math
import random

import pytest

import yade_dda
from yade import wrapper
from yade_dda import O

from helpers import box, material, rotate

G = 9.81


def _pile(seed):
    rng = random.Random(seed)
    rock = material(O, young=1e8, frictionDeg=25)
    O.bodies.append(yade_dda.ddaBlock(box((-4, -4, -1), (4, 4, 0)), material=rock, fixed=True))
    for k in range(6):
        x, y, z = rng.uniform(-1, 1), rng.uniform(-1, 1), 0.2 + 1.4 * k
        corners = rotate(box((x, y, z), (x + 1, y + 0.6, z + 0.8)), (rng.random(), rng.random(), 1.0),
                         rng.uniform(-0.2, 0.2), about=(x + 0.5, y + 0.3, z + 0.4))
        O.bodies.append(yade_dda.ddaBlock(corners, material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), label='dda')]


def _expectedForces():
    """Per body id: (force, torque about its centroid) of its closed contacts, from contacts()."""
    out = {}
    for c in yade_dda.contacts('closed'):
        for bodyId, sign in ((c.id1, 1), (c.id2, -1)):
            f, t = out.get(bodyId, (c.force * 0, c.force * 0))
            arm = c.point - yade_dda.block(bodyId).centroid
            out[bodyId] = (f + sign * c.force, t + arm.cross(sign * c.force))
    return out


def _checkBodies(scale):
    for b in O.bodies:
        view = yade_dda.block(b.id)
        assert b.state.pos == view.centroid
        velocity = view.velocity
        assert tuple(b.state.vel) == tuple(velocity[:3]) and tuple(b.state.angVel) == tuple(velocity[3:6])
        shown = sorted(tuple(b.state.ori * v + b.state.pos) for v in b.shape.v)
        true = sorted(tuple(v) for v in view.vertices)
        assert max(max(abs(p - q) for p, q in zip(u, w)) for u, w in zip(shown, true)) <= 1e-12 * scale


def _checkInteractions():
    closed = yade_dda.contacts('closed')
    pairs = {(min(c.id1, c.id2), max(c.id1, c.id2)) for c in closed}
    assert {(i.id1, i.id2) for i in O.interactions if i.isReal} == pairs
    assert O.interactions.countReal() == len(O.interactions)   # no virtual leftovers
    for i in O.interactions:
        onId2 = sum((c.force * (1 if c.id1 == i.id2 else -1) for c in closed if {c.id1, c.id2} == {i.id1, i.id2}),
                    closed[0].force * 0)
        shown = i.phys.normalForce + i.phys.shearForce
        assert (shown - onId2).norm() <= 1e-12 * max(onId2.norm(), 1.0)


def _checkForces(extra):
    expected = _expectedForces()
    for b in O.bodies:
        f, t = expected.get(b.id, (b.state.pos * 0, b.state.pos * 0))
        scale = max(f.norm(), 1.0)
        assert (O.forces.f(b.id) - f - extra.get(b.id, f * 0)).norm() <= 1e-9 * scale
        assert (O.forces.t(b.id) - t).norm() <= 1e-9 * scale * 10


def _tamper(rng, action):
    """What a script may do between steps; returns permanent forces now set, per body."""
    ids = [b.id for b in O.bodies]
    if action == 'replaceState':
        O.bodies[rng.choice(ids)].state = wrapper.State()
    elif action == 'replaceShape':
        b = O.bodies[rng.choice(ids)]
        b.shape = wrapper.Polyhedra(v=[v * 1.5 for v in b.shape.v])    # another shape: the sync must write over it
    elif action == 'eraseInteraction':
        real = [(i.id1, i.id2) for i in O.interactions]
        if real:
            O.interactions.erase(*rng.choice(real))
    elif action == 'clearInteractions':
        O.interactions.clear()
    elif action == 'resetForces':
        O.forces.reset()
    elif action == 'toggleResetter':
        engines = list(O.engines)
        if isinstance(engines[0], wrapper.ForceResetter):
            O.engines = engines[1:]
        else:
            O.engines = [wrapper.ForceResetter()] + engines


ACTIONS = ('none', 'none', 'replaceState', 'replaceShape', 'eraseInteraction', 'clearInteractions', 'resetForces',
           'toggleResetter')


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_views_follow_the_core_whatever_the_script_does(scene, seed):
    print('seed', seed)
    rng = random.Random(seed)
    _pile(seed)
    O.step()
    seen, withContacts = set(), 0
    for step in range(300):
        action = rng.choice(ACTIONS) if step % 3 == 0 else 'none'
        _tamper(rng, action)
        O.step()
        seen.add(action)
        _checkBodies(10.0)
        _checkInteractions()
        _checkForces({})
        withContacts += len(yade_dda.contacts('closed')) > 0
    assert withContacts >= 50   # the pile formed: interactions and forces were tested
    assert seen == set(ACTIONS)
    assert yade_dda.scene.current().writer().counters()['bodiesKept'] > 0   # the writer kept the bodies' objects


def test_forces_are_not_read_back_when_nobody_touched_them(scene):
    """Without a reset, the writer's probe agrees at every sync: O.forces is read back only at the
    first (an unknown container), and still equals the DDA forces after 300 steps."""
    _pile(6)
    O.run(300, True)
    for _ in range(30):
        O.step()
    _checkForces({})
    assert len(yade_dda.contacts('closed')) > 0
    assert yade_dda.scene.current().writer().counters()['forceReadBacks'] == 1


def test_permanent_forces_are_overwritten_at_every_sync(scene):
    """A permanent force set on a DDA block comes back at each reset of O.forces (a ForceResetter);
    the sync reads the forces back and O.forces still shows the DDA force alone."""
    _pile(4)
    O.engines = [wrapper.ForceResetter()] + list(O.engines)
    O.run(200, True)
    O.forces.setPermF(3, (0, 0, 123.0))
    for _ in range(20):
        O.step()
        _checkForces({})


def test_forces_added_by_a_script_stay_until_a_reset(scene):
    """O.forces accumulates what anyone adds, as in YADE; the sync adds the change of the DDA force
    to it. A script's addF on a DDA block (which does not move it: DDA loads are point loads) stays
    in O.forces until a reset, as it would for a YADE body."""
    _pile(5)
    O.run(200, True)
    O.forces.addF(2, (5.0, 0, 0))
    O.forces.f(2, True)
    O.step()
    _checkForces({2: O.bodies[2].state.pos * 0 + (5.0, 0, 0)})
    O.forces.reset()
    O.step()
    _checkForces({})
