# -*- coding: utf-8 -*-
"""A scene for the accuracy sweep (doc/benchmarks.md, "Your own scene"): your own scene has the same shape.

A 1 m cube of rock slides across a fixed floor with v0 = 2 m/s and stops by
Coulomb friction (phi = 30 deg). Closed form: the deceleration is g tan(phi),
so it stops after s = v0^2 / (2 g tan(phi)) = 0.353 m, at t = 0.35 s; by
tEnd = 0.6 s it rests there.

Before the core's friction rules were fixed, the cube slid only 3 mm: its
contacts with the floor were new in the first step and started locked, the
spring held the whole step's slip and tipped the cube, and the tipped solve's
normal force drove the next solve's friction (speed 2.0 -> 1.2 m/s in one
step). New contacts whose blocks move apart tangentially now start sliding,
and sliding contacts iterate until their normal force settles; the same
physics is a test (tests/py/contact/test_contact_physics.py,
test_block_launched_along_floor_slides_to_a_stop).

The sweep needs three names (SI units):
    build()   makes the scene; O is already reset. One DDAIntegrator in O.engines
              (the swept knob is set on it afterwards; an MSCCollider is added for
              criticalLength / segments when the scene has none).
    measure() after the run: the error against the closed form (a float, or a dict
              with 'error' and anything else worth keeping).
    tEnd      simulated time of each run [s].
and may set `base`, knob settings for every run (e.g. {'maxDisplacement': 0.01}).

Sweep it:
    /usr/bin/python3 bench/accuracy.py --scene examples/accuracy_scene.py --knob dt=1e-2,3e-3,1e-3 \
        --out bench/out/my_scene.json
or from Python (any YADE script or /usr/bin/python3):
    import yade_dda, runpy
    s = runpy.run_path('examples/accuracy_scene.py')
    points = yade_dda.accuracySweep(s['build'], s['measure'], 'dt', [1e-2, 1e-3], tEnd=s['tEnd'])
"""
import math

from yade_dda import O, ddaBlock, DDAIntegrator, block, boxCorners
from yade import wrapper

G, PHI_DEG, V0 = 9.81, 30.0, 2.0
tEnd = 0.6
base = {'maxDisplacement': 0.01}
_ids = {}


box = boxCorners   # the 8 corners of the box from lo to hi [m]


def build():
    rock = O.materials.append(wrapper.PolyhedraMat(young=1e10, poisson=0.25, density=2600,
                                                   frictionAngle=math.radians(PHI_DEG)))
    O.bodies.append(ddaBlock(box((-2, -2, -1), (4, 2, 0)), material=rock, fixed=True))
    _ids['cube'] = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=rock,
                                            velocity=(V0, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda')]


def measure():
    stop = V0 ** 2 / (2 * G * math.tan(math.radians(PHI_DEG)))
    slid = block(_ids['cube']).centroid[0]
    return dict(error=abs(slid - stop), slid=slid, exact=stop, speed=abs(block(_ids['cube']).velocity[0]))
