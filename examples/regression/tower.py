# -*- coding: utf-8 -*-
"""Regression scene: a tower of ten 1 m cubes stands on a fixed floor.

Ten identical cubes stacked with coincident corners on a fixed 5 x 5 x 1 m
floor, hard rock (E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3), friction angle
`phiDeg`, released unloaded under gravity. There is no closed form for the
start-up (the column rings as its weight comes onto the penalty springs) so
the final state is compared with a stored reference
(references/<description>.json), made by `check.py --update`:

- heights of the centroids: abs 2e-6 m. The column's elastic shortening at
  rest is sum (k - 1/2) rho g L^2 / E = 1.3e-4 m at the top; 2e-6 m is 1.5%
  of it. The run is deterministic (any thread count; every collider gives
  the same contacts, hence the same numbers), but not smooth in round-off:
  moving the cubes by 1e-12 m at the start changes the heights by up to
  4e-7 m, hence not tighter.
- sideways positions (x, y) of the centroids and the rotation vectors: abs
  2e-4 m and 2e-4 rad. The start-up leaves the cubes shifted by up to
  6e-5 m and turned about z by up to 6e-5 rad, and those amounts are chaotic:
  the same 1e-12 m at the start changes them by 5e-5. So they are kept only
  as a bound, like the closed-form checks below.

Closed-form checks beside the reference: the stack is symmetric, so no cube
shifts sideways (< 1e-4 m) or tilts (< 1e-4 rad), and the top cube settles
by less than 1e-3 m.

Parameters (table columns): phiDeg [deg]; dt [s] largest time step; tEnd [s]
simulated time; collider. Run alone: yade -n -x tower.py
"""
import math

from yade_dda import *
from yade_dda import regression
from yade import PolyhedraMat

regression.readParamsFromTable(phiDeg=30.0, dt=2e-3, tEnd=1.0, collider='DESS')
from yade.params.table import *

G = 9.81


def box(lo, hi):
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


rock = O.materials.append(PolyhedraMat(young=1e10, poisson=0.25, density=2600, frictionAngle=math.radians(phiDeg)))
floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (3, 3, 0)), material=rock, fixed=True))
cubes = [O.bodies.append(ddaBlock(box((0, 0, k), (1, 1, k + 1)), material=rock)) for k in range(10)]
O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.02, collider=collider, label='dda')]
starts = [tuple(block(c).centroid) for c in cubes]
regression.runTo(tEnd)

centroids = [list(block(c).centroid) for c in cubes]
rotations = [list(block(c).rotation.toRotationVector()) for c in cubes]
rec = regression.Record()
rec.reference('heights', [p[2] for p in centroids], abs=2e-6, unit='m')
rec.reference('sideways positions', [p[0:2] for p in centroids], abs=2e-4, unit='m')
rec.reference('rotations', rotations, abs=2e-4, unit='rad')
rec.closedForm('largest sideways shift', max(math.hypot(p[0] - s[0], p[1] - s[1]) for p, s in zip(centroids, starts)),
               0.0, abs=1e-4, unit='m', formula='0 (symmetric stack)')
rec.closedForm('largest tilt', max(math.sqrt(sum(r * r for r in rot)) for rot in rotations), 0.0, abs=1e-4,
               unit='rad', formula='0 (symmetric stack)')
rec.closedForm('top settlement', starts[-1][2] - centroids[-1][2], 0.0, abs=1e-3, unit='m',
               formula='~0 (elastic: 50 rho g L^2/E = 1.3e-4 m)')
rec.measure('openCloseFailures', stats()['openCloseFailures'])
rec.write()
