# -*- coding: utf-8 -*-
"""yade-dda demo: blocks moving alone under DDA, checked against closed forms.

Run with `yade -n -x examples/demo.py` (or `make demo`). Six scenes, each an
ordinary YADE script section: a block thrown under gravity, a block spinning
for 100 revolutions, an elastic column settling on fixed points under its own
weight (static analysis), a block pushed by a point load, and two with
contacts: a block sliding down a frictional slope, and a tower of 10 cubes.
The summary compares each with its closed form. SI units throughout.
"""
import math

from yade_dda import *
from yade import PolyhedraMat

G = 9.81
rows = []


def box(lo, hi):
    return [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]


def report(name, value, expected, unit):
    error = abs(value - expected) / abs(expected)
    rows.append((name, value, expected, unit, error))


# 1. A 1 x 2 x 3 m block thrown at (3, 0, 7.5) m/s from 50 m: a parabola, exactly.
O.reset()
rock = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
thrown = O.bodies.append(ddaBlock(box((0, 0, 50), (1, 2, 53)), material=rock, velocity=(3, 0, 7.5)))
O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.05, label='dda')]
O.run(1000, True)
t = O.time
report('thrown block: height after %.3f s' % t, O.bodies[thrown].state.pos[2], 51.5 + 7.5 * t - G * t * t / 2, 'm')
report('thrown block: range after %.3f s' % t, O.bodies[thrown].state.pos[0], 0.5 + 3 * t, 'm')

# 2. A block spinning at one revolution per second for 100 s keeps its volume.
O.reset()
rock = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
spinner = O.bodies.append(ddaBlock(box((-0.5, -1, -1.5), (0.5, 1, 1.5)), material=rock,
                                   angularVelocity=(0, 2 * math.pi * 0.6, 2 * math.pi * 0.8)))
V0 = block(spinner).volume
O.engines = [DDAIntegrator(dt=1e-2, maxDisplacement=1.0, label='dda')]
O.run(10000, True)
report('spinning block: volume after 100 revolutions', block(spinner).volume, V0, 'm^3')

# 3. A 2 m column held at its four base corners settles under its own weight.
#    Constant strain, base held: ez = -rho g h / (2 (lambda + 2 mu)).
O.reset()
E, nu, rho, h = 4e6, 0.25, 2600.0, 2.0
rock = O.materials.append(PolyhedraMat(young=E, poisson=nu, density=rho))
column = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, h)), material=rock,
                                  fixedPoints=[(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]))
O.engines = [DDAIntegrator(dt=0.05, gravity=(0, 0, -G), velocityRatio=0, label='dda')]
O.run(200, True)
constrained = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
report('column: vertical strain', block(column).strain[2], -rho * G * h / (2 * constrained), '-')
report('column: vertical stress', block(column).stress[2], -rho * G * h / 2, 'Pa')

# 4. A 2.6 t block pushed by 5.2 kN at its centroid for 0.5 s: x = F t^2 / (2 m).
O.reset()
rock = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
pushed = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock, loads=[((0.5, 0.5, 0.5), (5200, 0, 0))]))
O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=0.05, label='dda')]
O.run(500, True)
report('pushed block: displacement', O.bodies[pushed].state.pos[0] - 0.5, 5200 / 2600 * O.time ** 2 / 2, 'm')

# 5. A cube on a 30 degree slope with 20 degrees of friction (gravity tilted):
#    x = g (sin a - tan(phi) cos a) t^2 / 2.
O.reset()
slope, phi = math.radians(30), math.radians(20)
rock = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=phi))
O.bodies.append(ddaBlock(box((-20, -5, -1), (20, 5, 0)), material=rock, fixed=True))
slider = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=rock))
O.engines = [DDAIntegrator(dt=1e-3, gravity=(G * math.sin(slope), 0, -G * math.cos(slope)), maxDisplacement=0.01,
                           label='dda')]
O.run(1000, True)
report('sliding block: distance down the slope', O.bodies[slider].state.pos[0],
       G * (math.sin(slope) - math.tan(phi) * math.cos(slope)) * O.time ** 2 / 2, 'm')

# 6. Ten 1 m cubes stacked on a fixed floor stand for 2 s (Shi's dynamic
#    coefficient 0.5 damps the start-up): the floor carries the whole tower.
O.reset()
rock = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=math.radians(30)))
floor = O.bodies.append(ddaBlock(box((-5, -5, -1), (5, 5, 0)), material=rock, fixed=True))
tower = [O.bodies.append(ddaBlock(box((-0.5, -0.5, k), (0.5, 0.5, k + 1)), material=rock)) for k in range(10)]
O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.005, velocityRatio=0.5, label='dda')]
O.run(2000, True)
reaction = sum(c.normalForce for c in contacts('closed') if floor in (c.id1, c.id2))
report('tower: floor reaction', reaction, 10 * 2600 * G, 'N')
# Standing: the top cube's centre is where it started, up to elastic settlement (~1e-3 m).
report('tower: top cube height', O.bodies[tower[-1]].state.pos[2], 9.5, 'm')

print()
print('%-46s %16s %16s %-4s %9s' % ('yade-dda demo', 'DDA', 'closed form', '', 'rel.err'))
for name, value, expected, unit, error in rows:
    print('%-46s %16.9g %16.9g %-4s %9.1e' % (name, value, expected, unit, error))
printStats()
worst = max(r[4] for r in rows)
print('largest relative error %.1e: %s' % (worst, 'OK' if worst < 0.01 else 'FAILED'))
if worst >= 0.01:
    raise SystemExit(1)
