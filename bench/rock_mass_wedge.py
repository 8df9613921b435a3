"""Benchmark: a kinematically free wedge in a cut, jointed slope against Hoek and Bray's rate.

A 10 m x 8 m x 6 m box (x east, y north, z up) with a slope face dipping 70 deg east through
the crest (6, 0, 6) m (the rock beyond excavated), cut by two single joints, A (dip 60 deg,
dip direction 30 deg) and B (dip 60 deg, dip direction 150 deg), both through (3, 4, 6) m:
their line of intersection plunges 40.9 deg east and daylights in the face at z = 2.2 m, so
the rock above both planes is a wedge free to slide along it. A horizontal joint set
(spacing 1.5 m) cuts the whole box, and, by variant, vertical sets too: 'horizontal' (none),
'x' (planes normal to x, spacing 2.2 m), 'y' (normal to y, spacing 2.1 m) and 'xy' (both).
Every joint has the friction angle phi (25 deg by default: the wedge's factor of safety
is 0.81, the horizontal joints hold); blocks touching the box's back (x = 0), sides (y = 0
and 8 m) or base are held; E = 1e9 Pa, start from rest, dt = 1e-3 s. cutRockMass keeps
every block (minVolume=0), so no sliver is merged across a wedge plane.

Closed form: the wedge (all blocks above both planes, which slide together) accelerates
along the line of intersection at g sin(plunge) (1 - FS), FS from the planes' normal
reactions (tests/py/scenes.py, wedge_factor_of_safety). Per variant it records the wedge's
mass-weighted displacement along the line, the acceleration fitted to it from 0.1 s on,
both against the closed form, the spread of the wedge blocks' displacements and the
largest displacement of any other free block, and the start from rest's report.

Writes bench/out/rock_mass_wedge.json (--out) and prints a line per variant. SI units.
Run: /usr/bin/python3 bench/rock_mass_wedge.py [--variants horizontal,x,y,xy] [--time 0.3]
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if os.environ.get('YADE_DDA_BUILD'):
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator, cutRockMass  # noqa: E402
from yade import PolyhedraMat  # noqa: E402
import scenes as S  # noqa: E402

G = 9.81
SIZE = (10.0, 8.0, 6.0)        # [m]
APEX = (3.0, 4.0, 6.0)         # both wedge planes pass through this point [m]
DIP, DIR_A, DIR_B = 60.0, 30.0, 150.0
SLOPE, CREST = 70.0, (6.0, 0.0, 6.0)
VERTICAL = {'x': dict(dip=90.0, dipDirection=90.0, spacing=2.2, origin=(0.7, 0.0, 0.0)),
            'y': dict(dip=90.0, dipDirection=0.0, spacing=2.1, origin=(0.0, 0.6, 0.0))}


def joint_sets(variant):
    a = math.radians(SLOPE)
    sets = [dict(dip=DIP, dipDirection=DIR_A, spacing=100.0, origin=APEX),
            dict(dip=DIP, dipDirection=DIR_B, spacing=100.0, origin=APEX),
            dict(dip=0.0, dipDirection=0.0, spacing=1.5, origin=(0.0, 0.0, 0.25))]
    sets += [VERTICAL[k] for k in ('x', 'y') if k in variant and variant != 'horizontal']
    sets.append(dict(excavate=(CREST, (math.sin(a), 0.0, math.cos(a)))))
    return sets


def held(corners):
    L, W, _ = SIZE
    return any(p[2] <= 1e-9 or p[0] <= 1e-9 or p[1] <= 1e-9 or p[1] >= W - 1e-9 for p in corners)


def run(variant, phi, duration, young):
    O.reset()
    L, W, H = SIZE
    box = [(x, y, z) for x in (0, L) for y in (0, W) for z in (0, H)]
    rock = cutRockMass(box, joint_sets(variant), seed=1, minVolume=0)
    nA = np.array(S.upward_normal(math.radians(DIP), math.radians(DIR_A)))
    nB = np.array(S.upward_normal(math.radians(DIP), math.radians(DIR_B)))
    line, plunge = S.wedge_line(tuple(nA), tuple(nB))
    line = np.array(line)
    fs = S.wedge_factor_of_safety(tuple(nA), tuple(nB), math.radians(phi), math.radians(phi))
    closed = G * math.sin(plunge) * (1 - fs)
    mat = O.materials.append(PolyhedraMat(young=young, poisson=0.25, density=2600.0,
                                          frictionAngle=math.radians(phi)))
    free, wedge = [], []
    for b in rock:
        i = O.bodies.append(ddaBlock(b.corners, material=mat, fixed=held(b.corners)))
        if held(b.corners):
            continue
        free.append(i)
        c = np.mean(np.array(b.corners), axis=0) - np.array(APEX)
        if c @ nA > 0 and c @ nB > 0:
            wedge.append(i)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), threads=1, label='dda')]
    start = time.time()
    O.step()
    st = yade_dda.stats()
    settle = dict(steps=st['settleSteps'], converged=st['settleConverged'], unsettled=list(st['unsettledBlocks']))
    c0 = {i: np.array(yade_dda.block(i).centroid) for i in free}
    mass = {i: yade_dda.block(i).mass for i in wedge}
    total = sum(mass.values())
    track = []
    while O.time < duration - 1e-9:
        O.run(10, True)
        along = sum(mass[i] * (np.array(yade_dda.block(i).centroid) - c0[i]) @ line for i in wedge) / total
        track.append((O.time, along))
    t, x = np.array(track).T
    m = t >= 0.1 - 1e-9
    fitted = np.linalg.lstsq(np.c_[np.ones(m.sum()), t[m], 0.5 * t[m] ** 2], x[m], rcond=None)[0][2]
    each = [(np.array(yade_dda.block(i).centroid) - c0[i]) @ line for i in wedge]
    rest = [np.linalg.norm(np.array(yade_dda.block(i).centroid) - c0[i]) for i in free if i not in wedge]
    return dict(variant=variant, phi=phi, young=young, blocks=len(rock), free=len(free), wedge=len(wedge),
                wedgeMass=total, plungeDeg=math.degrees(plunge), factorOfSafety=fs, closedAcceleration=closed,
                fittedAcceleration=fitted, time=float(t[-1]), displacement=float(x[-1]),
                closedDisplacement=0.5 * closed * float(t[-1]) ** 2,
                spread=float(max(each) - min(each)) if each else 0.0, restMoved=float(max(rest, default=0.0)),
                settle=settle, wall=time.time() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--variants', default='horizontal,x,y,xy')
    parser.add_argument('--phi', type=float, default=25.0, help='friction angle of every joint [deg]')
    parser.add_argument('--time', type=float, default=0.3, help='simulated time [s]')
    parser.add_argument('--young', type=float, default=1e9, help="Young's modulus [Pa]")
    parser.add_argument('--out', default=os.path.join(HERE, 'out'))
    args = parser.parse_args()
    rows = []
    for variant in args.variants.split(','):
        r = run(variant, args.phi, args.time, args.young)
        rows.append(r)
        print('%-10s %3d blocks %3d free %2d in the wedge (%.0f kg)  FS %.3f  a %.4f m/s^2 (closed %.4f, %+.1f%%)  '
              'moved %.5f m (closed %.5f)  spread %.1e m  rest %.1e m  settle %d steps %s, %d unsettled  %.0f s'
              % (variant, r['blocks'], r['free'], r['wedge'], r['wedgeMass'], r['factorOfSafety'],
                 r['fittedAcceleration'], r['closedAcceleration'],
                 100 * (r['fittedAcceleration'] / r['closedAcceleration'] - 1), r['displacement'],
                 r['closedDisplacement'], r['spread'], r['restMoved'], r['settle']['steps'],
                 r['settle']['converged'], len(r['settle']['unsettled']), r['wall']), flush=True)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, 'rock_mass_wedge.json')
    with open(path, 'w') as f:
        json.dump(dict(size=SIZE, apex=APEX, planes=[(DIP, DIR_A), (DIP, DIR_B)], slope=SLOPE, rows=rows), f, indent=1)
    print('wrote', path)


if __name__ == '__main__':
    main()
