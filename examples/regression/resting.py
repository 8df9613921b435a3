# -*- coding: utf-8 -*-
"""Regression scene: a cube resting on a floor settles by its closed-form amount.

A 1 m cube of hard rock (E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3, friction
angle `phiDeg`) released at rest on a fixed floor under gravity. DDA's
block has constant strain; it stands on its four bottom corners, each a
vertex-face contact with a normal penalty spring kn = 40 E L (L = 1 m, the
cube root of the volume) and, when locked by friction, a shear spring
ks = 0.4 kn. Minimising block strain energy + spring energy + m g w0 over the
centroid's drop w0 and the strains (ex = ey = e by symmetry, ez) gives:

    equilibrium:  M ez + 2 lambda e = -rho g h / 2      (szz = -rho g h/2)
    springs:      each corner carries m g / 4, sinks p = m g / (4 kn)
    lateral:      e (V (M + lambda) + ks a^2) = -V lambda ez
    settlement of the centroid:  h |ez| / 2 + p

(M = lambda + 2 mu = E (1 - nu)/((1 + nu)(1 - 2 nu)) the constrained modulus.)
Frictionless (phiDeg = 0): the corners slide, no shear springs, e = -nu ez:
uniaxial stress, ez = -rho g h / (2E). Friction that locks the corners: as
ks -> infinity this is the confined column of tests/py/blocks/test_motion.py,
ez = -rho g h / (2M); the shear springs' compliance leaves e = 2.5e-8 and
ez 1.5% above the confined value. Locking needs tan(phi) above the corner's
shear demand |F_shear|/N = sqrt(2) ks e a / 2 / (m g / 4) (= 0.44 here); between
0 and that the corners slip partly and there is no closed form.

Tolerance: rel 1e-3 on ez and on the settlement, 1e-2 on e (a 1e-8 quantity),
1e-3 on the floor reaction (= weight); the cube settles in ~0.1 s (the time
scheme damps the ringing of the stiff springs).

Parameters (table columns): phiDeg [deg]; dt [s]; tEnd [s]; collider.
Run alone: yade -n -x resting.py
"""
import math

from yade_dda import *
from yade_dda.tools import regression
from yade import PolyhedraMat

regression.readParamsFromTable(phiDeg=30.0, dt=2e-3, tEnd=0.5, collider='DESS')
from yade.params.table import *

G = 9.81
E, nu, rho, a, h = 1e10, 0.25, 2600.0, 1.0, 1.0
penaltyFactor, shearRatio = 40.0, 0.4        # DDAIntegrator's contactPenaltyFactor, shearStiffnessRatio
lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
M = lam + 2 * mu
V = a * a * h
m = rho * V
kn = penaltyFactor * E * V ** (1.0 / 3.0)
ks = shearRatio * kn
p = m * G / (4 * kn)
phi = math.radians(phiDeg)
if phiDeg == 0:
    ez = -rho * G * h / (2 * E)
    e = -nu * ez
    regime = 'frictionless: uniaxial stress'
else:
    ez = -rho * G * h / 2 / (M - 2 * lam * lam * V / (V * (M + lam) + ks * a * a))
    e = -V * lam * ez / (V * (M + lam) + ks * a * a)
    demand = math.sqrt(2) * ks * e * a / 2 / (m * G / 4)
    if math.tan(phi) < 1.2 * demand:
        raise ValueError('phiDeg = %g: tan(phi) must be 0 or above 1.2 x the corners\' shear demand %.3f '
                         '(partial slip has no closed form)' % (phiDeg, demand))
    regime = 'locked: laterally confined by the shear springs'


box = boxCorners   # the 8 corners of the box from lo to hi [m]


rock = O.materials.append(PolyhedraMat(young=E, poisson=nu, density=rho, frictionAngle=phi))
floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (a + 2, a + 2, 0)), material=rock, fixed=True))
cube = O.bodies.append(ddaBlock(box((0, 0, 0), (a, a, h)), material=rock))
O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.02, collider=collider,
                           contactPenaltyFactor=penaltyFactor, shearStiffnessRatio=shearRatio, label='dda')]
regression.runTo(tEnd)

blk = block(cube)
reaction = sum(c.normalForce * c.normal[2] * (1 if c.id1 == cube else -1) for c in contacts() if c.state != 'open')
rec = regression.Record()
rec.closedForm('settlement', h / 2 - blk.centroid[2], h * abs(ez) / 2 + p, rel=1e-3, unit='m',
               formula='h |ez|/2 + m g/(4 kn)')
rec.closedForm('vertical strain ez', blk.strain[2], ez, rel=1e-3, formula=regime)
rec.closedForm('lateral strain ex', blk.strain[0], e, rel=1e-2, formula=regime)
rec.closedForm('lateral strain ey', blk.strain[1], e, rel=1e-2, formula=regime)
rec.closedForm('floor reaction', reaction, m * G, rel=1e-3, unit='N', formula='m g')
rec.measure('confinedColumnEz', -rho * G * h / (2 * M))
rec.measure('uniaxialStressEz', -rho * G * h / (2 * E))
rec.measure('contactStates', sorted(set(c.state for c in contacts() if c.state != 'open')))
rec.write()
