"""Benchmark row for the effect "base motion": the same scene without a prescribed
motion and with one that stands still (baseMotion with a table of zero velocity: the
machinery runs, the floor does not move), time per step and the largest difference in
final positions (tolerance 0: a still motion must change no trajectory).

Scene: 36 unit cubes launched across a fixed floor at 0.5 to 1.5 m/s, friction 30 deg,
0.3 s at dt 2e-3 s, one thread. The runs alternate in this process; each time the fastest.
What the row cannot show, the cost of the code paths when no scene uses them against the
sources before them, is measured by running ``--time`` with each build
(``YADE_DDA_BUILD=<build>/py /usr/bin/python3 bench/effect_rows_shaking.py --time``).

``rows()`` returns the row for bench/effects.py; run standalone it prints it as JSON.
"""
import argparse
import json
import math
import os
import sys
import time

if os.environ.get('YADE_DDA_BUILD'):
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from yade import wrapper  # noqa: E402
from helpers import box  # noqa: E402

STEPS = 150
DT = 2e-3


def cubes(still):
    """Builds the scene (a still motion on the floor when `still`); returns the cubes' ids."""
    O.reset()
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e8, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    floor = O.bodies.append(ddaBlock(box((-10, -10, -1), (30, 10, 0)), material=rock, fixed=True))
    ids = []
    for k in range(36):
        x, y = 2.0 * (k % 6) - 6, 2.0 * (k // 6) - 6
        ids.append(O.bodies.append(ddaBlock(box((x, y, 0), (x + 1, y + 1, 1)), material=rock,
                                            velocity=(0.5 + k / 35.0, 0, 0))))
    if still:
        yade_dda.baseMotion(floor, velocity=[(0.0, 0.0)])
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -9.81), threads=1, label='dda')]
    return ids


def run(still):
    """One run: ms per step (the first step untimed), the final positions and the last step's stats."""
    ids = cubes(still)
    O.run(1, True)
    start = time.perf_counter()
    O.run(STEPS - 1, True)
    ms = 1e3 * (time.perf_counter() - start) / (STEPS - 1)
    return ms, [tuple(yade_dda.block(b).centroid) for b in ids], yade_dda.stats()


def rows(quick=False):
    """One row: {effect, scene, msPerStepWith, msPerStepWithout, maxDifference [m], tolerance [m], note}.
    The runs alternate (without, with, without, ...) so that the machine's load falls on both; each
    time is the fastest of its runs."""
    repeats = 2 if quick else 3
    runs = {False: [], True: []}
    for _ in range(repeats):
        for still in (False, True):
            runs[still].append(run(still))
    withMs, withPositions, withStats = min(runs[True], key=lambda r: r[0])
    withoutMs, withoutPositions, withoutStats = min(runs[False], key=lambda r: r[0])
    difference = max(math.dist(a, b) for a, b in zip(withPositions, withoutPositions))
    note = ('%d steps at dt %.0e s, one thread, fastest of %d; shaken blocks %d vs %d; effects.baseMotion %s vs %s'
            % (STEPS, DT, repeats, withStats['shakenBlocks'], withoutStats['shakenBlocks'],
               withStats['effects']['baseMotion'], withoutStats['effects']['baseMotion']))
    return [dict(effect='base motion', scene='36 cubes across a floor (still motion on it)', msPerStepWith=withMs,
                 msPerStepWithout=withoutMs, maxDifference=difference, tolerance=0.0, note=note)]


def timeWithout(repeats):
    """ms per step of the scene without a motion, each of `repeats` runs (for comparing builds)."""
    return [run(False)[0] for _ in range(repeats)]


if __name__ == '__main__':
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--time', type=int, default=0, metavar='N',
                        help='print the ms per step of N runs of the scene without a motion instead')
    args = parser.parse_args()
    print(json.dumps(timeWithout(args.time) if args.time else rows(), indent=1))
