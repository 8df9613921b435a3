"""Benchmark: how much of an elastic bounce's energy each time scheme keeps.

A frictionless 1 m cube (2600 kg/m^3) dropped flat from 0.5 m onto a fixed floor,
rigid or deformable, E = 1e8 or 1e10 Pa, under Shi's scheme (newmarkGamma 1, the
default), gamma 0.75 and average acceleration (gamma 1/2; beta = gamma/2 always),
dt 1e-3 and 1e-4 s. Records the first rebound's apex as a fraction of the drop
height (the restitution of the energy; the apex is sampled every 10 steps), the
mechanical energy (stats()['energy']: kinetic with rotation and strain rates, plus
gravity, strain and contact) at that apex over the drop energy, and the wall time.

What it shows (doc/benchmarks.md, "What accuracy costs"): Shi's scheme damps the contact's
vibration, so the bounce loses most of its energy unless dt resolves the contact
(pi sqrt(m / 4 kn)); average acceleration with its secant contact force keeps a
rigid cube's energy exactly at any dt, and, without strain viscosity, a deformable
cube's within about 2% (the impact excites the block's strain modes, which keep part
of it: the apex alone is lower). Deformable cubes run with the default strain
viscosity (strainDamping 0.5), which dissipates much of what the impact puts into
strain, and without it.

Writes bench/out/bounce.json and prints a table. SI units.
Run: make bench (or /usr/bin/python3 bench/bounce.py).
"""
import argparse
import json
import os
import sys
import time

if os.environ.get('YADE_DDA_BUILD'):
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator, block  # noqa: E402
from yade import wrapper  # noqa: E402

G = 9.81
HEIGHT = 0.5


def box(lo, hi):
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def firstBounce(gamma, dt, young, rigid, zeta):
    O.reset()
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25, frictionAngle=0))
    O.bodies.append(ddaBlock(box((-2, -2, -1), (3, 3, 0)), material=rock, fixed=True))
    cube = O.bodies.append(ddaBlock(box((0, 0, HEIGHT), (1, 1, 1 + HEIGHT)), material=rock, rigid=rigid))
    O.engines = [DDAIntegrator(dt=dt, gravity=(0, 0, -G), maxDisplacement=0.01, newmarkBeta=gamma / 2,
                               newmarkGamma=gamma, strainDamping=zeta, threads=1)]
    mass = block(cube).mass
    drop = mass * G * HEIGHT
    start = time.time()
    O.run(1, True)
    e0 = yade_dda.stats()['energy']
    mech = lambda e: e['kinetic'] + e['gravity'] + e['strain'] + e['contact']
    rising, top, kept = False, 0.0, None
    while O.time < 1.0:
        O.run(10, True)
        b = block(cube)
        h = b.centroid[2] - 0.5
        if b.velocity[2] > 0 and h > 1e-3:
            rising, top = True, max(top, h)
        elif rising and b.velocity[2] <= 0:
            kept = (mech(yade_dda.stats()['energy']) - mech(e0)) / drop + 1
            break
    return dict(apex=top / HEIGHT, mechanical=kept, wall=time.time() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), 'out'))
    args = parser.parse_args()
    rows = []
    for rigid in (True, False):
        # The strain viscosity acts on deformable blocks only: its default (0.5) and none.
        for zeta in ((0.5,) if rigid else (0.5, 0.0)):
            for young in (1e8, 1e10):
                for gamma in (1.0, 0.75, 0.5):
                    for dt in (1e-3, 1e-4):
                        r = dict(rigid=rigid, strainDamping=zeta, young=young, gamma=gamma, dt=dt,
                                 **firstBounce(gamma, dt, young, rigid, zeta))
                        rows.append(r)
                        print('%-10s zeta %.1f E %6.0e gamma %.2f dt %6.0e  apex %.3f  mechanical %s  %.1f s'
                              % ('rigid' if rigid else 'deformable', zeta, young, gamma, dt, r['apex'],
                                 '%.3f' % r['mechanical'] if r['mechanical'] is not None else '-', r['wall']),
                              flush=True)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, 'bounce.json')
    with open(path, 'w') as f:
        json.dump(dict(height=HEIGHT, rows=rows), f, indent=1)
    print('wrote', path)


if __name__ == '__main__':
    main()
