"""Benchmark: energy of a dropped pile of cubes against Young's modulus.

30 slightly turned 1 m cubes (density 2600 kg/m^3, 30 deg friction) in layers
of 3 x 3, 0.1 m apart, dropped onto a fixed floor with every integrator setting
at its default, for 0.6 s. For each E it records what the hard-case tests
assert and what it costs:
- gain: the largest rise of kinetic (translation) plus potential energy above
  its start, relative to the start (must stay below 1e-3; an earlier
  contact law gained 5-36% on 200 cubes at 1e11 Pa); gainFull: the same
  with the energy account's kinetic energy (rotation and strain rates too);
- speed: the fastest centroid over the free-fall bound sqrt(2 g z_top) (<= 1);
- drift: the energy account's sum minus loads minus contactChanges, its change
  over the run relative to the largest change of any term (the account's
  conservation law; exact only for small strains);
- contactChanges: the energy the contacts' springs gained between steps, over
  the same scale (negative: lost);
- steps, solves per step, dt cuts, friction-limit passes and unsettled groups,
  wall and CPU seconds (this process; on a shared machine the CPU time is the
  fairer measure).

--hulls N: the random convex hulls of test_energy_and_creep.py instead (27 hulls of 4 to
12 random points in a fixed box), seeds 1..N at 1e9 and 1e11 Pa (or --youngs), 1 s (or
--time): the contact changes between steps, net, their gains and the largest single
step's, over the largest change of any account term; writes bench/out/energy_hulls.json.

Writes bench/out/energy.json and prints a table. SI units.
Run: make bench (or /usr/bin/python3 bench/energy.py [--youngs 1e5 1e11] [--time 0.6];
YADE_DDA_BUILD=<build>/py to use a build tree instead of the installed package).

--pile200: the slow test's scene instead, the pile of
tests/py/solver/test_energy_and_creep.py::test_pile_of_200_cubes_never_gains_energy
(200 cubes in 8 layers of 5 x 5, 0.2 m apart, the same seed and builder), for
1.5 s, gain and speed sampled at every step (allLandedAt: when the last cube
left its free fall); a run stops early once a block is --stop-speed (10) times
its free-fall bound, or gainFull is above --stop-gain (0.5) (recorded as
`stopped`); writes
bench/out/energy_pile200.json. Not in `make bench`: it takes many minutes per
E (see doc/benchmarks.md, "Energy of a dropped pile"). --count/--side run
other piles of that builder (written to energy_pile<count>.json). --threads
sets DDAIntegrator.threads (results do not depend on it; 1 is fair to other
users of the machine).
"""
import argparse
import json
import math
import os
import random
import time

import sys

if os.environ.get('YADE_DDA_BUILD'):  # a build tree instead of the installed package
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator, block  # noqa: E402
from yade import wrapper  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'py'))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'py', 'solver'))
from helpers import box, rotate  # noqa: E402  (the tests' shapes: same piles as test_energy_and_creep.py)

G = 9.81
SEED = 20261125


def account(e):
    """The energy account's sum minus the loads [J] (conserved up to contactChanges)."""
    return e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']


def small_pile(young, count):
    """The 30-cube pile of `make bench` (3 x 3 per layer, 0.1 m apart)."""
    rng = random.Random(SEED)
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=young, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    O.bodies.append(ddaBlock(box((-2, -2, -1), (6, 6, 0)), material=rock, fixed=True))
    cubes = []
    for k in range(count):
        i, j, layer = k % 3, (k // 3) % 3, k // 9
        x, y, z = 0.1 + 1.1 * i, 0.1 + 1.1 * j, 0.2 + 1.1 * layer
        pts = rotate(box((x, y, z), (x + 1, y + 1, z + 1)), (rng.random(), rng.random(), rng.random()),
                     rng.uniform(-0.1, 0.1), about=(x + .5, y + .5, z + .5))
        cubes.append(O.bodies.append(ddaBlock(pts, material=rock)))
    return cubes


def run(young, duration, count=30, side=None, threads=0, every=10, progress=None, maxWall=None, stopSpeed=None,
        stopGain=None):
    """side=None: the 30-cube bench pile; else the slow test's pile(count, young, SEED, side=side)."""
    O.reset()
    if side is None:
        cubes = small_pile(young, count)
    else:
        from test_energy_and_creep import pile  # the slow test's own builder (spacing 1.2, turn 0.1)
        cubes = pile(count, young, SEED, side=side)
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), threads=threads, label='dda')]

    landed = {}  # cube: the first sampled time its fall departs from a free fall by 1%

    def translational():
        energy, fastest = 0.0, 0.0
        for b in cubes:
            blk = block(b)
            v = blk.velocity
            speed2 = v[0] ** 2 + v[1] ** 2 + v[2] ** 2
            energy += blk.mass * G * blk.centroid[2] + 0.5 * blk.mass * speed2
            fastest = max(fastest, math.sqrt(speed2))
            if b not in landed and O.time > 0 and abs(v[2] + G * O.time) > 0.01 * G * O.time:
                landed[b] = O.time
        return energy, fastest

    start, cpuStart = time.time(), time.process_time()
    O.step()  # synchronous: O.run(1, True) waits about 40 ms per call for YADE's thread
    e0, _ = translational()
    top = max(block(b).centroid[2] for b in cubes)
    bound = math.sqrt(2 * G * top)
    a0 = dict(yade_dda.stats()['energy'])
    full0 = a0['kinetic'] + a0['gravity']
    gainFull, gainFullAt, gainFullOver = 0.0, 0.0, None
    gain, speed, drift, changes, steps, solves, cuts, passes, unsettled = 0.0, 0.0, 0.0, 0.0, 1, 0, 0, 0, 0
    searches, failures, mostSolves, gainAt, speedAt = 0, 0, 0, 0.0, 0.0
    nextReport = 0.0
    stopped = None
    while O.time < duration:
        if maxWall is not None and time.time() - start > maxWall:
            stopped = 'wall time above %g s' % maxWall
            break
        if stopSpeed is not None and speed > stopSpeed:
            stopped = 'a block at %.3g x its free-fall bound' % speed
            break
        if stopGain is not None and gainFull > stopGain:
            stopped = 'kinetic (all rates) plus potential energy %.3g above its start' % gainFull
            break
        O.step()
        s = yade_dda.stats()
        steps += 1
        solves += s['openCloseIterationsTotal']
        mostSolves = max(mostSolves, s['openCloseIterationsTotal'])
        cuts += s['stepCuts']
        passes += s['limitPasses']
        unsettled += s['limitsUnsettled']
        searches += s['lineSearches']
        failures = s['openCloseFailures']
        if progress is not None and O.time >= nextReport:
            nextReport += progress
            print('  E %.0e t %.3f s wall %.1f s steps %d solves/step %.1f cuts %d passes %d unsettled %d gain %.2e '
                  'speed %.3f landed %d' % (young, O.time, time.time() - start, steps, solves / steps, cuts, passes,
                                            unsettled, gain, speed, len(landed)), flush=True)
        if steps % every:
            continue
        e, fastest = translational()
        if (e - e0) / e0 > gain:
            gain, gainAt = (e - e0) / e0, O.time
        if fastest / bound > speed:
            speed, speedAt = fastest / bound, O.time
        a = s['energy']
        if (a['kinetic'] + a['gravity'] - full0) / full0 > gainFull:
            gainFull, gainFullAt = (a['kinetic'] + a['gravity'] - full0) / full0, O.time
            if gainFull > 1e-3 and gainFullOver is None:
                gainFullOver = O.time
        scale = max(abs(a[k] - a0[k]) for k in a)
        drift = max(drift, abs(account(a) - account(a0) - (a['contactChanges'] - a0['contactChanges'])) / scale)
        changes = (a['contactChanges'] - a0['contactChanges']) / scale
    row = dict(young=young, blocks=count, time=O.time, gain=gain, gainFull=gainFull, speedOverFreeFall=speed,
               accountDrift=drift,
               contactChanges=changes, steps=steps, solvesPerStep=solves / steps, dtCuts=cuts, limitPasses=passes,
               limitsUnsettled=unsettled, wallSeconds=time.time() - start, cpuSeconds=time.process_time() - cpuStart)
    if side is not None:
        row.update(stopped=stopped, allLandedAt=max(landed.values()) if len(landed) == len(cubes) else None,
                   gainAt=gainAt, gainFullAt=gainFullAt, gainFullAbove1e3At=gainFullOver, speedAt=speedAt,
                   freeFallBound=bound, lineSearches=searches, openCloseFailures=failures,
                   mostSolvesInStep=mostSolves, threads=threads)
    elif stopped:
        row['stopped'] = stopped
    return row


def run_hulls(young, seed, duration, threads=0, dt=None):
    """The random-hull pile of test_energy_and_creep.py (27 hulls of 4 to 12 random points
    dropped into a fixed box, that test's builder) for `duration` s, every step: the
    contactChanges between steps (net, summed gains, the largest single step and when),
    over the largest change of any account term; the account's drift; kinetic plus
    potential energy's largest rise; steps and CPU seconds. `dt` [s]: DDAIntegrator.dt
    (the largest step; None: its default)."""
    from test_energy_and_creep import hull_pile
    O.reset()
    blocks = hull_pile(27, young, seed)
    O.engines = [DDAIntegrator(gravity=(0, 0, -G), threads=threads, label='dda', **({} if dt is None else dict(dt=dt)))]
    cpuStart = time.process_time()
    O.step()
    a0 = dict(yade_dda.stats()['energy'])

    def kp(a):
        return a['kinetic'] + a['gravity']

    prev, gains, largest, largestAt, rise, steps = a0['contactChanges'], 0.0, 0.0, 0.0, 0.0, 1
    while O.time < duration:
        O.step()
        steps += 1
        a = yade_dda.stats()['energy']
        change = a['contactChanges'] - prev
        prev = a['contactChanges']
        if change > 0:
            gains += change
        if change > largest:
            largest, largestAt = change, O.time
        rise = max(rise, kp(a) - kp(a0))
    a = yade_dda.stats()['energy']
    scale = max(abs(a[k] - a0[k]) for k in a)
    drift = account(a) - account(a0) - (a['contactChanges'] - a0['contactChanges'])
    return dict(young=young, seed=seed, dt=O.engines[0].dt, blocks=len(blocks), time=O.time, steps=steps, scale=scale,
                contactChanges=(a['contactChanges'] - a0['contactChanges']) / scale, gains=gains / scale,
                largestStepGain=largest / scale, largestStepGainJ=largest, largestAt=largestAt,
                accountDrift=drift / scale, kineticPlusPotentialRise=rise / scale,
                cpuSeconds=time.process_time() - cpuStart)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--youngs', type=float, nargs='+', default=[1e5, 1e7, 1e9, 1e11])
    parser.add_argument('--time', type=float, default=None, help='simulated seconds (0.6; 1.5 with --pile200)')
    parser.add_argument('--pile200', action='store_true', help="the slow test's 200-cube pile")
    parser.add_argument('--count', type=int, default=None, help='cubes of the slow test\'s pile builder')
    parser.add_argument('--side', type=int, default=5, help='cubes per layer side with --count')
    parser.add_argument('--threads', type=int, default=0, help='DDAIntegrator.threads (0: all)')
    parser.add_argument('--progress', type=float, default=None, help='print a line every this many simulated s')
    parser.add_argument('--max-wall', type=float, default=None, help='stop a run after this many wall seconds')
    parser.add_argument('--stop-speed', type=float, default=10.0,
                        help='with --count/--pile200: stop a run once a block is this many times its free-fall bound')
    parser.add_argument('--stop-gain', type=float, default=0.5,
                        help='with --count/--pile200: stop a run once gainFull is above this (blown up)')
    parser.add_argument('--hulls', type=int, default=None, metavar='N',
                        help='the random-hull pile of test_energy_and_creep.py, seeds 1..N (default E: 1e9 1e11)')
    parser.add_argument('--dts', type=float, nargs='+', default=[None],
                        help='with --hulls: DDAIntegrator.dt values to run each seed at [s] (default: its default)')
    parser.add_argument('--out', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), 'out'))
    args = parser.parse_args()
    if args.hulls:
        youngs = args.youngs if '--youngs' in sys.argv else [1e9, 1e11]
        rows = [run_hulls(E, seed, args.time or 1.0, args.threads, dt) for E in youngs for dt in args.dts
                for seed in range(1, args.hulls + 1)]
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, 'energy_hulls.json'), 'w') as f:
            json.dump(dict(rows=rows), f, indent=1)
        print('%8s %8s %4s %6s %10s %10s %12s %8s %9s %9s %7s' % (
            'E [Pa]', 'dt [s]', 'seed', 'steps', 'changes', 'gains', 'largest step', 'at [s]', 'drift', 'rise', 'CPU s'))
        for r in rows:
            print('%8.0e %8.1e %4d %6d %10.2e %10.2e %12.2e %8.3f %9.1e %9.1e %7.1f' % (
                r['young'], r['dt'], r['seed'], r['steps'], r['contactChanges'], r['gains'], r['largestStepGain'],
                r['largestAt'], r['accountDrift'], r['kineticPlusPotentialRise'], r['cpuSeconds']))
        return
    if args.pile200:
        args.count, args.side = 200, 5
    big = args.count is not None
    duration = args.time if args.time is not None else (1.5 if big else 0.6)
    if big:
        rows = [run(E, duration, args.count, args.side, args.threads, every=1, progress=args.progress,
                    maxWall=args.max_wall, stopSpeed=args.stop_speed, stopGain=args.stop_gain) for E in args.youngs]
        name = 'energy_pile%d.json' % args.count
    else:
        rows = [run(E, duration, threads=args.threads, progress=args.progress, maxWall=args.max_wall)
                for E in args.youngs]
        name = 'energy.json'
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, name), 'w') as f:
        json.dump(dict(seed=SEED, rows=rows), f, indent=1)
    print('%8s %9s %9s %8s %9s %9s %6s %7s %5s %7s %6s' % ('E [Pa]', 'gain', 'gainFull', 'speed', 'drift', 'changes',
                                                             'steps', 'solves', 'cuts', 'passes', 'cpu'))
    for r in rows:
        print('%8.0e %9.1e %9.1e %8.3f %9.1e %9.1e %6d %7.1f %5d %7d %6.1f%s' % (
            r['young'], r['gain'], r['gainFull'], r['speedOverFreeFall'], r['accountDrift'], r['contactChanges'],
            r['steps'], r['solvesPerStep'], r['dtCuts'], r['limitPasses'], r['cpuSeconds'],
            ' (stopped at %.4f s: %s)' % (r['time'], r['stopped']) if r.get('stopped') else ''))


if __name__ == '__main__':
    main()
