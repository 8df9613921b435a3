"""Benchmark (issue 21): the paper's 70-block hexahedra drop (examples/paper), steps per second in chunks.

The drop's cost depends on the state of its pile (the logs land, pile up in the V-shaped trough, rebound,
then slide off its open ends and fall), so one rate says little: this runs the scene from the start in
chunks of ``--chunk`` steps (``O.step()``; the bodies are synced only when something reads them, as in
``O.run``) and records per chunk its steps per second, simulated time, the step's phases (ms per step),
the open-close solves, refinements and step cuts, and the contact pairs and largest coupled component.
Issue 21's target is 300 steps/s once piled up.

Writes bench/out/drop.json (``--out``) and prints one line per chunk. Run:
YADE_DDA_BUILD=<build>/py /usr/bin/python3 bench/drop.py [--chunks 12] [--chunk 300] [--threads 1]
(about a minute). With ``--threads 2`` both cores must be free (bench/scale.py's note).
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


def chunk(O, yade_dda, steps):
    """Runs `steps` steps; returns the chunk's record."""
    phases = dict.fromkeys(PHASES, 0.0)
    counts = dict(solves=0, refined=0, refineIterations=0, refineFallbacks=0, stepCuts=0)
    largest = 0
    t0, wall = O.time, time.perf_counter()
    for _ in range(steps):
        O.step()
        s = yade_dda.stats()
        for k in PHASES:
            phases[k] += s['time'].get(k, 0.0)
        counts['solves'] += s['openCloseIterationsTotal']
        counts['refined'] += s.get('refinedComponents', 0)
        counts['refineIterations'] += s.get('refineIterations', 0)
        counts['refineFallbacks'] += s.get('refineFallbacks', 0)
        counts['stepCuts'] += s['stepCuts']
        largest = max(largest, s['largestComponent'])
    wall = time.perf_counter() - wall
    s = yade_dda.stats()
    return dict(stepsPerSecond=steps / wall, simulatedTime=[t0, O.time],
                msPerStep={k: 1e3 * v / steps for k, v in phases.items()},
                solvesPerStep=counts['solves'] / steps, counts=counts, largestComponent=largest,
                contactPairs=s['contactPairs'], closedContacts=s['closedContacts'])


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
    O, yade_dda = build(args.threads, refine)
    rows = []
    for k in range(args.chunks):
        row = chunk(O, yade_dda, args.chunk)
        row['steps'] = [k * args.chunk, (k + 1) * args.chunk]
        rows.append(row)
        ms = row['msPerStep']
        print('steps %5d-%5d  t %.3f-%.3f s  %6.1f steps/s  solves/step %.2f  cuts %d  refined %d  pairs %d  '
              'component %d  narrow %.2f  assembly %.2f  solve %.2f  core %.2f  sync %.2f ms'
              % (row['steps'][0], row['steps'][1], row['simulatedTime'][0], row['simulatedTime'][1],
                 row['stepsPerSecond'], row['solvesPerStep'], row['counts']['stepCuts'], row['counts']['refined'],
                 row['contactPairs'], row['largestComponent'], ms['narrowPhase'], ms['assembly'], ms['solve'],
                 ms['core'], ms['sync']), flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(scene='hexahedra_drop', threads=args.threads, chunk=args.chunk, refine=args.refine,
                       target=300, chunks=rows), f, indent=1)
    print('wrote', args.out)


if __name__ == '__main__':
    main()
