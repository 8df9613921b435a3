# -*- coding: utf-8 -*-
"""Regression scene: a tetrahedral rock wedge on two planes slides (FS < 1) or holds (FS > 1).

Two fixed slabs whose top faces (planes A and B) meet along a keel plunging
`slopeDeg` towards +x; in the section perpendicular to the keel they make a
90 degree valley whose bisector is vertical. A tetrahedral wedge (keel edge
2 m, arms 1 m) lies in the valley with two faces on the planes. Hard rock
(E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3). Both planes get the friction
angle phi that gives the factor of safety `fs` (the wedge's own friction
angle is 60 degrees, so each contact takes its plane's):

    limit equilibrium along the keel l (Hoek & Bray; vector form):
    R_A + c R_B = W n_A.z,  c R_A + R_B = W n_B.z  (c = n_A.n_B),
    FS = (R_A + R_B) tan(phi) / (W sin(psi)),   psi the plunge of l.

FS < 1: the wedge slides along l with a = g sin(psi) (1 - FS), so its centroid
moves s = a t^2 / 2 (closed form; tolerance 2%: a relative friction error e
changes s by e FS / (1 - FS), so 2% is 0.9% of friction at FS = 0.7; the rest
is the start-up of the contact forces, as on the incline), within 1 degree of
l. Each plane carries its reaction R (2%). FS > 1: the wedge holds: it moves
less than 1e-4 m (elastic settlement ~1e-7 m) and turns less than 1e-4 rad.

Parameters (table columns): fs [-] target factor of safety; slopeDeg [deg]
plunge of the keel; dt [s] largest time step; tEnd [s] simulated time;
collider. Run alone: yade -n -x wedge.py
"""
import math

from yade_dda import *
from yade_dda.tools import regression
from yade import PolyhedraMat

regression.readParamsFromTable(fs=0.7, slopeDeg=35.0, dt=2e-3, tEnd=1.0, collider='DESS')
from yade.params.table import *

G = 9.81
if abs(fs - 1.0) < 0.05:
    raise ValueError('fs = %g is too close to 1 for a closed-form regime' % fs)
psi, xi, beta = math.radians(slopeDeg), math.radians(90.0), math.radians(90.0)


def comb(*terms):
    return tuple(sum(s * v[i] for s, v in terms) for i in range(3))


def dot(p, q):
    return sum(p[i] * q[i] for i in range(3))


def frameBox(origin, axes, lo, hi):
    return [comb((1.0, origin), (x, axes[0]), (y, axes[1]), (z, axes[2]))
            for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


origin = (3.0, -2.0, 10.0)
keel = (math.cos(psi), 0.0, -math.sin(psi))                 # line of intersection l, downhill
h, u = (0.0, 1.0, 0.0), (math.sin(psi), 0.0, math.cos(psi))  # horizontal and up in the section
dA = comb((math.cos(beta + xi / 2), h), (math.sin(beta + xi / 2), u))   # plane traces leaving the keel
dB = comb((math.cos(beta - xi / 2), h), (math.sin(beta - xi / 2), u))
nA = comb((math.sin(beta + xi / 2), h), (-math.cos(beta + xi / 2), u))  # plane normals, into the wedge
nB = comb((-math.sin(beta - xi / 2), h), (math.cos(beta - xi / 2), u))

c = dot(nA, nB)
RA, RB = (nA[2] - c * nB[2]) / (1 - c * c), (nB[2] - c * nA[2]) / (1 - c * c)   # per unit weight
phi = math.atan(fs * math.sin(psi) / (RA + RB))

planes = O.materials.append(PolyhedraMat(young=1e10, poisson=0.25, density=2600, frictionAngle=phi))
rock = O.materials.append(PolyhedraMat(young=1e10, poisson=0.25, density=2600, frictionAngle=math.radians(60)))
slabA = O.bodies.append(ddaBlock(frameBox(origin, (keel, dA, comb((-1.0, nA))), (-1.0, -1.0, 0.0), (4.5, 2.0, 1.0)),
                                 material=planes, fixed=True))
slabB = O.bodies.append(ddaBlock(frameBox(origin, (keel, dB, comb((-1.0, nB))), (-1.0, -1.0, 0.0), (4.5, 2.0, 1.0)),
                                 material=planes, fixed=True))
wedge = O.bodies.append(ddaBlock([origin, comb((1.0, origin), (2.0, keel)),
                                  comb((1.0, origin), (1.0, keel), (1.0, dA)),
                                  comb((1.0, origin), (1.0, keel), (1.0, dB))], material=rock))
O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.02, collider=collider, label='dda')]
c0 = tuple(block(wedge).centroid)
regression.runTo(tEnd)

t = O.time
d = [block(wedge).centroid[i] - c0[i] for i in range(3)]
moved = math.sqrt(dot(d, d))
weight = block(wedge).mass * G


def normalForce(slab):
    return sum(k.normalForce for k in contacts() if {k.id1, k.id2} == {wedge, slab} and k.state != 'open')


rec = regression.Record()
if fs < 1:
    rec.closedForm('slide distance', dot(d, keel), G * math.sin(psi) * (1 - fs) * t * t / 2, rel=0.02, unit='m',
                   formula='g sin(psi) (1 - FS) t^2/2')
    rec.closedForm('angle to the keel', math.degrees(math.acos(min(1.0, dot(d, keel) / moved))), 0.0, abs=1.0,
                   unit='deg', formula='0 (slides along l)')
    rec.closedForm('normal force on plane A', normalForce(slabA), RA * weight, rel=0.02, unit='N',
                   formula='R_A = W (n_A.z - c n_B.z)/(1 - c^2)')
    rec.closedForm('normal force on plane B', normalForce(slabB), RB * weight, rel=0.02, unit='N',
                   formula='R_B = W (n_B.z - c n_A.z)/(1 - c^2)')
else:
    rec.closedForm('displacement', moved, 0.0, abs=1e-4, unit='m', formula='0 (FS > 1: holds)')
    rec.closedForm('rotation', block(wedge).rotation.toRotationVector().norm(), 0.0, abs=1e-4, unit='rad',
                   formula='0 (FS > 1: holds)')
rec.measure('phiPlanesDeg', math.degrees(phi))
rec.write()
