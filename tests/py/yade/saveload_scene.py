"""The scene of test_save_load.py, also run by its child processes (SI units).

A block sliding down a frictional slope (gravity tilted 30 degrees, friction
20 degrees: it slides), and beside it, on a separate floor of 45 degrees
friction, a stack of two blocks whose contacts lock; the blocks carry stress
and strain from their weight. Run for a few steps it has open, sliding and
locked contacts at once.
"""
import math

from yade import wrapper

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator


def box(x0, y0, z0, x1, y1, z1):
    return [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]


def build(collider='MSC', engines=(), rigidTop=False):
    """rigidTop: the top block of the stack is rigid (6 unknowns)."""
    O.reset()
    slippery = O.materials.append(wrapper.PolyhedraMat(young=1e8, poisson=0.25, density=2600,
                                                       frictionAngle=math.radians(20)))
    rough = O.materials.append(wrapper.PolyhedraMat(young=1e8, poisson=0.25, density=2600,
                                                    frictionAngle=math.radians(45)))
    O.bodies.append(ddaBlock(box(-20, -5, -1, 2, 5, 0), material=slippery, fixed=True))
    O.bodies.append(ddaBlock(box(2.5, -5, -1, 20, 5, 0), material=rough, fixed=True))
    O.bodies.append(ddaBlock(box(-0.5, -0.5, 0, 0.5, 0.5, 1), material=slippery))
    O.bodies.append(ddaBlock(box(4, -0.5, 0, 5, 0.5, 1), material=rough))
    O.bodies.append(ddaBlock(box(4.1, -0.4, 1, 4.9, 0.4, 1.8), material=rough, rigid=rigidTop))
    tilt = math.radians(30)
    # As placed (startFromRest=False): the stack's contacts start unloaded and ring
    # open and closed, so the saved state holds open, sliding and locked contacts.
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(9.81 * math.sin(tilt), 0, -9.81 * math.cos(tilt)),
                               maxDisplacement=0.01, collider=collider, startFromRest=False)] + list(engines)


def state():
    """Everything that decides later steps and what a user reads, as exact
    values (float.hex), so equality is bitwise."""
    core = yade_dda.scene.current().core
    h = lambda values: tuple(float(x).hex() for x in values)
    blocks = []
    for i in range(core.blockCount()):
        blocks.append((tuple(h(v) for v in core.vertices(i)), h(core.centroid(i)), h(core.velocity(i)),
                       h(core.stress(i)), h(core.strain(i)), h(core.rotation(i))))
    contacts = [(c.id1, c.id2, c.kind, c.type, c.state, c.normalForce.hex(), h(c.shearForce), h(c.point),
                 c.bonded) for c in yade_dda.contacts()]
    return dict(blocks=blocks, contacts=contacts, iter=O.iter, time=float(O.time).hex(), steps=core.steps(),
                nextDt=float(O.dt).hex())


def impact(speed=2.0, engines=()):
    """A block falling at ``speed`` [m/s] onto a fixed floor, released 1 mm above
    it: during the impact (the first 8 or so steps at 2 m/s) the contact spring
    presses it into the floor deeper than the initial-overlap tolerance of
    blocks entering a scene (guards.checkInitialOverlaps)."""
    O.reset()
    material = O.materials.append(wrapper.PolyhedraMat(young=1e8, poisson=0.25, density=2600, frictionAngle=0.5))
    O.bodies.append(ddaBlock(box(-2, -2, -1, 2, 2, 0), material=material, fixed=True))
    O.bodies.append(ddaBlock(box(-0.5, -0.5, 0.001, 0.5, 0.5, 1.001), material=material, velocity=(0, 0, -speed)))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.01)] + list(engines)
