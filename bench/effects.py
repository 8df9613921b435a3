"""Benchmark: effects on demand. For each effect, the same scene with the
effect's work done and without it, in one process and one thread: time per
step and the largest difference in results, against a stated tolerance.

Rows (keys: effect, scene, msPerStepWith, msPerStepWithout, maxDifference,
tolerance, note): friction (frictionless vs a tiny friction angle), gravity
(none vs a tiny one), static analysis (velocityRatio 0 vs 1), the resting
pile's candidate-pair cache (on vs reuseCandidatePairs=False), fixed-fixed
pairs (counters; not switchable), lazy YADE sync (automatic vs every step),
then the rows of every bench/effect_rows_*.py present (their rows()).

Writes bench/out/effects.json and prints a table.
Run: /usr/bin/python3 bench/effects.py [--quick]  (make bench runs it).
"""
import argparse
import glob
import importlib.util
import inspect
import json
import math
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from yade import wrapper  # noqa: E402
from helpers import box  # noqa: E402

G = 9.81


def material(frictionRad, young=1e8):
    return O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=frictionRad))


def run(build, steps, repeats=2, **engine):
    """Builds a scene and runs `steps` steps (the first untimed), `repeats`
    times; returns the fastest ms per step, the final body positions and the
    last step's counters."""
    best = math.inf
    for _ in range(repeats):
        O.reset()
        build()
        O.engines = [DDAIntegrator(threads=1, label='dda', **engine)]
        O.run(1, True)
        start = time.perf_counter()
        O.run(steps - 1, True)
        best = min(best, 1e3 * (time.perf_counter() - start) / (steps - 1))
    s = yade_dda.stats()
    counters = {key: s[key] for key in ('frictionTerms', 'bodyForceBlocks', 'broadPhaseSkipped', 'candidatePairs',
                                        'fixedPairsSearched', 'shellUpdates', 'syncs')}
    counters['broadPhaseMs'] = 1e3 * s['time']['broadPhase']
    positions = [tuple(b.state.pos) for b in O.bodies]
    return best, positions, counters


def difference(a, b):
    return max(math.dist(p, q) for p, q in zip(a, b))


def cubes_on_floor(frictionRad):
    """36 unit cubes launched across a fixed floor at 0.5 to 1.5 m/s."""
    def build():
        rock = material(frictionRad)
        O.bodies.append(ddaBlock(box((-10, -10, -1), (30, 10, 0)), material=rock, fixed=True))
        for k in range(36):
            x, y = 2.0 * (k % 6) - 6, 2.0 * (k // 6) - 6
            O.bodies.append(ddaBlock(box((x, y, 0), (x + 1, y + 1, 1)), material=rock,
                                     velocity=(0.5 + k / 35.0, 0, 0)))
    return build


def free_blocks():
    """100 spinning unit cubes, far apart (no contacts)."""
    rock = material(0.0)
    for k in range(100):
        x, y, z = 3.0 * (k % 10), 3.0 * ((k // 10) % 10), 0.0
        O.bodies.append(ddaBlock(box((x, y, z), (x + 1, y + 1, z + 1)), material=rock, velocity=(0.1, 0, 0),
                                 angularVelocity=(0.3, 0.2, 0.1)))


def tower(levels):
    def build():
        rock = material(math.radians(30))
        O.bodies.append(ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
        for k in range(levels):
            O.bodies.append(ddaBlock(box((-0.5, -0.5, k), (0.5, 0.5, k + 1)), material=rock))
    return build


def resting_pile(nx=10, layers=2):
    """nx x nx x layers unit cubes stacked exactly on a fixed floor, 1 cm apart sideways."""
    def build():
        rock = material(math.radians(30))
        O.bodies.append(ddaBlock(box((-1, -1, -1), (nx * 1.01 + 1, nx * 1.01 + 1, 0)), material=rock, fixed=True))
        for k in range(nx * nx * layers):
            i, j, layer = k % nx, (k // nx) % nx, k // (nx * nx)
            x, y = 1.01 * i, 1.01 * j
            O.bodies.append(ddaBlock(box((x, y, layer), (x + 1, y + 1, layer + 1)), material=rock))
    return build


def fixed_floor():
    """200 fixed unit cubes side by side (a 10 x 20 floor) and 2 cubes resting on it."""
    rock = material(math.radians(30))
    for i in range(10):
        for j in range(20):
            O.bodies.append(ddaBlock(box((i, j, -1), (i + 1, j + 1, 0)), material=rock, fixed=True))
    O.bodies.append(ddaBlock(box((3.8, 7.7, 0.0), (4.8, 8.7, 1.0)), material=rock))
    O.bodies.append(ddaBlock(box((5.8, 11.7, 0.0), (6.8, 12.7, 1.0)), material=rock))


def rows(quick):
    steps = 60 if quick else 300
    out = []
    gravity = (0, 0, -G)

    # friction: frictionless (no tangential terms) vs tan(phi) = 1e-6
    tiny = math.atan(1e-6)
    msOff, pOff, cOff = run(cubes_on_floor(0.0), steps, dt=2e-3, gravity=gravity)
    msOn, pOn, cOn = run(cubes_on_floor(tiny), steps, dt=2e-3, gravity=gravity)
    t = O.time
    out.append(dict(effect='friction', scene='36 cubes sliding on a floor, %d steps' % steps,
                    msPerStepWith=msOn, msPerStepWithout=msOff, maxDifference=difference(pOn, pOff),
                    tolerance=2 * 0.5 * G * 1e-6 * t ** 2,
                    note='with: friction angle atan(1e-6), %d friction terms; without: frictionless, %d. '
                         'Tolerance: twice g tan(phi) t^2/2, the closed-form slide loss' %
                         (cOn['frictionTerms'], cOff['frictionTerms'])))

    # gravity: none (no body-force assembly) vs 1e-6 m/s^2
    msOff, pOff, cOff = run(free_blocks, steps, dt=1e-2, maxDisplacement=0.05)
    msOn, pOn, cOn = run(free_blocks, steps, dt=1e-2, maxDisplacement=0.05, gravity=(0, 0, -1e-6))
    t = O.time
    out.append(dict(effect='gravity', scene='100 free spinning cubes, %d steps' % steps,
                    msPerStepWith=msOn, msPerStepWithout=msOff, maxDifference=difference(pOn, pOff),
                    tolerance=1e-6 * t ** 2 / 2 * (1 + 1e-6),
                    note='with: g = 1e-6 m/s^2 (%d block assemblies with body force in the last step); '
                         'without: none (0). Tolerance: g t^2/2, free fall' % cOn['bodyForceBlocks']))

    # static analysis: velocityRatio 0 vs 1, a settled tower's rest state
    levels = 5
    msDyn, pDyn, _ = run(tower(levels), steps, dt=2e-3, gravity=gravity)
    msStat, pStat, _ = run(tower(levels), steps, dt=2e-3, gravity=gravity, velocityRatio=0)
    # closed form: the top cube's elastic settlement at rest, rho g / E x sum of
    # the mean loads (in cube weights) of the cubes below it (uniform strain per cube)
    settlement = 2600 * G / 1e8 * sum(levels - j - 0.5 for j in range(levels))
    out.append(dict(effect='static', scene='tower of %d cubes at rest, %d steps' % (levels, steps),
                    msPerStepWith=msStat, msPerStepWithout=msDyn, maxDifference=difference(pStat, pDyn),
                    tolerance=settlement,
                    note='with: velocityRatio=0 (Shi static analysis); without: dynamic (1). Neither has '
                         'settled; tolerance: the elastic settlement at rest, rho g / E x sum(n - j - 1/2) m'))

    # resting pile: candidate-pair cache vs a search every step
    nx = 6 if quick else 10
    msOff, pOff, cOff = run(resting_pile(nx), steps, dt=2e-3, gravity=gravity, reuseCandidatePairs=False)
    msOn, pOn, cOn = run(resting_pile(nx), steps, dt=2e-3, gravity=gravity)
    out.append(dict(effect='restingReuse', scene='%d cubes resting on a floor, %d steps' % (2 * nx * nx, steps),
                    msPerStepWith=msOn, msPerStepWithout=msOff, maxDifference=difference(pOn, pOff), tolerance=0.0,
                    note='with: DESS pair cache (last step skipped the search: %d, broad phase %.3f ms); '
                         'without: reuseCandidatePairs=False (broad phase %.3f ms). Same contacts, so bitwise '
                         'the same positions' % (cOn['broadPhaseSkipped'], cOn['broadPhaseMs'], cOff['broadPhaseMs'])))

    # fixed blocks: not switchable; the counters show the work not done
    ms, _, c = run(fixed_floor, steps, dt=2e-3, gravity=gravity)
    out.append(dict(effect='fixedBlocks', scene='200 fixed floor cubes + 2 resting cubes, %d steps' % steps,
                    msPerStepWith=ms, msPerStepWithout=None, maxDifference=None, tolerance=None,
                    note='cannot be switched off: %d candidate pairs (of 19,900 fixed-fixed pairs: %d searched)'
                         % (c['candidatePairs'], c['fixedPairsSearched'])))

    # lazy sync: automatic (once per O.run) vs every step
    msLazy, pLazy, cLazy = run(resting_pile(nx), steps, dt=2e-3, gravity=gravity)
    msEvery, pEvery, cEvery = run(resting_pile(nx), steps, dt=2e-3, gravity=gravity, syncPeriod=1)
    out.append(dict(effect='lazySync', scene='%d cubes resting on a floor, %d steps' % (2 * nx * nx, steps),
                    msPerStepWith=msEvery, msPerStepWithout=msLazy, maxDifference=difference(pLazy, pEvery),
                    tolerance=0.0,
                    note='with: syncPeriod=1 (%d syncs); without: automatic (%d syncs). Positions read '
                         'after the run' % (cEvery['syncs'], cLazy['syncs'])))
    return out


def extra_rows(quick):
    """Rows of bench/effect_rows_*.py (each module's rows(), called with quick if it takes it)."""
    out = []
    for path in sorted(glob.glob(os.path.join(os.path.dirname(os.path.abspath(__file__)), 'effect_rows_*.py'))):
        name = os.path.splitext(os.path.basename(path))[0]
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        takesQuick = 'quick' in inspect.signature(module.rows).parameters
        out.extend(module.rows(quick=quick) if takesQuick else module.rows())
    return out


def fmt(value, spec):
    return '-' if value is None else spec % value


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--quick', action='store_true', help='CI-sized runs')
    parser.add_argument('--out', default=os.path.join(os.path.dirname(__file__), 'out', 'effects.json'))
    args = parser.parse_args()
    table = rows(args.quick) + extra_rows(args.quick)
    print('%-13s %-44s %10s %10s %12s %12s' % ('effect', 'scene', 'ms with', 'ms without', 'max diff', 'tolerance'))
    for r in table:
        print('%-13s %-44s %10s %10s %12s %12s' % (
            r['effect'], r['scene'][:44], fmt(r['msPerStepWith'], '%.3f'), fmt(r['msPerStepWithout'], '%.3f'),
            fmt(r['maxDifference'], '%.3e'), fmt(r['tolerance'], '%.3e')))
        print('%-13s   %s' % ('', r['note']))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(quick=args.quick, rows=table), f, indent=1)
    print('\nwrote', args.out)


if __name__ == '__main__':
    main()
