"""Benchmark: why the frictional slides' error grows as dt shrinks.

A 1 m cube (density 2600 kg/m^3) starts at rest on a fixed slab, gravity
tilted 30 deg, friction 20 deg: it must slide with a = g (sin a - tan phi
cos a) (Coulomb). After 3 ms of simulated time we record the error of its
velocity along the slope against a t [m/s] for a rigid block whose four
corner contacts start preloaded (each compressed by m g cos a / (4 kn), the
share of the weight it carries at rest) or unloaded, and for a deformable
block, against dt and the penalty factor.

What it shows (doc/benchmarks.md, "What accuracy costs"): the error is the penalty
model's start-up, not the time scheme's. In the first step the contacts
are locked and their shear springs stretch while the block accelerates; a
dt that resolves the springs' period lets the block leave that step faster
than Coulomb friction allows, by about F / (m omega), and it keeps that
speed. A larger dt damps the start-up (Newmark gamma = 1). Stiffer springs
move the onset to smaller dt and shrink the error as 1 / sqrt(kn).

Writes bench/out/friction_startup.json and prints a table. SI units.
Run: make bench (or /usr/bin/python3 bench/friction_startup.py).
"""
import argparse
import json
import math
import os

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator, block
from yade import wrapper

G = 9.81
SLOPE = math.radians(30.0)
FRICTION = math.radians(20.0)
DENSITY = 2600.0
DURATION = 3e-3  # s


def _box(lo, hi):
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def velocityError(dt, penaltyFactor=40.0, rigid=True, preloaded=True, young=1e10, startFromRest=False):
    """Velocity along the slope minus Coulomb's a t [m/s] after DURATION of a 1 m
    cube started at rest; preloaded: its four contacts start compressed by their
    share of the weight (kn = penaltyFactor x E x 1 m, as the core sets it);
    startFromRest: the integrator's settling (static equilibrium with friction
    locked, then the dynamics) instead, the default of DDAIntegrator."""
    O.reset()
    mat = O.materials.append(wrapper.PolyhedraMat(young=young, poisson=0.25, density=DENSITY,
                                                  frictionAngle=FRICTION))
    O.bodies.append(ddaBlock(_box((-1, -1.5, -1), (5, 1.5, 0)), material=mat, fixed=True))
    kn = penaltyFactor * young * 1.0
    z0 = -DENSITY * G * math.cos(SLOPE) / (4 * kn) if preloaded else 0.0
    cube = O.bodies.append(ddaBlock(_box((-0.5, -0.5, z0), (0.5, 0.5, 1 + z0)), material=mat, rigid=rigid))
    O.engines = [DDAIntegrator(dt=dt, gravity=(G * math.sin(SLOPE), 0, -G * math.cos(SLOPE)),
                               maxDisplacement=0.01, contactPenaltyFactor=penaltyFactor, threads=1,
                               startFromRest=startFromRest)]
    O.run(int(round(DURATION / dt)), True)
    acceleration = G * (math.sin(SLOPE) - math.tan(FRICTION) * math.cos(SLOPE))
    return block(cube).velocity[0] - acceleration * O.time


CASES = [dict(rigid=True, preloaded=True, penaltyFactor=f) for f in (40.0, 400.0, 4000.0)] + \
        [dict(rigid=True, preloaded=False, penaltyFactor=40.0),
         dict(rigid=False, preloaded=False, penaltyFactor=40.0),
         dict(rigid=True, preloaded=False, penaltyFactor=40.0, startFromRest=True),
         dict(rigid=False, preloaded=False, penaltyFactor=40.0, startFromRest=True)]
STEPS = [1e-3, 1e-4, 1e-5]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), 'out'))
    args = parser.parse_args()
    rows = []
    for case in CASES:
        errors = {dt: velocityError(dt, **case) for dt in STEPS}
        rows.append(dict(case, errors={'%g' % dt: e for dt, e in errors.items()}))
        start = 'settled' if case.get('startFromRest') else 'preloaded' if case['preloaded'] else 'unloaded'
        print('%-10s %-9s penalty %6g  ' % ('rigid' if case['rigid'] else 'deformable', start, case['penaltyFactor'])
              + '  '.join('dt %g: %9.2e m/s' % (dt, e) for dt, e in errors.items()))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, 'friction_startup.json')
    with open(path, 'w') as f:
        json.dump(dict(duration=DURATION, slopeDeg=30.0, frictionDeg=20.0, young=1e10, rows=rows), f, indent=1)
    print('wrote', path)


if __name__ == '__main__':
    main()
