# -*- coding: utf-8 -*-
"""A small pile of blocks dropped on a floor, recorded for ParaView by DDAVTKRecorder.

A pyramid of 14 blocks (3 x 3 cubes, 2 x 2 cubes over their joints, a
triangular prism on top; each turned a little about a random axis, a fixed
seed), its layers 0.1 to 0.25 m apart, falls onto a fixed floor and settles.
E = 50 MPa, nu = 0.25, rho = 2600 kg/m^3, friction 35 degrees; dt 1 ms at
most, steps of at most 5 mm.

Every `--period` iterations the recorder writes ``OUT/pile-blocks.<iteration>.vtu``
(the blocks, cell data: velocity, displacement, stress, strain, von Mises...)
and ``OUT/pile-contacts.<iteration>.vtp`` (the contacts: normal, forces,
state, gap), and updates the series ``OUT/pile-blocks.pvd`` and
``OUT/pile-contacts.pvd``: open those in ParaView (File > Open), press
Apply, colour the blocks by vonMises and play. ``tools/render_vtk.py OUT``
renders the last output to a PNG without ParaView (doc/vtk_pile.png).

Run: ``yade -n -x examples/vtk_pile.py [--out vtk_pile] [--steps 2000] [--period 50]``
(about 15 s). SI units throughout.
"""
import argparse
import math
import os
import random
import sys

from yade_dda import O, DDAIntegrator, DDAVTKRecorder, ddaBlock, contacts, block
from yade_dda.recorder import readSeries
from yade import PolyhedraMat


def turned(corners, rng, largest=math.radians(6)):
    """corners turned by up to `largest` [rad] about a random axis through their mean (Rodrigues)."""
    centre = [sum(c[i] for c in corners) / len(corners) for i in range(3)]
    axis = [rng.uniform(-1, 1) for _ in range(3)]
    norm = math.sqrt(sum(a * a for a in axis))
    k = [a / norm for a in axis]
    angle = rng.uniform(-largest, largest)
    cos, sin = math.cos(angle), math.sin(angle)
    out = []
    for p in corners:
        v = [p[i] - centre[i] for i in range(3)]
        kxv = (k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0])
        kv = sum(k[i] * v[i] for i in range(3))
        out.append(tuple(centre[i] + v[i] * cos + kxv[i] * sin + k[i] * kv * (1 - cos) for i in range(3)))
    return out


def cube(x, y, z, size):
    return [(x + dx * size, y + dy * size, z + dz * size) for dx in (0, 1) for dy in (0, 1) for dz in (0, 1)]


def prism(x, y, z, size):
    """A triangular prism (a ridge along y) on the square [x, x + size] x [y, y + size] at height z."""
    return [(x, y, z), (x + size, y, z), (x + size / 2, y, z + size),
            (x, y + size, z), (x + size, y + size, z), (x + size / 2, y + size, z + size)]


def build(seed=1):
    """The floor and a pyramid of 14 blocks (3 x 3 cubes, 2 x 2 cubes on their joints, a prism on top),
    each layer 0.1 to 0.25 m above the one below; returns the ids of the falling blocks."""
    rng = random.Random(seed)
    rock = O.materials.append(PolyhedraMat(young=5e7, poisson=0.25, density=2600, frictionAngle=math.radians(35)))
    floor = [(x, y, z) for x in (-3, 6.5) for y in (-3, 6.5) for z in (-1, 0)]
    O.bodies.append(ddaBlock(floor, material=rock, fixed=True, color=(0.6, 0.6, 0.6)))
    ids = []
    for layer, side in enumerate((3, 2, 1)):
        for i in range(side):
            for j in range(side):
                x, y, z = 1.1 * i + 0.55 * layer, 1.1 * j + 0.55 * layer, 0.1 + 1.25 * layer
                shape = prism if side == 1 else cube
                ids.append(O.bodies.append(ddaBlock(turned(shape(x, y, z, 1.0), rng), material=rock)))
    return ids


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--out', default='vtk_pile', help='output directory (made when missing)')
    parser.add_argument('--steps', type=int, default=2000)
    parser.add_argument('--period', type=int, default=50, help='iterations between outputs')
    args = parser.parse_args(argv)
    O.reset()
    ids = build()
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.005, label='dda'),
                 DDAVTKRecorder(fileName=os.path.join(args.out, 'pile-'), iterPeriod=args.period, label='vtk')]
    O.run(args.steps, True)
    weight = sum(block(i).mass for i in ids) * 9.81
    floor = sum(c.normalForce * c.normal[2] for c in contacts('closed') if 0 in (c.id1, c.id2))
    outputs = len(readSeries(os.path.join(args.out, 'pile-blocks.pvd')))
    print('vtk_pile: %d steps, t = %.3f s, %d outputs in %s/ (pile-blocks.pvd, pile-contacts.pvd)'
          % (O.iter, O.time, outputs, args.out))
    print('  the floor carries %.4g N of the pile\'s weight %.4g N (%.1f%%: it has %s)'
          % (floor, weight, 100 * floor / weight, 'settled' if abs(floor / weight - 1) < 0.05 else 'not settled yet'))


# Under `yade -x script.py args`, sys.argv is [script.py, args...].
main(sys.argv[1:] if sys.argv and sys.argv[0].endswith('.py') else [])
