"""Fingerprints of the regression and paper scenes: what a refactor must leave bitwise.

Every row of examples/regression/full.table and the three paper scenes of
examples/paper are run step by step, each in its own process, and after every
step the contact set is hashed (per sub-contact: body ids, kind, state, normal
force and shear force as exact floats, in the order yade_dda.contacts() gives),
together with O.time and O.iter; after the last step the whole state is hashed
too (per block: vertices, 12 rates, stress; the contact set). The regression
scenes run to their table's tEnd exactly as `make regress` runs them (the
tool replaces regression.runTo with the same steps taken one at a time: O.run(n)
is n steps); the paper scenes run their first --paper-steps steps (1000).

Writes a JSON file {scene: {steps, perStep: [sha256 per step], final: sha256}}
and, with --compare A B, prints the first step at which each scene differs.

Run:  /usr/bin/python3 bench/fingerprints.py [--out bench/out/fingerprints.json]
      /usr/bin/python3 bench/fingerprints.py --compare before.json after.json
(`make fingerprints`; YADE_DDA_BUILD=<build>/py to fingerprint a build tree.)
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
REGRESSION = os.path.join(REPO, 'examples', 'regression')
PAPER = os.path.join(REPO, 'examples', 'paper')
PAPER_SCENES = ['hexahedra_drop.py', 'single_block_slide.py', 'slanted_slide.py']


def _floats(values):
    return ','.join(float(v).hex() for v in values)


def contactHash():
    """sha256 of O.time, O.iter and every sub-contact (exact floats)."""
    import yade_dda
    from yade_dda import O
    h = hashlib.sha256()
    h.update(('%s %d|' % (float(O.time).hex(), O.iter)).encode())
    for c in yade_dda.contacts():
        h.update(('%d %d %s %s %s %s;' % (c.id1, c.id2, c.kind, c.state, float(c.normalForce).hex(),
                                         _floats(c.shearForce))).encode())
    return h.hexdigest()


def stateHash():
    """sha256 of every block's vertices, rates and stress, and the contact set."""
    import yade_dda
    h = hashlib.sha256()
    for b in yade_dda.scene.current(create=False).bodyOfBlock:
        blk = yade_dda.block(b)
        h.update(('%d:%s|%s|%s;' % (b, ','.join(_floats(v) for v in blk.vertices), _floats(blk.velocity),
                                    _floats(blk.stress))).encode())
    h.update(contactHash().encode())
    return h.hexdigest()


def _worker(kind, spec, paperSteps):
    """Runs one scene in this process; prints its fingerprint as JSON on the last line."""
    if os.environ.get('YADE_DDA_BUILD'):
        sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
    import yade_dda  # noqa: F401  (boots YADE)
    from yade_dda import O
    perStep = []

    def stepped(n):
        for _ in range(n):
            O.step()
            perStep.append(contactHash())

    if kind == 'regression':
        from yade_dda.tools import regression
        table, line = spec.rsplit(':', 1)
        os.environ['YADE_BATCH'] = spec
        os.environ.setdefault('YADE_DDA_RECORDS', os.path.join('/tmp', 'yade-dda-fingerprint-records'))
        from yade import utils
        script = utils.TableParamReader(table).paramDict()[int(line)]['!SCRIPT']

        def runTo(tEnd, budgetFactor=4):
            # regression.runTo's steps, one O.step() at a time (its O.run(n, True) is n steps).
            dda = [e for e in O.engines if type(e).__name__ == 'DDAIntegrator'][0]
            dt = dda.dt
            n = int((tEnd - O.time) / dt + 1e-9) - 1
            if n > 0:
                stepped(n)
            try:
                while O.time < tEnd - 1e-12 * max(1.0, tEnd):
                    dda.dt = min(dt, tEnd - O.time)
                    stepped(1)
            finally:
                dda.dt = dt

        regression.runTo = runTo
        path = os.path.join(REGRESSION, script)
        os.chdir(REGRESSION)
    else:
        sys.path.insert(0, PAPER)
        import paperscript

        def run(name, ids, blocks, steps, **kw):
            stepped(paperSteps)

        paperscript.run = run
        os.environ['DDA_STEPS'] = str(paperSteps)
        path = os.path.join(PAPER, spec)
        os.chdir(PAPER)
    sys.argv = [path]
    code = compile(open(path).read(), path, 'exec')
    exec(code, {'__name__': '__main__', '__file__': path})
    print(json.dumps(dict(steps=len(perStep), perStep=perStep, final=stateHash())))


def scenes():
    """(name, kind, spec) of every scene fingerprinted."""
    table = os.path.join(REGRESSION, 'full.table')
    out = []
    for number, text in enumerate(open(table), start=1):
        fields = text.split()
        if not fields or fields[0].startswith('#') or fields[0] == 'description':
            continue
        out.append(('regression/' + fields[0], 'regression', '%s:%d' % (table, number)))
    out += [('paper/' + name[:-3], 'paper', name) for name in PAPER_SCENES]
    return out


def compare(a, b):
    A, B = json.load(open(a)), json.load(open(b))
    same = True
    for name in sorted(set(A) | set(B)):
        if name not in A or name not in B:
            print('%-40s only in %s' % (name, a if name in A else b))
            same = False
            continue
        x, y = A[name], B[name]
        first = next((i for i, (p, q) in enumerate(zip(x['perStep'], y['perStep'])) if p != q), None)
        if first is None and x['steps'] == y['steps'] and x['final'] == y['final']:
            print('%-40s identical (%d steps)' % (name, x['steps']))
            continue
        same = False
        where = 'step %d' % (first + 1) if first is not None else 'step count %d vs %d or final state' % (
            x['steps'], y['steps'])
        print('%-40s DIFFERS from %s' % (name, where))
    return same


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', default=os.path.join(HERE, 'out', 'fingerprints.json'))
    parser.add_argument("--paper-steps", type=int, default=1000)
    parser.add_argument('--only', default=None, help='substring of the scene names to run')
    parser.add_argument('--compare', nargs=2, metavar=('A', 'B'))
    parser.add_argument('--worker', nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.compare:
        sys.exit(0 if compare(*args.compare) else 1)
    if args.worker:
        _worker(args.worker[0], args.worker[1], args.paper_steps)
        return
    result, start = {}, time.time()
    for name, kind, spec in scenes():
        if args.only and args.only not in name:
            continue
        t0 = time.time()
        run = subprocess.run([sys.executable, os.path.abspath(__file__), '--paper-steps', str(args.paper_steps),
                              '--worker', kind, spec], capture_output=True, text=True)
        lines = run.stdout.strip().splitlines()
        if run.returncode != 0 or not lines or not lines[-1].startswith('{'):
            sys.stderr.write(run.stdout[-2000:] + run.stderr[-4000:])
            raise SystemExit('%s failed (exit %d)' % (name, run.returncode))
        result[name] = json.loads(lines[-1])
        print('%-40s %5d steps  %6.1f s  %s' % (name, result[name]['steps'], time.time() - t0,
                                                 result[name]['final'][:16]), flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(result, f, indent=1)
    print('%d scenes in %.0f s -> %s' % (len(result), time.time() - start, args.out))


if __name__ == '__main__':
    main()
