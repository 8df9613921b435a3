# -*- coding: utf-8 -*-
"""Regression scene: a cube released on an incline slides, or friction holds it.

A fixed 6 x 3 x 1 m slab whose top face dips `slopeDeg` towards +x, and a
1 m cube resting on it at rest, both hard rock (E = 10 GPa, nu = 0.25,
rho = 2600 kg/m^3) with friction angle `phiDeg`; gravity is vertical. Along
the slope the cube feels g sin(a); the slab pushes back with N = m g cos(a)
and a sliding contact resists with tan(phi) N, so (closed form)
    s(t) = g (sin a - tan(phi) cos a) t^2 / 2,   v(t) = g (sin a - tan(phi) cos a) t
when tan(phi) < tan(a); otherwise static friction holds the cube: s = 0.
Rows near the limit (tan(phi) within 2% of tan(a)) or near toppling (a held
cube with tan(a) > 0.9 b/h, a sliding one with tan(phi) > 0.9 b/h; b/h = 1)
are refused: they have no such closed form.

Tolerances. Sliding: the acceleration is constant and DDA's scheme is exact
for it, but the cube settles at rest with its friction locked (start from
rest) and must then go over to sliding: in the first steps its contact forces
and elastic modes start up and it keeps a small velocity offset (doc/benchmarks.md,
"What accuracy costs"). Measured on core b7154a7: the frictional
rows of full.table and the same scene at dt 1e-4 s are within 6e-5 of s and
3e-5 of v; 1% is a margin. Frictionless
the contact force is normal to the slope and the motion along it is exact up
to round-off (~1e-11). Distance and velocity: rel 1% with friction, 1e-6
without. Holding: the cube may creep by the elastic shear of the
shear springs and of itself (~1e-6 m); allowed 1e-4 m. In both cases the cube
must not turn (rotation < 1e-3 rad) nor leave the slope (normal displacement
< 1e-4 m).

Parameters (table columns): slopeDeg, phiDeg [deg]; dt [s] largest time
step; tEnd [s] simulated time; collider ('DESS', 'MSC', 'NBS', 'AllPairs').
Run alone: yade -n -x incline.py
"""
import math

from yade_dda import *
from yade_dda.tools import regression
from yade import PolyhedraMat

regression.readParamsFromTable(slopeDeg=30.0, phiDeg=20.0, dt=1e-3, tEnd=1.0, collider='DESS')
from yade.params.table import *

G = 9.81
a, phi = math.radians(slopeDeg), math.radians(phiDeg)
if abs(math.tan(a) - math.tan(phi)) < 0.02 * math.tan(a):
    raise ValueError('slopeDeg = %g and phiDeg = %g are too close to the limit tan(phi) = tan(a) for a closed form'
                     % (slopeDeg, phiDeg))
# A cube (width/height b/h = 1) topples instead when tan(a) > b/h while held, or tan(phi) > b/h while
# sliding (Hoek & Bray's chart; tests/py/scenes.classical_regime); keep 10% away from both.
if (math.tan(a) if math.tan(phi) >= math.tan(a) else math.tan(phi)) > 0.9:
    raise ValueError('slopeDeg = %g, phiDeg = %g: the cube would (nearly) topple (b/h = 1); no closed form'
                     % (slopeDeg, phiDeg))

# slope frame: downhill, across, normal (right-handed); the slope face is the plane through the origin
downhill = (math.cos(a), 0.0, -math.sin(a))
across = (0.0, 1.0, 0.0)
normal = (math.sin(a), 0.0, math.cos(a))


def onSlope(s, w, n):
    """Point at slope coordinates (s along downhill, w across, n along the normal) [m]."""
    return tuple(s * downhill[i] + w * across[i] + n * normal[i] for i in range(3))


def slopeBox(lo, hi):
    return [onSlope(s, w, n) for s in (lo[0], hi[0]) for w in (lo[1], hi[1]) for n in (lo[2], hi[2])]


rock = O.materials.append(PolyhedraMat(young=1e10, poisson=0.25, density=2600, frictionAngle=phi))
slab = O.bodies.append(ddaBlock(slopeBox((-1.0, -1.5, -1.0), (5.0, 1.5, 0.0)), material=rock, fixed=True))
cube = O.bodies.append(ddaBlock(slopeBox((0.0, -0.5, 0.0), (1.0, 0.5, 1.0)), material=rock))
O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.02, collider=collider, label='dda')]
c0 = tuple(block(cube).centroid)
regression.runTo(tEnd)

t = O.time
d = [block(cube).centroid[i] - c0[i] for i in range(3)]
v = list(block(cube).velocity)[0:3]
along = sum(d[i] * downhill[i] for i in range(3))
speed = sum(v[i] * downhill[i] for i in range(3))
acceleration = max(G * (math.sin(a) - math.tan(phi) * math.cos(a)), 0.0)
rec = regression.Record()
if acceleration > 0:
    rel = 0.01 if phi > 0 else 1e-6
    rec.closedForm('slide distance', along, acceleration * t * t / 2, rel=rel, unit='m',
                   formula='g (sin a - tan(phi) cos a) t^2/2')
    rec.closedForm('slide velocity', speed, acceleration * t, rel=rel, unit='m/s', formula='g (sin a - tan(phi) cos a) t')
else:
    rec.closedForm('slide distance', along, 0.0, abs=1e-4, unit='m', formula='0 (tan(phi) >= tan(a): friction holds)')
rec.closedForm('normal displacement', sum(d[i] * normal[i] for i in range(3)), 0.0, abs=1e-4, unit='m',
               formula='0 (stays on the slope)')
rec.closedForm('rotation', block(cube).rotation.toRotationVector().norm(), 0.0, abs=1e-3, unit='rad',
               formula='0 (does not tip)')
rec.measure('contactStates', sorted(set(c.state for c in contacts() if c.state != 'open')))
rec.write()
