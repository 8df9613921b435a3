"""Benchmark: the paper's 70-block hexahedra drop (examples/paper), steps per second in chunks.

The drop's cost depends on the state of its pile (the logs land, pile up in the V-shaped trough, rebound,
then slide off its open ends and fall), so one rate says little: this runs the scene from the start in
chunks of ``--chunk`` steps of ``O.run`` (as a script runs it) and records each chunk's steps per second;
then runs it again, the same trajectory, with a PyRunner summing every step's stats (its rates are not
the scene's: reading stats syncs YADE's bodies every step) for each chunk's simulated time, the step's
phases (ms per step), the open-close solves, refinements and step cuts, the contact pairs and the
largest coupled component. The target is 300 steps/s once piled up.

Writes bench/out/drop.json (``--out``) and prints one line per chunk. Run:
YADE_DDA_BUILD=<build>/py /usr/bin/python3 bench/drop.py [--chunks 12] [--chunk 300] [--threads 1]
(a minute or two). With ``--threads 2`` both cores must be free (bench/scale.py's note).
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PHASES = ('broadPhase', 'narrowPhase', 'assembly', 'solve', 'update', 'core', 'sync')


def build(threads, refine):
    """The drop under MSC with the paper's step settings; returns (O, yade_dda)."""
    if os.environ.get('YADE_DDA_BUILD'):
        sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
    import yade_dda
    from yade import wrapper
    O = yade_dda.O
    sys.path.insert(0, os.path.join(ROOT, 'examples', 'paper'))
    import paper_scenes
    blocks, mat = paper_scenes.SCENES['hexahedra_drop']()
    material = O.materials.append(wrapper.PolyhedraMat(**mat))
    for points, fixed in blocks:
        O.bodies.append(yade_dda.ddaBlock(points, material=material, fixed=fixed))
    extra = {} if refine is None else dict(refineSolves=refine)
    O.engines = [yade_dda.MSCCollider(label='collider'),
                 yade_dda.DDAIntegrator(label='dda', gravity=(0, 0, -9.81), threads=threads, **paper_scenes.STEP,
                                        **extra)]
    return O, yade_dda


class Totals:
    """Sums each step's phases and counts; a PyRunner calls add() after every DDA step."""

    def __init__(self, yade_dda):
        self.yade_dda = yade_dda
        self.reset()

    def reset(self):
        self.phases = dict.fromkeys(PHASES, 0.0)
        self.counts = dict(solves=0, refined=0, refineIterations=0, refineFallbacks=0, stepCuts=0)
        self.largest = 0

    def add(self):
        s = self.yade_dda.stats()
        for k in PHASES:
            self.phases[k] += s['time'].get(k, 0.0)
        self.counts['solves'] += s['openCloseIterationsTotal']
        self.counts['refined'] += s.get('refinedComponents', 0)
        self.counts['refineIterations'] += s.get('refineIterations', 0)
        self.counts['refineFallbacks'] += s.get('refineFallbacks', 0)
        self.counts['stepCuts'] += s['stepCuts']
        self.largest = max(self.largest, s['largestComponent'])


def rates(threads, refine, chunks, steps):
    """Steps per second of each chunk of O.run(steps) (nothing reads the bodies, so they are synced once a chunk)."""
    O, yade_dda = build(threads, refine)
    out = []
    for _ in range(chunks):
        wall = time.perf_counter()
        O.run(steps, True)
        out.append(steps / (time.perf_counter() - wall))
    return out


def details(threads, refine, chunks, steps):
    """The same run again with a PyRunner summing each step's stats (which syncs the bodies every step, so
    its rates are not the scene's): per chunk the phases, counts, pairs and simulated time."""
    O, yade_dda = build(threads, refine)
    from yade import wrapper
    import __main__
    totals = Totals(yade_dda)
    __main__.dropBenchTotals = totals
    O.engines = O.engines + [wrapper.PyRunner(iterPeriod=1, command='dropBenchTotals.add()')]
    out = []
    for _ in range(chunks):
        totals.reset()
        t0 = O.time
        O.run(steps, True)
        s = yade_dda.stats()
        out.append(dict(simulatedTime=[t0, O.time], msPerStep={k: 1e3 * v / steps for k, v in totals.phases.items()},
                        solvesPerStep=totals.counts['solves'] / steps, counts=dict(totals.counts),
                        largestComponent=totals.largest, contactPairs=s['contactPairs'],
                        closedContacts=s['closedContacts']))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--chunks', type=int, default=12)
    parser.add_argument('--chunk', type=int, default=300)
    parser.add_argument('--threads', type=int, default=1)
    parser.add_argument('--refine', choices=('on', 'off', 'default'), default='default',
                        help="DDAIntegrator's refineSolves (a core without it: default)")
    parser.add_argument('--out', default=os.path.join(HERE, 'out', 'drop.json'))
    args = parser.parse_args()
    refine = None if args.refine == 'default' else args.refine == 'on'
    rows = [dict(steps=[k * args.chunk, (k + 1) * args.chunk], stepsPerSecond=r)
            for k, r in enumerate(rates(args.threads, refine, args.chunks, args.chunk))]
    O = sys.modules['yade_dda'].O
    O.reset()
    for row, more in zip(rows, details(args.threads, refine, args.chunks, args.chunk)):
        row.update(more)
        ms = row['msPerStep']
        print('steps %5d-%5d  t %.3f-%.3f s  %6.1f steps/s  solves/step %.2f  cuts %d  refined %d  pairs %d  '
              'component %d  narrow %.2f  assembly %.2f  solve %.2f  core %.2f ms'
              % (row['steps'][0], row['steps'][1], row['simulatedTime'][0], row['simulatedTime'][1],
                 row['stepsPerSecond'], row['solvesPerStep'], row['counts']['stepCuts'], row['counts']['refined'],
                 row['contactPairs'], row['largestComponent'], ms['narrowPhase'], ms['assembly'], ms['solve'],
                 ms['core']), flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(scene='hexahedra_drop', threads=args.threads, chunk=args.chunk, refine=args.refine,
                       target=300, chunks=rows), f, indent=1)
    print('wrote', args.out)


if __name__ == '__main__':
    main()
