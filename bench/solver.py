"""Benchmark: the coupled solve on jointed rock masses, direct against iterative (SI units: m, s).

Seeded confined masses of tests/py/rockmass_scenes.py (a cube of the given
edge cut by three oblique joint sets at about 1 m, the blocks touching its
sides or base held, E = 1e9 Pa), released as cut (startFromRest=False, so
every step loads the whole contact network and the open-close iteration
makes many solves) and stepped at dt = 1e-3 s. Per case and solver path:
free blocks, the largest connected component, solves a step, the mean time
of one solve [ms] (the step's solve phase over its solves), conjugate-gradient
iterations per iterative solve, and the step's time and phases. Paths:
'direct' (iterativeSolveBlocks=0: the block sparse Cholesky with refinement),
'iterative' (the default) on 1 and on 2 threads. Each run is its own process.

Writes bench/out/solver.json and bench/out/solver.png (time of one solve
against free blocks, log-log, n and n^3 drawn) and prints a table.
Run: /usr/bin/python3 bench/solver.py [--sides 5,7,9,11,14] [--direct-up-to 9]
[--steps 3] (about 10 minutes with the defaults).
"""
import argparse
import json
import os
import subprocess
import sys

import benchtasks  # bench/benchtasks.py: the RESULT protocol and the timed steps

HERE = os.path.dirname(os.path.abspath(__file__))


def run_case(side, path, threads, steps):
    """One case in this process: a dict of its numbers."""
    sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'py'))
    from yade_dda import O
    import rockmass_scenes as R
    case = R.draw_case(1, kind='oblique', side=side)
    settings = dict(dt=1e-3, threads=threads, startFromRest=False)
    if path == 'direct':
        settings['iterativeSolveBlocks'] = 0
    ids, fixed, free = R.build_scene(case, **settings)
    O.step()   # the first step builds the contact network
    return dict(side=side, path=path, threads=threads, description=R.describe(case), blocks=len(ids),
                free=len(free), steps=steps, **benchtasks.timedSteps(steps))


def plot(rows, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for (name, threads), style in ((('direct', 1), 'o-'), (('iterative', 1), 's-'), (('iterative', 2), '^--')):
        pts = sorted((r['free'], r['msPerSolve']) for r in rows if r['path'] == name and r['threads'] == threads)
        if pts:
            ax.loglog(*zip(*pts), style, label='%s, %d thread%s' % (name, threads, 's' if threads > 1 else ''))
    xs = sorted({r['free'] for r in rows})
    it = sorted((r['free'], r['msPerSolve']) for r in rows if r['path'] == 'iterative' and r['threads'] == 1)
    if it:
        n0, t0 = it[0]
        ax.loglog(xs, [t0 * x / n0 for x in xs], ':', color='grey', label='~ n')
        ax.loglog(xs, [t0 * (x / n0) ** 3 for x in xs], '-.', color='grey', label='~ n^3')
    ax.set_xlabel('free blocks (one connected mass)')
    ax.set_ylabel('time of one solve [ms]')
    ax.set_title('Coupled solve on jointed rock masses')
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--sides', default='5,7,9,11,14', help='cube edges [m]')
    parser.add_argument('--direct-up-to', type=float, default=9.0, help='largest edge [m] run with the direct path')
    parser.add_argument('--steps', type=int, default=3, help='steps timed after the first')
    parser.add_argument('--one', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        side, path, threads = args.one.split(',')
        benchtasks.printResult(run_case(float(side), path, int(threads), args.steps))
        return
    rows = []
    for side in [float(s) for s in args.sides.split(',')]:
        runs = [('iterative', 1), ('iterative', 2)] + ([('direct', 1)] if side <= args.direct_up_to else [])
        for path, threads in runs:
            row = benchtasks.resultOf([sys.executable, os.path.abspath(__file__), '--one',
                                       '%g,%s,%d' % (side, path, threads), '--steps', str(args.steps)],
                                      'case %g %s %d' % (side, path, threads))
            rows.append(row)
            print('%4g m %5d free %-9s %d thr: %5.1f solves/step, %8.2f ms/solve, %6.1f iterations/solve, '
                  '%8.1f ms/step (solve %8.1f, assembly %6.1f, narrow %5.1f)' % (
                      side, row['free'], path, threads, row['solvesPerStep'], row['msPerSolve'],
                      row['iterationsPerSolve'], row['msPerStep'], row['msSolve'], row['msAssembly'],
                      row['msNarrowPhase']), flush=True)
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=HERE, capture_output=True,
                            text=True).stdout.strip()
    out = os.path.join(HERE, 'out')
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, 'solver.json'), 'w') as f:
        json.dump(dict(commit=commit, steps=args.steps, rows=rows), f, indent=1)
    plot(rows, os.path.join(out, 'solver.png'))
    print('wrote bench/out/solver.json and bench/out/solver.png (commit %s)' % commit)


if __name__ == '__main__':
    main()
