"""Benchmark: jointed rock masses at rest against their size (SI units: m, s, bytes).

Seeded confined masses of tests/py/rockmass_scenes.py (cubes of the given
edges cut by three oblique joint sets at about 1 m, the blocks touching the
sides or the base held, E = 1e9 Pa, friction above every joint's dip),
started from rest (the default) and then stepped at dt = 1e-3 s. Per mass:
blocks and free blocks; the start from rest (wall time on one thread, static
steps, solves, whether it converged); then the steps, timed on one thread and
then on two: wall time a step and its phases (narrow phase, assembly, solve),
solves a step, conjugate-gradient iterations a solve, the coarse level's
aggregates, the heap the scene's arrays hold (stats()['memory']) per block
and the process's peak resident size per block. Each mass runs in its own
process.

Writes bench/out/rock_mass_scale.json and bench/out/rock_mass_scale.png
(time a step and its phases against blocks, log-log, with n and n log n
drawn; the start from rest beside it) and prints a table.
Run: /usr/bin/python3 bench/rock_mass_scale.py [--sides 10,13,16,21] [--steps 5]
[--set NAME=VALUE ...] (DDAIntegrator settings for every mass). The default
sides give about 1,200 to 9,000 blocks; the 21 m mass's start from rest takes
the longest (minutes).
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import benchtasks  # bench/benchtasks.py: the RESULT protocol and the timed steps

HERE = os.path.dirname(os.path.abspath(__file__))


def run_case(side, steps, settings):
    """One mass in this process: a dict of its numbers."""
    sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'py'))
    import yade_dda
    from yade_dda import O
    import rockmass_scenes as R
    case = R.draw_case(1, kind='oblique', side=side)
    ids, fixed, free = R.build_scene(case, dt=1e-3, threads=1, **settings)
    start = time.time()
    O.step()
    settle = time.time() - start
    first = yade_dda.stats()
    memory = sum(first['memory'].values())
    row = dict(side=side, description=R.describe(case), blocks=len(ids), free=len(free), settleSeconds=settle,
               settleSteps=first['settleSteps'], settleSolves=first['settleSolves'],
               settleConverged=bool(first['settleConverged']), unsettled=len(first['unsettledBlocks']),
               memoryPerBlock=memory / len(ids))
    row['oneThread'] = benchtasks.timedSteps(steps)
    O.engines[0].threads = 2
    row['twoThreads'] = benchtasks.timedSteps(steps)
    row['largestSpeed'] = max(O.bodies[i].state.vel.norm() for i in free)
    row['peakResidentPerBlock'] = 1024.0 * resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / len(ids)
    return row


def plot(rows, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10.5, 4.4))
    rows = sorted(rows, key=lambda r: r['blocks'])
    n = [r['blocks'] for r in rows]
    for key, label, style in (('msPerStep', 'step, 1 thread', 'o-'), ('msSolve', 'solve', 's-'),
                              ('msNarrowPhase', 'narrow phase', '^-'), ('msAssembly', 'assembly', 'v-')):
        ax.loglog(n, [r['oneThread'][key] for r in rows], style, label=label)
    ax.loglog(n, [r['twoThreads']['msPerStep'] for r in rows], 'o--', label='step, 2 threads')
    n0, t0 = n[0], rows[0]['oneThread']['msPerStep']
    ax.loglog(n, [t0 * x / n0 for x in n], ':', color='grey', label='~ n')
    ax.loglog(n, [t0 * x * math.log(x) / (n0 * math.log(n0)) for x in n], '-.', color='grey', label='~ n log n')
    ax.set_xlabel('blocks')
    ax.set_ylabel('wall time a step at rest [ms]')
    ax.set_title('Rock masses at rest')
    ax.legend(fontsize=8)
    bx.loglog(n, [r['settleSeconds'] for r in rows], 'o-', label='start from rest, 1 thread')
    s0 = rows[0]['settleSeconds']
    bx.loglog(n, [s0 * x / n0 for x in n], ':', color='grey', label='~ n')
    bx.set_xlabel('blocks')
    bx.set_ylabel('wall time [s]')
    bx.set_title('Start from rest')
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--sides', default='10,13,16,21', help='cube edges [m]')
    parser.add_argument('--steps', type=int, default=5, help='steps timed on each thread count')
    parser.add_argument('--set', action='append', default=[], metavar='NAME=VALUE',
                        help='a DDAIntegrator setting for every mass (a number)')
    parser.add_argument('--one', help=argparse.SUPPRESS)
    args = parser.parse_args()
    settings = {k: float(v) for k, v in (item.split('=', 1) for item in args.set)}
    if args.one:
        benchtasks.printResult(run_case(float(args.one), args.steps, settings))
        return
    rows = []
    for side in args.sides.split(','):
        r = benchtasks.resultOf([sys.executable, os.path.abspath(__file__), '--one', side, '--steps', str(args.steps)]
                                + ['--set=' + item for item in args.set], 'mass of side %s' % side)
        rows.append(r)
        one, two = r['oneThread'], r['twoThreads']
        print('%4s m %6d blocks %6d free | settle %7.1f s %3d steps %5d solves %-5s | %8.1f ms/step (narrow %.1f, '
              'assembly %.1f, solve %.1f) %.2f solves %.0f its/solve %d aggregates | 2 threads %.2f of one | '
              '%.0f B/block held, %.0f B/block peak' % (
                  side, r['blocks'], r['free'], r['settleSeconds'], r['settleSteps'], r['settleSolves'],
                  r['settleConverged'], one['msPerStep'], one['msNarrowPhase'], one['msAssembly'], one['msSolve'],
                  one['solvesPerStep'], one['iterationsPerSolve'], one['coarseAggregates'],
                  two['msPerStep'] / one['msPerStep'], r['memoryPerBlock'], r['peakResidentPerBlock']), flush=True)
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=HERE, capture_output=True,
                            text=True).stdout.strip()
    out = os.path.join(HERE, 'out')
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, 'rock_mass_scale.json'), 'w') as f:
        json.dump(dict(commit=commit, steps=args.steps, settings=settings, rows=rows), f, indent=1)
    plot(rows, os.path.join(out, 'rock_mass_scale.png'))
    print('wrote bench/out/rock_mass_scale.json and bench/out/rock_mass_scale.png (commit %s)' % commit)


if __name__ == '__main__':
    main()
