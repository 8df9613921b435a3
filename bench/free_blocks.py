"""Benchmark: step time of many free DDA blocks (no contacts), core against YADE sync.

For each scene size the same blocks run twice: with the default automatic sync
(bodies written when something may read them) and with syncPeriod=1 (bodies
written every step). Writes bench/out/free_blocks.json; prints a table.
Run: make bench (or /usr/bin/python3 bench/free_blocks.py [--sizes 1000,10000] [--steps 50]).
"""
import argparse
import json
import math
import os
import random
import resource
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from helpers import box, rotate  # noqa: E402


def build(n, seed=1):
    rng = random.Random(seed)
    side = int(math.ceil(n ** (1 / 3)))
    start = time.perf_counter()
    for i in range(n):
        x, y, z = 3.0 * (i % side), 3.0 * ((i // side) % side), 3.0 * (i // (side * side))
        pts = rotate(box((x, y, z), (x + 1, y + 0.5, z + 2)), (rng.random(), rng.random(), rng.random() + 0.1),
                     rng.uniform(0, math.pi), about=(x + 0.5, y + 0.25, z + 1))
        O.bodies.append(ddaBlock(pts, velocity=(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)),
                                 angularVelocity=(rng.uniform(-1, 1), 0, rng.uniform(-1, 1))))
    return time.perf_counter() - start


def run(n, steps, syncPeriod, threads):
    O.reset()
    buildTime = build(n)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), syncPeriod=syncPeriod, threads=threads, label='dda')]
    O.run(1, True)  # first step links the bodies: not timed
    before = yade_dda.stats()
    start = time.perf_counter()
    O.run(steps, True)
    wall = time.perf_counter() - start
    s = yade_dda.stats()
    sync = s['syncTimeTotal'] - before['syncTimeTotal']
    engine = s['stepTimeTotal'] - before['stepTimeTotal']
    return dict(blocks=n, steps=steps, syncPeriod=syncPeriod, threads=threads,
                wallPerStep=wall / steps, enginePerStep=engine / steps, corePerStep=(engine - sync) / steps,
                syncPerStep=sync / steps, corePerStepLast=s['time']['core'],
                syncShare=sync / wall, syncs=s['syncs'], buildSeconds=buildTime,
                peakRssMB=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--sizes', default='1000,10000')
    parser.add_argument('--steps', type=int, default=50)
    parser.add_argument('--threads', type=int, default=0)
    parser.add_argument('--out', default=os.path.join(os.path.dirname(__file__), 'out', 'free_blocks.json'))
    args = parser.parse_args()
    rows = []
    for n in (int(s) for s in args.sizes.split(',')):
        for syncPeriod in (0, 1):
            row = run(n, args.steps, syncPeriod, args.threads)
            rows.append(row)
            print('%6d blocks, sync %-6s: %8.2f ms/step (DDA engine %6.2f ms: core %6.2f ms, sync %6.2f ms = %4.1f%%), '
                  'build %.1f s, peak RSS %.0f MB'
                  % (n, 'auto' if syncPeriod == 0 else 'every', 1e3 * row['wallPerStep'], 1e3 * row['enginePerStep'],
                     1e3 * row['corePerStep'],
                     1e3 * row['syncPerStep'], 100 * row['syncShare'], row['buildSeconds'], row['peakRssMB']))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(benchmark='free_blocks', machine=os.uname().nodename, cpus=os.cpu_count(), rows=rows), f, indent=1)
    print('wrote', args.out)


if __name__ == '__main__':
    main()
