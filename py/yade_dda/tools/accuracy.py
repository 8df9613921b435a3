"""Accuracy against time: sweep one accuracy knob of a DDA scene, measure its
error and what it cost.

A scene is two callables (SI units throughout)::

    def build():                 # O is already reset: add materials, blocks, O.engines
        ...                      # with one DDAIntegrator (and optionally an MSCCollider)
    def measure():               # after the run: the error against your closed form
        return abs(x - exact)    # a float [your unit], or a dict with at least 'error'

    from yade_dda.tools.accuracy import sweep      # also yade_dda.accuracySweep
    points = sweep(build, measure, knob='dt', values=[1e-2, 1e-3, 1e-4], tEnd=1.0)

For each value, `sweep` resets YADE (``O.reset()``), calls ``build()``, sets
the knob on the scene's engine, runs until ``O.time == tEnd`` exactly
(``advance``) and calls ``measure()``. Knobs (``KNOBS``) are parameters of
``DDAIntegrator`` (``dt`` [s], also spelt ``maxTimeStep``;
``maxDisplacementRatio`` [-], ``maxDisplacement`` [m],
``contactPenaltyFactor`` [-], ...) or of
``MSCCollider`` (``criticalLength`` [m], ``segments`` [-]; one is inserted
before the integrator when the scene has none).

Each point is a dict: the knob and value, ``error`` (and whatever else
``measure`` returned), ``wallSeconds`` (perf_counter time of the calls that
advanced the scene, the per-step monitor's own time taken out),
``wallPerSimulatedSecond`` (= wallSeconds / tEnd, the cost measure of the
benchmark), ``engineSeconds`` (YADE's time inside ``DDAIntegrator``, sync
included), ``steps``, the mean ``dt`` taken, and per-step sums of the core's
counters (``stats()``: step cuts, open-close iterations, candidate pairs,
sub-unit tests, broad- and narrow-phase time) and the deepest
``maxPenetration`` [m] of any step.

The monitor that collects these counters runs inside the integrator's
engine call, right after each step (no extra engine, so no extra engine
dispatch and no extra sync of the bodies); its own time is measured and
taken out of ``wallSeconds`` and ``engineSeconds``. ``monitor=`` adds your
own per-step callable (read the core with ``yade_dda.block``/``contacts``,
which need no sync; its time is taken out too).

From the command line, for a script that defines ``build``, ``measure`` and
``tEnd``: ``bench/accuracy.py --scene my_scene.py --knob dt=1e-2,1e-3,1e-4``.
"""
import math
import time

from .._yade import O
from .. import engines as _engines
from ..colliders import MSCCollider
from ..scene import stats

# knob name -> (engine class name, parameter name, unit)
KNOBS = {
    'dt': ('DDAIntegrator', 'dt', 's'),
    'maxTimeStep': ('DDAIntegrator', 'dt', 's'),
    'maxDisplacementRatio': ('DDAIntegrator', 'maxDisplacementRatio', '-'),
    'maxDisplacement': ('DDAIntegrator', 'maxDisplacement', 'm'),
    'contactPenaltyFactor': ('DDAIntegrator', 'contactPenaltyFactor', '-'),
    'shearStiffnessRatio': ('DDAIntegrator', 'shearStiffnessRatio', '-'),
    'contactDistance': ('DDAIntegrator', 'contactDistance', 'm'),
    'maxOpenCloseIterations': ('DDAIntegrator', 'maxOpenCloseIterations', '-'),
    'timeStepGrowth': ('DDAIntegrator', 'timeStepGrowth', '-'),
    'criticalLength': ('MSCCollider', 'criticalLength', 'm'),
    'segments': ('MSCCollider', 'segments', '-'),
}

# per-step sums of these stats() counters go into each point
_SUMMED = ('stepCuts', 'openCloseIterationsTotal', 'openCloseCuts', 'candidatePairs', 'contactPairs',
           'contacts', 'closedContacts', 'subUnitPairs', 'subUnitTests', 'shellPairs', 'shellTests',
           'fullSearchPairs')
_TIMES = ('broadPhase', 'narrowPhase', 'assembly', 'solve', 'core')

class _Monitor:
    """Per-step collector, called inside DDAIntegrator's engine call right after the step."""

    def __init__(self, user):
        self.user = user
        self.seconds = 0.0
        self.steps = 0
        self.sums = {}
        self.times = {k: 0.0 for k in _TIMES}
        self.maxPenetration = 0.0
        self.openCloseFailures = 0

    def step(self):
        start = time.perf_counter()
        s = stats()
        self.steps += 1
        for key in _SUMMED:
            if key in s:
                self.sums[key] = self.sums.get(key, 0) + s[key]
        for key in _TIMES:
            self.times[key] += s['time'].get(key, 0.0)
        self.maxPenetration = max(self.maxPenetration, s.get('maxPenetration', 0.0))
        self.openCloseFailures = s.get('openCloseFailures', 0)
        if self.user is not None:
            self.user()
        self.seconds += time.perf_counter() - start


def knobEngine(knob):
    """The engine in O.engines that carries `knob` (inserting an MSCCollider for
    MSC knobs when there is none) and the parameter name. Raises ValueError for
    an unknown knob, RuntimeError when the scene has no DDAIntegrator."""
    if knob not in KNOBS:
        raise ValueError('unknown knob %r; knobs: %s' % (knob, ', '.join(sorted(KNOBS))))
    cls, param, _ = KNOBS[knob]
    engines = list(O.engines)
    integrators = [i for i, e in enumerate(engines) if type(e).__name__ == 'DDAIntegrator']
    if len(integrators) != 1:
        raise RuntimeError('the scene must put exactly one DDAIntegrator in O.engines (found %d)' % len(integrators))
    if cls == 'DDAIntegrator':
        return engines[integrators[0]], param
    found = [e for e in engines if type(e).__name__ == cls]
    if found:
        return found[0], param
    engine = MSCCollider(label='collider')
    engines.insert(integrators[0], engine)
    O.engines = engines
    return engine, param


def advance(tEnd, budgetFactor=1000):
    """Runs the scene until O.time == tEnd [s] exactly, in as few ``O.run(n, True)``
    calls as the step control allows (whole steps of the integrator's dt; a
    last shorter step lands on tEnd). Returns the wall seconds spent in the run
    calls. Raises RuntimeError when more than `budgetFactor` times the nominal
    step count is needed (a collapsing time step)."""
    if not tEnd > O.time:
        raise ValueError('tEnd = %r s must be later than O.time = %r s' % (tEnd, O.time))
    dda = knobEngine('dt')[0]
    dt = dda.dt
    budget = budgetFactor * int(math.ceil((tEnd - O.time) / dt)) + 100
    wall = 0.0
    taken = 0
    while True:
        remaining = tEnd - O.time
        if remaining <= 1e-12 * max(1.0, tEnd):
            break
        if taken > budget:
            raise RuntimeError('time step collapsed: O.time = %.6g s of %.6g s after %d steps' % (O.time, tEnd, taken))
        n = int(math.floor(remaining / dt * (1 - 1e-12)))
        if n >= 1:
            start = time.perf_counter()
            O.run(n, True)
            wall += time.perf_counter() - start
            taken += n
        else:                                   # the last, shorter step
            dda.dt = remaining
            start = time.perf_counter()
            O.run(1, True)
            wall += time.perf_counter() - start
            dda.dt = dt
            taken += 1
    return wall


def runPoint(build, measure, tEnd, settings=None, monitor=None):
    """One run: O.reset(), build(), engine settings {knob: value}, advance to
    tEnd [s], measure(). Returns the point dict (see the module docstring)."""
    O.reset()
    build()
    settings = dict(settings or {})
    for knob, value in settings.items():
        engine, param = knobEngine(knob)
        setattr(engine, param, value)
    mon = _Monitor(monitor)
    original = _engines.integratorStep

    def stepAndMonitor(text):
        original(text)
        mon.step()
    _engines.integratorStep = stepAndMonitor
    iter0 = O.iter
    try:
        wall = advance(tEnd)
    finally:
        _engines.integratorStep = original
    engineSeconds = stats()['stepTimeTotal'] - mon.seconds
    result = measure()
    if not isinstance(result, dict):
        result = {'error': result}
    if 'error' not in result:
        raise ValueError("measure() must return a float or a dict with an 'error' entry, got %r" % (result,))
    steps = O.iter - iter0
    point = dict(settings)
    point.update(result)
    wall -= mon.seconds
    point.update(wallSeconds=wall, wallPerSimulatedSecond=wall / tEnd, engineSeconds=engineSeconds,
                 monitorSeconds=mon.seconds, steps=steps, meanDt=tEnd / max(steps, 1), simulatedTime=O.time,
                 maxPenetration=mon.maxPenetration, openCloseFailures=mon.openCloseFailures,
                 perStep={k: v / max(mon.steps, 1) for k, v in mon.sums.items()},
                 phaseSeconds=dict(mon.times),
                 detectionMsPerStep=1e3 * (mon.times['broadPhase'] + mon.times['narrowPhase']) / max(mon.steps, 1))
    return point


def sweep(build, measure, knob, values, tEnd, base=None, monitor=None, log=None):
    """Runs `build`/`measure` once per value of `knob` (see the module docstring).

    build() [no arguments]: makes the scene (O is reset before); measure():
    error after the run, a float or a dict with 'error'; knob: a name of
    ``KNOBS``; values: the knob's values (its unit in ``KNOBS``); tEnd [s]:
    simulated time of each run; base: other knob settings {name: value} for
    every run; monitor: optional callable run after every step; log: optional
    callable(str) told about each point. Returns the list of points.
    """
    if knob not in KNOBS:
        raise ValueError('unknown knob %r; knobs: %s' % (knob, ', '.join(sorted(KNOBS))))
    values = list(values)
    if not values:
        raise ValueError('no values to sweep for %s' % knob)
    if not (isinstance(tEnd, (int, float)) and math.isfinite(tEnd) and tEnd > 0):
        raise ValueError('tEnd must be a positive number of seconds, got %r' % (tEnd,))
    for other in (base or {}):
        if other not in KNOBS:
            raise ValueError('unknown knob %r in base; knobs: %s' % (other, ', '.join(sorted(KNOBS))))
    points = []
    for value in values:
        settings = dict(base or {})
        settings[knob] = value
        point = runPoint(build, measure, tEnd, settings, monitor)
        point['knob'], point['value'] = knob, value
        points.append(point)
        if log:
            log('%s = %-10.4g error %.4g, wall %.3f s per simulated s, %d steps'
                % (knob, value, point['error'], point['wallPerSimulatedSecond'], point['steps']))
    return points


def paretoFront(points, x='wallPerSimulatedSecond', y='error'):
    """Indices of the points no other point beats in both cost `x` and `y`
    (lower is better in both), sorted by cost."""
    order = sorted(range(len(points)), key=lambda i: (points[i][x], points[i][y]))
    front, best = [], math.inf
    for i in order:
        if points[i][y] < best:
            front.append(i)
            best = points[i][y]
    return front
