"""Benchmark: energy of a dropped pile of cubes against Young's modulus (issue 17).

30 slightly turned 1 m cubes (density 2600 kg/m^3, 30 deg friction) in layers
of 3 x 3, 0.1 m apart, dropped onto a fixed floor with every integrator setting
at its default, for 0.6 s. For each E it records what the hard-case tests
assert and what it costs:
- gain: the largest rise of kinetic (translation) plus potential energy above
  its start, relative to the start (must stay below 1e-3; the contact law
  before issue 17 gained 5-36% on 200 cubes at 1e11 Pa);
- speed: the fastest centroid over the free-fall bound sqrt(2 g z_top) (<= 1);
- drift: the energy account's sum minus loads minus contactChanges, its change
  over the run relative to the largest change of any term (the account's
  conservation law; exact only for small strains);
- contactChanges: the energy the contacts' springs gained between steps, over
  the same scale (negative: lost);
- steps, solves per step, dt cuts, friction-limit passes and unsettled groups,
  wall seconds.

Writes bench/out/energy.json and prints a table. SI units.
Run: make bench (or /usr/bin/python3 bench/energy.py [--youngs 1e5 1e11] [--time 0.6]).
"""
import argparse
import json
import math
import os
import random
import time

import sys

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator, block
from yade import wrapper

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'py'))
from helpers import box, rotate  # noqa: E402  (the tests' shapes: same piles as test_energy_and_creep.py)

G = 9.81
SEED = 20261125


def run(young, duration, count=30):
    O.reset()
    rng = random.Random(SEED)
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    O.bodies.append(ddaBlock(box((-2, -2, -1), (6, 6, 0)), material=rock, fixed=True))
    cubes = []
    for k in range(count):
        i, j, layer = k % 3, (k // 3) % 3, k // 9
        x, y, z = 0.1 + 1.1 * i, 0.1 + 1.1 * j, 0.2 + 1.1 * layer
        pts = rotate(box((x, y, z), (x + 1, y + 1, z + 1)), (rng.random(), rng.random(), rng.random()),
                     rng.uniform(-0.1, 0.1), about=(x + .5, y + .5, z + .5))
        cubes.append(O.bodies.append(ddaBlock(pts, material=rock)))
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), label='dda')]

    def translational():
        energy, fastest = 0.0, 0.0
        for b in cubes:
            blk = block(b)
            v = blk.velocity
            speed2 = v[0] ** 2 + v[1] ** 2 + v[2] ** 2
            energy += blk.mass * G * blk.centroid[2] + 0.5 * blk.mass * speed2
            fastest = max(fastest, math.sqrt(speed2))
        return energy, fastest

    def account(e):
        return e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']

    start = time.time()
    O.run(1, True)
    e0, _ = translational()
    top = max(block(b).centroid[2] for b in cubes)
    bound = math.sqrt(2 * G * top)
    a0 = dict(yade_dda.stats()['energy'])
    gain, speed, drift, changes, steps, solves, cuts, passes, unsettled = 0.0, 0.0, 0.0, 0.0, 1, 0, 0, 0, 0
    while O.time < duration:
        O.run(1, True)
        s = yade_dda.stats()
        steps += 1
        solves += s['openCloseIterationsTotal']
        cuts += s['stepCuts']
        passes += s['limitPasses']
        unsettled += s['limitsUnsettled']
        if steps % 10:
            continue
        e, fastest = translational()
        gain = max(gain, (e - e0) / e0)
        speed = max(speed, fastest / bound)
        a = s['energy']
        scale = max(abs(a[k] - a0[k]) for k in a)
        drift = max(drift, abs(account(a) - account(a0) - (a['contactChanges'] - a0['contactChanges'])) / scale)
        changes = (a['contactChanges'] - a0['contactChanges']) / scale
    return dict(young=young, blocks=count, time=O.time, gain=gain, speedOverFreeFall=speed, accountDrift=drift,
                contactChanges=changes, steps=steps, solvesPerStep=solves / steps, dtCuts=cuts, limitPasses=passes,
                limitsUnsettled=unsettled, wallSeconds=time.time() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--youngs', type=float, nargs='+', default=[1e5, 1e7, 1e9, 1e11])
    parser.add_argument('--time', type=float, default=0.6)
    parser.add_argument('--out', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), 'out'))
    args = parser.parse_args()
    rows = [run(E, args.time) for E in args.youngs]
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, 'energy.json'), 'w') as f:
        json.dump(dict(seed=SEED, rows=rows), f, indent=1)
    print('%8s %9s %8s %9s %9s %6s %7s %5s %7s %6s' % ('E [Pa]', 'gain', 'speed', 'drift', 'changes', 'steps',
                                                        'solves', 'cuts', 'passes', 'wall'))
    for r in rows:
        print('%8.0e %9.1e %8.3f %9.1e %9.1e %6d %7.1f %5d %7d %6.1f' % (
            r['young'], r['gain'], r['speedOverFreeFall'], r['accountDrift'], r['contactChanges'], r['steps'],
            r['solvesPerStep'], r['dtCuts'], r['limitPasses'], r['wallSeconds']))


if __name__ == '__main__':
    main()
