"""Benchmark: speed and scale of the DDA step on random slender deposits, with their targets.

One table per size n (1,000, 10,000, 50,000 blocks; bench/colliders.py's seeded generator
``slenderScene``, d0 = 1 cm, so anyone can reproduce it):

- detection (broad + narrow phase) of MSC, DESS and YADE's InsertionSortCollider with its Polyhedra
  functors, one thread each, from bench/colliders.py run as a child (``--paper ''``): MSC/YADE and
  MSC/DESS, MSC's candidate pairs over the true contact pairs, peak memory per block;
- the full DDA step with MSC (``O.step()``, which syncs YADE's bodies and views every step) and the
  sync's share, on 1 and on 2 threads, alternated in one process (``--rounds`` rounds, medians);
- the paper's 70-block hexahedra drop (examples/paper) once piled up: steps per second of
  ``O.run(n)`` on 1 and 2 threads.

Writes bench/out/scale.json (everything, with each target's verdict) and scale_steps.png (time per
step against blocks, log-log, n log n drawn), and prints the table. Long: about half an hour with
50,000 blocks (YADE's step alone takes seconds there). Run: make bench-scale, or
/usr/bin/python3 bench/scale.py [--sizes 1000,10000] (YADE_DDA_BUILD=<build>/py for a build tree);
--detection-only gives the detection columns alone (with the narrow phase's cost per candidate pair), all
on one thread, in a few minutes.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import colliders  # noqa: E402  (the slender generator and the detection benchmark)
import drop  # noqa: E402  (the paper's 70-block drop)

TARGETS = dict(syncShare=0.10, twoThreadRatio=0.6, mscOverYade=1 / 30, candidatesOverPairs=1.5, dropStepsPerSecond=300)


def _child(args):
    """Runs this file as a child with `args`; returns its JSON result (its last stdout line)."""
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, os.path.abspath(__file__)] + args, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        raise RuntimeError('child %s failed: %s' % (args, proc.stderr[-3000:]))
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _importDDA():
    if os.environ.get('YADE_DDA_BUILD'):
        sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
    import yade_dda
    return yade_dda


def threadsWorker(n, seed, outDir, rounds):
    """The slender scene of n blocks under MSC, stepped with O.step() on 1 and 2 threads in turn."""
    yade_dda = _importDDA()
    from yade import wrapper
    O = yade_dda.O
    blocks, mat, integrator, gravity = colliders.sceneSpec('slender_%d' % n, outDir, seed)
    material = O.materials.append(wrapper.PolyhedraMat(**mat))
    for points, fixed in blocks:
        O.bodies.append(yade_dda.ddaBlock(points, material=material, fixed=fixed))
    O.engines = [yade_dda.MSCCollider(label='collider'),
                 yade_dda.DDAIntegrator(label='dda', gravity=gravity, threads=1, **integrator)]
    O.step()   # links the bodies, builds the shells: not measured
    rows = {1: [], 2: []}
    for _ in range(rounds):
        for threads in (1, 2):
            O.engines[1].threads = threads
            t0 = time.perf_counter()
            O.step()
            wall = time.perf_counter() - t0
            s = yade_dda.stats()
            t = s['time']
            rows[threads].append(dict(stepMs=1e3 * wall, coreMs=1e3 * t['core'], syncMs=1e3 * t['sync'],
                                      syncBodiesMs=1e3 * t['syncBodies'], syncViewsMs=1e3 * t['syncViews'],
                                      broadMs=1e3 * t['broadPhase'], narrowMs=1e3 * t['narrowPhase'],
                                      assemblyMs=1e3 * t['assembly'], solveMs=1e3 * t['solve'],
                                      updateMs=1e3 * t['update'], candidatePairs=s['candidatePairs'],
                                      contactPairs=s['contactPairs']))
    return {str(k): {key: statistics.median(r[key] for r in v) for key in v[0]} for k, v in rows.items()}


def dropWorker(rounds, steps):
    """The paper's 70-block drop: 1,500 steps to pile up, then rounds of O.run(steps) on 1 and 2 threads."""
    O, yade_dda = drop.build(threads=1, refine=None)
    O.run(1500, True)
    rates = {1: [], 2: []}
    for _ in range(rounds):
        for threads in (1, 2):
            O.engines[1].threads = threads
            t0 = time.perf_counter()
            O.run(steps, True)
            rates[threads].append(steps / (time.perf_counter() - t0))
    s = yade_dda.stats()
    return dict(stepsPerSecond={str(k): statistics.median(v) for k, v in rates.items()},
                rounds={str(k): v for k, v in rates.items()}, contactPairs=s['contactPairs'],
                closedContacts=s['closedContacts'], simulatedTime=O.time,
                lastStepMs={k: 1e3 * v for k, v in s['time'].items()})


def _detection(collidersResult, n):
    """Per strategy: mean detection ms, candidates, contact pairs and peak MB from bench/colliders.py."""
    out = {}
    for summary in collidersResult['summaries']:
        if summary['scene'] == 'slender_%d' % n:
            mean = summary['mean']
            out[summary['strategy']] = dict(detectionMs=mean['detectionMs'], peakMB=summary['peakMB'],
                                            candidatePairs=mean.get('candidatePairs'),
                                            contactPairs=mean.get('contactPairs'), wallMs=mean.get('wallMs'),
                                            broadMs=mean.get('broadMs'), narrowMs=mean.get('narrowMs'))
    return out


def table(rows, drop):
    lines = ['| blocks | MSC detection | YADE ISC + polyhedra | MSC/YADE | MSC/DESS | MSC candidates / pairs | '
             'full DDA step (1 thread) | of which sync | 2 threads / 1 | MB per block (MSC) |',
             '|---|---|---|---|---|---|---|---|---|---|']
    for r in rows:
        lines.append('| %d | %.1f ms | %s | %s | %.2f | %.2f | %.1f ms | %.1f ms (%.1f %%) | %.2f | %.3f |' % (
            r['blocks'], r['mscDetectionMs'], '%.0f ms' % r['yadeDetectionMs'] if r['yadeDetectionMs'] else 'n/a',
            '%.3f (1/%.0f)' % (r['mscOverYade'], 1 / r['mscOverYade']) if r['mscOverYade'] else 'n/a',
            r['mscOverDess'], r['candidatesOverPairs'], r['step1Ms'], r['syncMs'], 100 * r['syncShare'],
            r['twoThreadRatio'], r['mbPerBlock']))
    if drop:
        lines.append('')
        lines.append("70-block hexahedra drop, piled up: %.0f steps/s on 1 thread, %.0f on 2 (%d contact pairs)"
                     % (drop['stepsPerSecond']['1'], drop['stepsPerSecond']['2'], drop['contactPairs']))
    return '\n'.join(lines)


def detectionRow(n, det):
    """The detection columns for n blocks from _detection's strategies."""
    msc, dess, yade = det.get('MSC', {}), det.get('DESS', {}), det.get('InsertionSortCollider', {})
    return dict(
        blocks=n, mscDetectionMs=msc.get('detectionMs'), dessDetectionMs=dess.get('detectionMs'),
        yadeDetectionMs=yade.get('detectionMs'),
        mscOverYade=msc['detectionMs'] / yade['detectionMs'] if yade.get('detectionMs') else None,
        mscOverDess=msc['detectionMs'] / dess['detectionMs'],
        candidatesOverPairs=msc['candidatePairs'] / msc['contactPairs'],
        mscBroadMs=msc.get('broadMs'), mscNarrowMs=msc.get('narrowMs'),
        # The narrow phase's cost per candidate pair [us] (its planes, the pair tests, the contacts' set-up).
        mscNarrowUsPerCandidate=1e3 * msc['narrowMs'] / msc['candidatePairs'] if msc.get('narrowMs') else None,
        mbPerBlock=msc['peakMB'] / n)


def detectionTable(rows):
    lines = ['| blocks | MSC detection | of which narrow | narrow per candidate | YADE ISC + polyhedra | MSC/YADE | '
             'MSC/DESS | MSC candidates / pairs |', '|---|---|---|---|---|---|---|---|']
    for r in rows:
        lines.append('| %d | %.1f ms | %.1f ms | %.2f us | %s | %s | %.2f | %.2f |' % (
            r['blocks'], r['mscDetectionMs'], r['mscNarrowMs'], r['mscNarrowUsPerCandidate'],
            '%.0f ms' % r['yadeDetectionMs'] if r['yadeDetectionMs'] else 'n/a',
            '%.3f (1/%.1f)' % (r['mscOverYade'], 1 / r['mscOverYade']) if r['mscOverYade'] else 'n/a',
            r['mscOverDess'], r['candidatesOverPairs']))
    return '\n'.join(lines)


def plot(rows, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    ns = [r['blocks'] for r in rows]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for key, label in (('step1Ms', 'DDA step, 1 thread'), ('step2Ms', 'DDA step, 2 threads'),
                       ('mscDetectionMs', 'MSC detection'), ('dessDetectionMs', 'DESS detection'),
                       ('yadeDetectionMs', 'YADE ISC + Polyhedra detection')):
        pts = [(r['blocks'], r[key]) for r in rows if r.get(key)]
        if pts:
            ax.loglog(*zip(*pts), 'o-', label=label)
    n0, t0 = rows[0]['blocks'], rows[0]['step1Ms']
    ax.loglog(ns, [t0 * n * math.log(n) / (n0 * math.log(n0)) for n in ns], 'k--', lw=1, label='n log n')
    ax.set_xlabel('blocks')
    ax.set_ylabel('ms per step')
    ax.set_title('Random slender deposits (d0 = 1 cm)')
    ax.legend(fontsize=8)
    ax.grid(True, which='both', alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--sizes', default='1000,10000,50000')
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--rounds', type=int, default=5, help='alternating 1/2-thread rounds per size')
    parser.add_argument('--drop-rounds', type=int, default=3)
    parser.add_argument('--drop-steps', type=int, default=300)
    parser.add_argument('--no-yade', action='store_true', help="skip YADE's collider (its 50,000-block steps take seconds)")
    parser.add_argument('--detection-only', action='store_true',
                        help='only the detection columns (one thread each): no full steps, no 2-thread rounds, no drop')
    parser.add_argument('--out', default=os.path.join(HERE, 'out', 'scale.json'))
    parser.add_argument('--worker', nargs='*', help=argparse.SUPPRESS)
    args = parser.parse_args()
    outDir = os.path.dirname(os.path.abspath(args.out))
    if args.worker:
        kind = args.worker[0]
        if kind == 'threads':
            result = threadsWorker(int(args.worker[1]), args.seed, outDir, args.rounds)
        else:
            result = dropWorker(args.drop_rounds, args.drop_steps)
        print(json.dumps(result))
        return
    os.makedirs(outDir, exist_ok=True)
    sizes = [int(s) for s in args.sizes.split(',') if s]
    started = time.time()
    collidersOut = os.path.join(outDir, 'scale_colliders.json')
    strategies = 'MSC,DESS' + ('' if args.no_yade else ',InsertionSortCollider')
    print('detection: bench/colliders.py --paper "" --sizes %s --strategies %s' % (args.sizes, strategies), flush=True)
    subprocess.run([sys.executable, os.path.join(HERE, 'colliders.py'), '--paper', '', '--sizes', args.sizes,
                    '--strategies', strategies, '--seed', str(args.seed), '--out', collidersOut], check=True)
    with open(collidersOut) as f:
        collidersResult = json.load(f)
    if args.detection_only:
        rows = [detectionRow(n, _detection(collidersResult, n)) for n in sizes]
        verdicts = dict(mscOverYade={str(r['blocks']): r['mscOverYade'] <= TARGETS['mscOverYade'] for r in rows
                                     if r['mscOverYade']},
                        candidatesOverPairs={str(r['blocks']): r['candidatesOverPairs'] <= TARGETS['candidatesOverPairs']
                                             for r in rows})
        result = dict(benchmark='scale, detection only', machine=colliders.machine(), seed=args.seed,
                      sizes=sizes, targets=TARGETS, verdicts=verdicts, rows=rows, seconds=time.time() - started,
                      detectionFrom=os.path.basename(collidersOut),
                      how='bench/colliders.py children, one thread each, means over the steps after the first')
        with open(args.out, 'w') as f:
            json.dump(result, f, indent=1)
        print(detectionTable(rows))
        print('verdicts:', json.dumps(verdicts))
        print('wrote', args.out)
        return
    rows = []
    for n in sizes:
        print('threads: %d blocks ...' % n, flush=True)
        steps = _child(['--worker', 'threads', str(n), '--seed', str(args.seed), '--rounds', str(args.rounds),
                        '--out', args.out])
        one, two = steps['1'], steps['2']
        row = detectionRow(n, _detection(collidersResult, n))
        row.update(step1Ms=one['stepMs'], step2Ms=two['stepMs'], syncMs=one['syncMs'],
                   syncShare=one['syncMs'] / one['stepMs'], twoThreadRatio=two['stepMs'] / one['stepMs'],
                   oneThread=one, twoThreads=two)
        rows.append(row)
    print('drop ...', flush=True)
    drop = _child(['--worker', 'drop', '--drop-rounds', str(args.drop_rounds), '--drop-steps', str(args.drop_steps),
                   '--out', args.out])
    verdicts = dict(
        syncShare={str(r['blocks']): r['syncShare'] <= TARGETS['syncShare'] for r in rows},
        twoThreadRatio={str(r['blocks']): r['twoThreadRatio'] <= TARGETS['twoThreadRatio'] for r in rows},
        mscOverYade={str(r['blocks']): r['mscOverYade'] <= TARGETS['mscOverYade'] for r in rows if r['mscOverYade']},
        candidatesOverPairs={str(r['blocks']): r['candidatesOverPairs'] <= TARGETS['candidatesOverPairs'] for r in rows},
        dropStepsPerSecond={k: v >= TARGETS['dropStepsPerSecond'] for k, v in drop['stepsPerSecond'].items()})
    result = dict(benchmark='scale', machine=colliders.machine(), seed=args.seed, sizes=sizes,
                  targets=TARGETS, verdicts=verdicts, rows=rows, drop=drop, seconds=time.time() - started,
                  detectionFrom=os.path.basename(collidersOut),
                  how='detection: bench/colliders.py children, one thread each, means over the steps after the first; '
                      'steps: O.step() (bodies and views synced every step) alternating 1 and 2 threads in one '
                      'process, medians of %d rounds; drop: O.run(%d) rounds after 1,500 steps' % (args.rounds,
                                                                                                  args.drop_steps))
    with open(args.out, 'w') as f:
        json.dump(result, f, indent=1)
    plot(rows, os.path.splitext(args.out)[0] + '_steps.png')
    print(table(rows, drop))
    print('verdicts:', json.dumps(verdicts))
    print('wrote', args.out)


if __name__ == '__main__':
    main()
