# -*- coding: utf-8 -*-
"""Regression scene: a block thrown under gravity follows the parabola exactly.

A 1 x 2 x 3 m block (rho = 2600 kg/m^3) starts with its centroid at
(0.5, 1, 51.5) m and velocity v0 = (3, 0, 7.5) m/s under g = 9.81 m/s^2.
Closed form at t = O.time:
    x(t) = x0 + v0 t + g t^2 / 2,   v(t) = v0 + g t.
Shi's scheme (D = v0 dt + a dt^2/2, v1 = 2 D/dt - v0) is exact for constant
acceleration for any sequence of step sizes, so only round-off remains: the
tolerance is 1e-9 m and 1e-9 m/s (the round-off of 50 m is ~1e-14 m per
step). With dt = 1e-2 s the block moves more than the allowed 0.015 m per step
(1% of half its 3 m extent), so the step control cuts steps; still exact.

Parameters (table columns): dt [s] largest time step, tEnd [s] simulated time.
Run alone: yade -n -x freefall.py
"""
from yade_dda import *
from yade_dda.tools import regression
from yade import PolyhedraMat

regression.readParamsFromTable(dt=1e-3, tEnd=1.0)
from yade.params.table import *

G = 9.81
x0, v0 = (0.5, 1.0, 51.5), (3.0, 0.0, 7.5)
rock = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
corners = [(x, y, z) for x in (0, 1) for y in (0, 2) for z in (50, 53)]
b = O.bodies.append(ddaBlock(corners, material=rock, velocity=v0))
O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), label='dda')]
regression.runTo(tEnd)

t = O.time
g = (0.0, 0.0, -G)
rec = regression.Record()
rec.closedForm('position', list(block(b).centroid), [x0[i] + v0[i] * t + g[i] * t * t / 2 for i in range(3)],
               abs=1e-9, unit='m', formula='x0 + v0 t + g t^2/2')
rec.closedForm('velocity', list(block(b).velocity)[0:3], [v0[i] + g[i] * t for i in range(3)],
               abs=1e-9, unit='m/s', formula='v0 + g t')
rec.write()
