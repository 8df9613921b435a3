# -*- coding: utf-8 -*-
"""Regression scene: a tower of ten 1 m cubes stands on a fixed floor.

Ten identical cubes stacked with coincident corners on a fixed 5 x 5 x 1 m
floor, hard rock (E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3), friction angle
`phiDeg`, under gravity. The integrator's start from rest brings the column
to static equilibrium before the first step (16 static steps, friction
locked and then at its true value), so it starts loaded and stays at rest.
Its state is compared with a stored reference (references/<description>.json),
made by `check.py --update`:

- heights of the centroids: abs 2e-6 m. The column's elastic shortening at
  rest is sum (k - 1/2) rho g L^2 / E = 1.3e-4 m at the top under uniaxial
  stress; settled with its interfaces locked, which hold the cubes' Poisson
  spread, the top sinks 1.25e-4 m. 2e-6 m is 1.5% of it, a bound on how far
  round-off and the settling's stopping rule may move the equilibrium
  reached.
- sideways positions (x, y) of the centroids and the rotation vectors: abs
  2e-4 m and 2e-4 rad. Settled, the stack stays symmetric to round-off;
  started unloaded (startFromRest=False) it rings and is left shifted by up
  to 6e-5 m and turned about z by up to 6e-5 rad, amounts that are chaotic
  in round-off. So they are
  kept only as a bound, like the closed-form checks below.

Closed-form checks beside the reference: the stack is symmetric, so no cube
shifts sideways (< 1e-4 m) or tilts (< 1e-4 rad), and the top cube settles
by less than 1e-3 m.

Parameters (table columns): phiDeg [deg]; dt [s] largest time step; tEnd [s]
simulated time; collider. Run alone: yade -n -x tower.py
"""
import math

from yade_dda import *
from yade_dda.tools import regression
from yade import PolyhedraMat

regression.readParamsFromTable(phiDeg=30.0, dt=2e-3, tEnd=1.0, collider='DESS')
from yade.params.table import *

G = 9.81


box = boxCorners   # the 8 corners of the box from lo to hi [m]


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
