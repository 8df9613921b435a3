"""Benchmark: contact scenes. Open-close iterations and step time on a 100-block
pile and a 10-cube tower; error of the frictional incline against dt.

Writes bench/out/contacts.json and prints a table.
Run: make bench (or /usr/bin/python3 bench/contacts.py [--quick]).
"""
import argparse
import json
import math
import os
import random
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from yade import wrapper  # noqa: E402
from helpers import box, rotate  # noqa: E402


def material(frictionDeg, young=1e9):
    return O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=math.radians(frictionDeg)))


def pile(seconds, seed=3):
    """100 unit cubes, 5 x 5 x 4, slightly rotated, dropped into a fixed box."""
    O.reset()
    rng = random.Random(seed)
    wall = material(30)
    rock = material(30)
    O.bodies.append(ddaBlock(box((-1, -1, -1), (7, 7, 0)), material=wall, fixed=True))
    for lo, hi in (((-1, -1, 0), (0, 7, 8)), ((6, -1, 0), (7, 7, 8)), ((0, -1, 0), (6, 0, 8)), ((0, 6, 0), (6, 7, 8))):
        O.bodies.append(ddaBlock(box(lo, hi), material=wall, fixed=True))
    for k in range(100):
        i, j, layer = k % 5, (k // 5) % 5, k // 25
        x, y, z = 0.15 + 1.175 * i, 0.15 + 1.175 * j, 0.3 + 1.5 * layer  # 0.15 m from the walls: turned 0.2 rad, a cube reaches 0.12 m further
        centre = (x + 0.45, y + 0.45, z + 0.45)
        pts = rotate(box((x, y, z), (x + 0.9, y + 0.9, z + 0.9)), (rng.random(), rng.random(), rng.random()),
                     rng.uniform(-0.2, 0.2), about=centre)
        O.bodies.append(ddaBlock(pts, material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.005, label='dda')]
    return measure('pile of 100 cubes', seconds)


def tower(seconds):
    """10 unit cubes stacked exactly on a fixed floor."""
    O.reset()
    rock = material(30)
    O.bodies.append(ddaBlock(box((-5, -5, -1), (5, 5, 0)), material=rock, fixed=True))
    for k in range(10):
        O.bodies.append(ddaBlock(box((-0.5, -0.5, k), (0.5, 0.5, k + 1)), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.005, label='dda')]
    return measure('tower of 10 cubes', seconds)


def measure(name, seconds):
    O.run(1, True)
    start = time.perf_counter()
    before = yade_dda.stats()
    steps = 0
    iterations = []
    coreTimes = []
    contacts = []
    cuts = 0
    while O.time < seconds:
        O.run(1, True)
        s = yade_dda.stats()
        steps += 1
        iterations.append(s['openCloseIterationsTotal'])
        coreTimes.append(s['time']['core'])
        contacts.append(s['contacts'])
        cuts += s['openCloseCuts']
    wall = time.perf_counter() - start
    after = yade_dda.stats()
    return dict(scene=name, simulatedSeconds=O.time, steps=steps,
                openCloseIterationsPerStep=sum(iterations) / steps, maxOpenCloseIterations=max(iterations),
                openCloseCuts=cuts, coreMsPerStep=1e3 * sum(coreTimes) / steps,
                engineMsPerStep=1e3 * (after['stepTimeTotal'] - before['stepTimeTotal']) / steps,
                wallMsPerStep=1e3 * wall / steps, meanContacts=sum(contacts) / steps,
                closedContactsEnd=after['closedContacts'], maxPenetrationEnd=after['maxPenetration'])


def incline(dt, phiDeg=20, slopeDeg=30, seconds=1.0):
    """Block on a frictional incline (gravity tilted); relative error of the slope displacement."""
    O.reset()
    rock = material(phiDeg)
    g, a = 9.81, math.radians(slopeDeg)
    O.bodies.append(ddaBlock(box((-20, -5, -1), (20, 5, 0)), material=rock, fixed=True))
    b = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=rock))
    O.engines = [DDAIntegrator(dt=dt, gravity=(g * math.sin(a), 0, -g * math.cos(a)), maxDisplacement=0.01)]
    start = time.perf_counter()
    O.run(int(round(seconds / dt)), True)
    wall = time.perf_counter() - start
    acc = g * (math.sin(a) - math.tan(math.radians(phiDeg)) * math.cos(a))
    exact = 0.5 * acc * O.time ** 2
    moved = yade_dda.block(b).centroid[0]
    return dict(dt=dt, time=O.time, displacement=moved, exact=exact, relativeError=(moved - exact) / exact,
                wallSeconds=wall)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--quick', action='store_true', help='shorter runs')
    parser.add_argument('--out', default=os.path.join(os.path.dirname(__file__), 'out', 'contacts.json'))
    args = parser.parse_args()
    seconds = 0.3 if args.quick else 1.0
    scenes = [pile(seconds), tower(seconds)]
    inclines = [incline(dt) for dt in (1e-2, 3e-3, 1e-3, 3e-4, 1e-4)]
    print('%-20s %8s %10s %10s %8s %10s %10s' % ('scene', 'steps', 'OCI/step', 'max OCI', 'cuts', 'core ms', 'contacts'))
    for r in scenes:
        print('%-20s %8d %10.2f %10d %8d %10.3f %10.1f' % (r['scene'], r['steps'], r['openCloseIterationsPerStep'],
                                                           r['maxOpenCloseIterations'], r['openCloseCuts'],
                                                           r['coreMsPerStep'], r['meanContacts']))
    print('\nincline, friction 20 deg on 30 deg, 1 s:')
    print('%10s %14s %14s %12s' % ('dt [s]', 'displacement', 'rel. error', 'wall [s]'))
    for r in inclines:
        print('%10.0e %14.6f %14.3e %12.3f' % (r['dt'], r['displacement'], r['relativeError'], r['wallSeconds']))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(scenes=scenes, incline=inclines), f, indent=1)
    print('\nwrote', args.out)


if __name__ == '__main__':
    main()
