"""Benchmark: cutRockMass on a 40 m cube (doc/rock-mass.md).

Three oblique joint sets (dip/dip direction 35/020, 65/140, 80/250, through (0.3, 0.7, 0.1)) at 2 m
(about 9,000 blocks) and at 1.09 m (about 50,000), and the 2 m case with a stochastic first set
(persistence 0.7, fisherK 30, exponential spacings). Each case runs in its own process so that its peak
resident memory (VmHWM, /proc/self/status) is its own: the peak after importing yade_dda (YADE itself)
and after the cut are both recorded. The cut is timed three times (wall clock of cutRockMass from Python,
the core's phases from rock.stats), the first run's memory kept; the three must give bitwise the same
blocks. For the 2 m case the time to make the YADE bodies (rock.ddaBlocks, O.bodies.append) is measured
too. Writes bench/out/rock_mass.json; prints a table.
The concave cases cut with concave=True (the first set at persistence 0.7, joined where absent) and time
the join in the wall clock; '8k-concave' also times rock.append (bodies and clumps).
Run: /usr/bin/python3 bench/rock_mass.py [--cases 8k,50k,8k-stochastic,8k-concave,50k-concave]
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import time

SIDE = 40.0
ORIENTATIONS = ((35, 20), (65, 140), (80, 250))
ORIGIN = (0.3, 0.7, 0.1)
CASES = {
    '8k': dict(spacing=2.0, stochastic=False, bodies=True),
    '50k': dict(spacing=1.09, stochastic=False, bodies=False),
    '8k-stochastic': dict(spacing=2.0, stochastic=True, bodies=False),
    # cutRockMass(..., concave=True) with the first set at persistence 0.7: joined blocks (3DEC's model)
    '8k-concave': dict(spacing=2.0, stochastic=False, bodies=True, concave=0.7),
    '50k-concave': dict(spacing=1.09, stochastic=False, bodies=False, concave=0.7),
}


def vmhwmMB():
    with open('/proc/self/status') as f:
        for line in f:
            if line.startswith('VmHWM:'):
                return int(line.split()[1]) / 1024
    return float('nan')


def jointSets(spacing, stochastic, persistence=None):
    sets = [dict(dip=d, dipDirection=a, spacing=spacing, origin=ORIGIN) for d, a in ORIENTATIONS]
    if stochastic:
        sets[0].update(persistence=0.7, fisherK=30, spacingDistribution='exponential')
    if persistence is not None:
        sets[0].update(persistence=persistence)
    return sets


def fingerprint(rock):
    return hash(tuple(b"".join(struct.pack('<3d', *c) for c in b.corners) for b in rock.blocks))


def runCase(name):
    """One case, in this process: a dict of its numbers."""
    case = CASES[name]
    import yade_dda
    from yade_dda import O, cutRockMass
    from yade import wrapper
    baseline = vmhwmMB()
    domain = [(x, y, z) for x in (0, SIDE) for y in (0, SIDE) for z in (0, SIDE)]
    concave = 'concave' in case
    sets = jointSets(case['spacing'], case['stochastic'], case.get('concave'))
    walls, prints, rock = [], set(), None
    for run in range(3):
        rock = None
        start = time.perf_counter()
        rock = cutRockMass(domain, sets, seed=1, concave=concave)
        walls.append(time.perf_counter() - start)
        prints.add(fingerprint(rock))
        if run == 0:
            peak = vmhwmMB()
    out = dict(case=name, side=SIDE, spacing=case['spacing'], orientations=ORIENTATIONS, stochastic=case['stochastic'],
               blocks=len(rock.blocks), slivers=len(rock.slivers), merged=rock.merged,
               snappedCorners=rock.stats['snappedCorners'], planes=rock.stats['planes'], cuts=rock.stats['cuts'],
               skippedCuts=rock.stats['skippedCuts'], vertices=rock.stats['vertices'],
               exactSigns=rock.stats['signsExact'],
               filteredSigns=rock.stats['signsFromBounds'] + rock.stats['signsFromIntervals'],
               volumeError=abs(sum(b.volume for b in rock.blocks) + sum(b.volume for b in rock.slivers)
                               - rock.domainVolume) / rock.domainVolume,
               wallSeconds=walls, wallSecondsMin=min(walls), coreSeconds=rock.stats['seconds'],
               bitwiseRepeatable=len(prints) == 1, concave=concave,
               concaveBlocks=sum(len(g) > 1 for g in rock.groups), ddaBlocks=len(rock.groups),
               vmhwmBaselineMB=baseline, vmhwmAfterCutMB=peak, cutPeakIncreaseMB=peak - baseline)
    if case['bodies']:
        mat = O.materials.append(wrapper.PolyhedraMat(young=1e9, poisson=0.25, density=2600))
        start = time.perf_counter()
        if concave:
            rock.append(material=mat)
        else:
            O.bodies.append(rock.ddaBlocks(material=mat))
        out['bodiesSeconds'] = time.perf_counter() - start
        out['vmhwmAfterBodiesMB'] = vmhwmMB()
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--cases', default=','.join(CASES))
    parser.add_argument('--case', help=argparse.SUPPRESS)  # a child process: run one case, print its JSON
    parser.add_argument('--out', default=os.path.join(os.path.dirname(__file__), 'out', 'rock_mass.json'))
    args = parser.parse_args()
    if args.case:
        print(json.dumps(runCase(args.case)))
        return
    rows = []
    for name in args.cases.split(','):
        done = subprocess.run([sys.executable, os.path.abspath(__file__), '--case', name], check=True,
                              stdout=subprocess.PIPE, text=True)
        rows.append(json.loads(done.stdout.strip().splitlines()[-1]))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(dict(benchmark='rock_mass', rows=rows), f, indent=1)
    print('%-14s %8s %8s %7s %7s %9s %9s %9s %10s %10s' % ('case', 'blocks', 'concave', 'merged', 'slivers', 'wall [s]',
                                                          'core cut', 'slivers', 'peak+ [MB]', 'bodies [s]'))
    for r in rows:
        print('%-14s %8d %8d %7d %7d %9.2f %9.3f %9.3f %10.0f %10s' % (
            r['case'], r['blocks'], r['concaveBlocks'], r['merged'], r['slivers'], r['wallSecondsMin'],
            r['coreSeconds']['cut'],
            r['coreSeconds']['slivers'], r['cutPeakIncreaseMB'],
            '%.1f' % r['bodiesSeconds'] if 'bodiesSeconds' in r else '-'))
    print('wrote', args.out)


if __name__ == '__main__':
    main()
