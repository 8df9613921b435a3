"""Where the frictional slides' error comes from (doc/benchmarks.md, "What accuracy costs").

Runs bench/accuracy.py's incline (30 deg, 20 deg friction) and wedge (FS 0.8)
for 1 s at dt = 1e-2, 1e-3 and 1e-4 s, with the moving block deformable (the
bench's default) or rigid, started from rest (DDAIntegrator's default) or as
placed (startFromRest=False). Records the slide error at 1 s [m] and the
velocity error along the slide against the closed form g_s t [m/s] at 3 ms,
10 ms, 0.1 s and 1 s: a constant velocity error is a start-up offset, one that
grows in time a wrong acceleration.

Writes bench/out/accuracy_start.json and prints a line per case. About a
minute on the 2-core machine. Run:
  YADE_DDA_BUILD=<build>/py /usr/bin/python3 bench/accuracy_start.py
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import accuracy as A  # noqa: E402  (the bench's scenes)

yade_dda = A._importDDA()
from yade_dda import O, block  # noqa: E402

TIMES = (0.003, 0.01, 0.1, 1.0)
STEPS = (1e-2, 1e-3, 1e-4)
_rigid = [False]
_ddaBlock = yade_dda.ddaBlock


def _block(*args, **kwargs):
    """ddaBlock with the moving block made rigid when asked (the scenes import it at build time)."""
    if _rigid[0] and not kwargs.get('fixed'):
        kwargs['rigid'] = True
    return _ddaBlock(*args, **kwargs)


yade_dda.ddaBlock = _block


def run(name, dt, rigid, startFromRest):
    _rigid[0] = rigid
    O.reset()
    scene = A.SCENES[name]()
    scene.build()
    dda = [e for e in O.engines if type(e).__name__ == 'DDAIntegrator'][0]
    dda.dt, dda.startFromRest = dt, startFromRest
    ctx = scene.context
    if name == 'wedge':
        direction = ctx['keel']
        acceleration = A.G * math.sin(ctx['psi']) * (1 - A.WEDGE['fs'])
    else:
        direction = (1.0, 0.0, 0.0)
        acceleration = A.G * (math.sin(math.radians(A.SLOPE_DEG)) - math.tan(math.radians(20.0))
                              * math.cos(math.radians(A.SLOPE_DEG)))
    velocityErrors, done = {}, 0
    for t in TIMES:
        steps = int(round(t / dt)) - done
        if t < dt:
            continue
        if steps > 0:
            O.run(steps, True)
            done += steps
        v = block(ctx['id']).velocity
        velocityErrors['%g' % O.time] = A._dot(v, direction) - acceleration * O.time
    m = scene.measure()
    stats = yade_dda.stats()
    return dict(scene=name, dt=dt, rigid=rigid, startFromRest=startFromRest, time=O.time,
                slideError=m['slide'] - m['exact'], relativeError=m['relativeError'], velocityErrors=velocityErrors,
                settleSteps=stats.get('settleSteps'), settledBlocks=stats.get('settledBlocks'))


def main():
    rows = []
    for name in ('incline_friction', 'wedge'):
        for rigid in (False, True):
            for startFromRest in (True, False):
                for dt in STEPS:
                    r = run(name, dt, rigid, startFromRest)
                    rows.append(r)
                    print('%-16s %-10s %-7s dt %-6g slide error %+.2e m (%+.1e)  velocity error %s  settled %s'
                          % (name, 'rigid' if rigid else 'deformable', 'settled' if startFromRest else 'placed', dt,
                             r['slideError'], r['relativeError'],
                             ' '.join('%s s: %+.1e' % (k, v) for k, v in r['velocityErrors'].items()),
                             r['settledBlocks']), flush=True)
    out = os.path.join(HERE, 'out', 'accuracy_start.json')
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, 'w') as f:
        json.dump(dict(rows=rows, times=TIMES), f, indent=1)
    print('wrote', out)


if __name__ == '__main__':
    main()
