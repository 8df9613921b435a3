# -*- coding: utf-8 -*-
"""A block on an incline on a shaking table: DDA's slip against Newmark's sliding block.

A rigid 1 m x 1 m x 0.4 m block rests on a slab whose top dips ALPHA = 20 deg towards +x;
friction angle PHI = 30 deg. The slab is a fixed block given a horizontal base acceleration
a(t) = A sin(w t) towards the uphill side (baseMotion), A = 0.5 g at 2 Hz, for CYCLES cycles.

Newmark (1965): the block slips downhill while a(t) exceeds the yield acceleration
a_y = g tan(PHI - ALPHA) (0.176 g here), with s'' = k (a - a_y), k = cos(PHI - ALPHA) / cos(PHI),
until its relative velocity returns to zero. The script integrates that equation numerically
(1e-5 s) and prints it beside DDA's slip at each cycle's end, and records the base's motion
with yade.plot (baseMotionRecord).

Run:  yade -n -x examples/shaking_table.py       (or /usr/bin/python3 examples/shaking_table.py)
"""
import math

from yade_dda import O, DDAIntegrator, ddaBlock, rigidBlock, baseMotion, baseMotionRecord, block
from yade import wrapper, plot

G = 9.81
ALPHA, PHI = math.radians(20.0), math.radians(30.0)
A, W, CYCLES = 0.5 * G, 4 * math.pi, 3
PERIOD = 2 * math.pi / W


def slope_box(lo, hi):
    """Corners of a box given in slope coordinates (x downhill, z normal to the slope) [m]."""
    down = (math.cos(ALPHA), 0.0, -math.sin(ALPHA))
    normal = (math.sin(ALPHA), 0.0, math.cos(ALPHA))
    corners = []
    for i in range(8):
        x, y, z = (hi[0] if i & 1 else lo[0]), (hi[1] if i & 2 else lo[1]), (hi[2] if i & 4 else lo[2])
        corners.append(tuple(x * down[k] + z * normal[k] + (y if k == 1 else 0.0) for k in range(3)))
    return corners


def newmark(t_end, h=1e-5):
    """Newmark's slip [m] by time t_end [s] under A sin(W t)."""
    ay, k = G * math.tan(PHI - ALPHA), math.cos(PHI - ALPHA) / math.cos(PHI)
    v = s = 0.0
    for i in range(int(round(t_end / h))):
        a0, a1 = A * math.sin(W * i * h), A * math.sin(W * (i + 1) * h)
        if v > 0 or a0 > ay or a1 > ay:
            v1 = max(0.0, v + 0.5 * h * k * (a0 + a1 - 2 * ay))
            s, v = s + 0.5 * h * (v + v1), v1
    return s


rock = O.materials.append(wrapper.PolyhedraMat(young=1e10, poisson=0.25, density=2600, frictionAngle=PHI))
slab = O.bodies.append(ddaBlock(slope_box((-3.0, -1.5, -1.0), (4.0, 1.5, 0.0)), material=rock, fixed=True))
blk = O.bodies.append(rigidBlock(slope_box((0.0, -0.5, 0.0), (1.0, 0.5, 0.4)), material=rock))
baseMotion(slab, acceleration=lambda t: A * math.sin(W * t), direction=(-1, 0, 0), sampling=1e-3,
           duration=CYCLES * PERIOD)
O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), staticFrictionExcess=0.0, label='dda')]

downhill = (math.cos(ALPHA), 0.0, -math.sin(ALPHA))
b0, s0 = block(blk).centroid, block(slab).centroid


def slip():
    d = (block(blk).centroid - b0) - (block(slab).centroid - s0)
    return sum(d[k] * downhill[k] for k in range(3))


print('cycle  time [s]   DDA slip [m]   Newmark [m]   difference')
for cycle in range(1, CYCLES + 1):
    while O.time < cycle * PERIOD - 1e-12:
        O.run(min(10, max(1, int((cycle * PERIOD - O.time) / 1e-3 * 0.999))), True)   # 10 ms between records
        plot.addData(t=O.time, slip=slip(), **baseMotionRecord())
    reference = newmark(O.time)
    print('%5d  %8.4f   %12.6f   %11.6f   %+9.3f %%'
          % (cycle, O.time, slip(), reference, 100 * (slip() - reference) / reference))
plot.plots = {'t': ('slip', 'baseUx')}
