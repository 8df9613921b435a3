"""Benchmark: jointed rock masses at rest (SI units: m, s, J).

Seeded confined masses of tests/py/rockmass_scenes.py (a cube cut by three
joint sets at 1 m, the blocks touching its sides or base held, E = 1e9 Pa,
friction 35 deg above every joint's dip), started from rest (the default) and
run for a given time at dt = 1e-3 s on one thread. Per case: blocks, free
blocks, the start from rest (static steps, open-close solves, converged, the blocks it could not
hold, its wall time), then per step the mean and largest open-close solves and
friction-limit passes, step cuts, the mean wall time and
its phases (narrow phase, assembly, solve), the free blocks' largest speed at
the end and the energy account's contact changes. Each case runs in its own
process (one YADE scene per process).

Writes bench/out/rock_mass_rest.json and prints a table.
Run: /usr/bin/python3 bench/rock_mass_rest.py [--cases junctions,oblique-4,...] [--time 0.2]
[--set NAME=VALUE ...] (DDAIntegrator settings for every case)
A case is 'junctions' (the fixed 5 m cube whose held base tetrahedra expose
only their bases) or KIND-SIDE[-SEED[-pPERSISTENCE][-sSLOPE]] with KIND oblique
or orthogonal, SIDE the cube's edge [m] (seed 1 unless given), PERSISTENCE the
last steep set's persistence (concave blocks) and SLOPE the dip [deg] of a cut
face (tests/py/rockmass_scenes.py, draw_case), e.g. oblique-6-1-p0.7-s60.
"""
import argparse
import json
import os
import sys
import time

import benchtasks  # bench/benchtasks.py: the RESULT protocol and the timed steps

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_CASES = ','.join(['junctions'] + ['%s-4-%d' % (kind, seed) for kind in ('oblique', 'orthogonal')
                                           for seed in range(1, 7)] + ['oblique-6', 'orthogonal-6'])


def run_case(name, duration, settings=None):
    """One case in this process: a dict of its numbers."""
    sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'py'))
    import yade_dda
    from yade_dda import O
    import rockmass_scenes as R
    if name == 'junctions':
        case = R.JUNCTIONS_CASE
    else:
        parts = name.split('-')
        options = dict(persistence=None, slope=None)
        for part in parts[3:]:
            options[{'p': 'persistence', 's': 'slope'}[part[0]]] = float(part[1:])
        case = R.draw_case(int(parts[2]) if len(parts) > 2 else 1, kind=parts[0], side=float(parts[1]), **options)
    ids, fixed, free = R.build_scene(case, dt=1e-3, threads=1, **(settings or {}))
    start = time.time()
    O.step()
    first = yade_dda.stats()
    settle = time.time() - start
    solves, passes, cuts, wall, narrow, assembly, solve = [], 0, 0, 0.0, 0.0, 0.0, 0.0
    changes0 = first['energy']['contactChanges']
    while O.time < duration:
        t = time.time()
        O.step()
        wall += time.time() - t
        s = yade_dda.stats()
        solves.append(s['openCloseIterations'])
        passes += s['limitPasses']
        cuts += s['stepCuts']
        narrow += s['time']['narrowPhase']
        assembly += s['time']['assembly']
        solve += s['time']['solve']
    n = len(solves)
    return dict(case=name, description=R.describe(case), blocks=len(ids), free=len(free),
                settleSteps=first['settleSteps'], settleSolves=first['settleSolves'],
                settleConverged=bool(first['settleConverged']),
                unsettled=len(first['unsettledBlocks']),
                settleSeconds=settle, steps=n, meanSolves=sum(solves) / n, mostSolves=max(solves), meanPasses=passes / n, stepCuts=cuts,
                msPerStep=1e3 * wall / n, msNarrowPhase=1e3 * narrow / n, msAssembly=1e3 * assembly / n,
                msSolve=1e3 * solve / n, largestSpeed=max(O.bodies[i].state.vel.norm() for i in free),
                contactChanges=s['energy']['contactChanges'] - changes0, time=O.time)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--cases', default=DEFAULT_CASES)
    parser.add_argument('--time', type=float, default=0.2, help='simulated time after the start from rest [s]')
    parser.add_argument('--set', action='append', default=[], metavar='NAME=VALUE',
                        help='a DDAIntegrator setting for every case (a number), e.g. --set staticFrictionExcess=0')
    parser.add_argument('--one', help=argparse.SUPPRESS)
    args = parser.parse_args()
    settings = {k: float(v) for k, v in (item.split('=', 1) for item in args.set)}
    if args.one:
        benchtasks.printResult(run_case(args.one, args.time, settings))
        return
    rows = []
    for name in args.cases.split(','):
        rows.append(benchtasks.resultOf([sys.executable, os.path.abspath(__file__), '--one', name, '--time',
                                         str(args.time)] + ['--set=' + item for item in args.set], 'case %s' % name))
        r = rows[-1]
        print('%-14s %5d blocks %4d free  settle %2d steps %5d solves %-5s unsettled %d %6.1f s | %4d steps  solves %5.2f '
              '(most %2d)  passes %.2f  cuts %d  '
              '%7.1f ms/step (narrow %.1f, assembly %.1f, solve %.1f)  speed %.2e m/s  contact changes %.2e J'
              % (r['case'], r['blocks'], r['free'], r['settleSteps'], r['settleSolves'], r['settleConverged'], r['unsettled'],
                 r['settleSeconds'], r['steps'], r['meanSolves'], r['mostSolves'], r['meanPasses'], r['stepCuts'], r['msPerStep'], r['msNarrowPhase'],
                 r['msAssembly'], r['msSolve'], r['largestSpeed'], r['contactChanges']), flush=True)
    os.makedirs(os.path.join(HERE, 'out'), exist_ok=True)
    path = os.path.join(HERE, 'out', os.environ.get('ROCK_MASS_REST_OUT', 'rock_mass_rest.json'))
    with open(path, 'w') as f:
        json.dump(dict(time=args.time, threads=1, settings=settings, rows=rows), f, indent=1)
    print('wrote', path)


if __name__ == '__main__':
    main()
