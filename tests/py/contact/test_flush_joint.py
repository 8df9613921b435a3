"""Flush joints between fixed blocks: a block sliding without friction from one
fixed block onto a second one laid flush against it (coplanar tops) keeps its
kinetic energy.

While the block's front is still short of the joint, the pair's separating
axis is the second block's side face at the joint; that face is covered by
the first block (an internal face of the flush pair). Used as an entrance it
pushed the block back horizontally, a "ghost" obstacle that took 61% of the
kinetic energy here. The engine now marks faces of fixed blocks fully
covered by a coplanar face of another fixed block as internal and never
enters through them (BlockGeometry::internalFaces).
"""
import math

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock
from yade import wrapper

from helpers import box

G = 9.81


def test_frictionless_block_crosses_a_flush_joint_keeping_its_energy(scene):
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e9, poisson=0.25, frictionAngle=0))
    O.bodies.append(ddaBlock(box((-10, -3, -1), (8, 3, 0)), material=rock, fixed=True))
    O.bodies.append(ddaBlock(box((8, -3, -1), (30, 3, 0)), material=rock, fixed=True))
    b = O.bodies.append(ddaBlock(box((0, -0.5, 0), (4, 0.5, 1)), material=rock, velocity=(5, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    mass = yade_dda.block(b).mass
    O.run(1600, True)  # the front crosses the joint at x = 8 m after 0.8 s; the block ends at x ~ 10
    v = yade_dda.block(b).velocity
    kinetic = 0.5 * mass * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    assert yade_dda.block(b).centroid[0] > 8
    assert abs(kinetic - 0.5 * mass * 25) < 0.01 * 0.5 * mass * 25
