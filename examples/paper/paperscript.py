# -*- coding: utf-8 -*-
"""YADE side shared by the paper scene scripts: parameters, building the
blocks of a ``scenes`` builder, the run (blocking in batch mode, non-blocking
in the GUI) and the summary with its checks.

Parameters (e.g. ``steps``) come, last one winning, from the defaults, a YADE
batch table (``yade-batch``: ``yade.utils.readParamsFromTable``), environment
variables ``DDA_<NAME>`` (``DDA_STEPS=500``) and the script's command line
(``yade -n -x hexahedra_drop.py --steps 500 --length 40``).
"""
import math
import os
import sys
import time

import yade
from yade import utils, wrapper
import yade_dda
from yade_dda import O, ddaBlock, block, stats, printStats, contacts, DDAIntegrator

import paper_scenes as scenes

PENETRATION_TOLERANCE = 1e-6   # largest initial penetration accepted [m]
SAMPLE_PERIOD = 10             # steps between samples of stats() (peak penetration, contacts, dt)


def readParams(**defaults):
    """The script's parameters as a dict (see the module docstring)."""
    utils.readParamsFromTable(noTableOk=True, unknownOk=False, **defaults)
    from yade.params import table
    values = {name: getattr(table, name, value) for name, value in defaults.items()}

    def convert(name, text):
        kind = type(defaults[name])
        if kind is bool:
            return text.lower() in ('1', 'true', 'yes', 'on')
        return kind(text)

    for name in defaults:
        env = 'DDA_' + name.upper()
        if os.environ.get(env):
            values[name] = convert(name, os.environ[env])
    args = list(sys.argv[1:])
    while args:
        arg = args.pop(0)
        if not arg.startswith('--'):
            raise SystemExit('unexpected argument %r (parameters: %s)' % (arg, ', '.join('--' + n for n in defaults)))
        name, _, text = arg[2:].partition('=')
        if name not in defaults:
            raise SystemExit('unknown parameter --%s (parameters: %s)' % (name, ', '.join('--' + n for n in defaults)))
        if not text:
            if not args:
                raise SystemExit('--%s needs a value' % name)
            text = args.pop(0)
        values[name] = convert(name, text)
    return values


def batchMode():
    """True when the script should run to the end itself (``-x``, ``-n``, no
    display, or imported from plain Python); False in an interactive GUI."""
    opts = getattr(yade.runtime, 'opts', None)
    if opts is None:
        return True
    return bool(getattr(opts, 'exitAfter', True) or getattr(opts, 'nogui', True)
                or not getattr(yade.runtime, 'hasDisplay', False))


COLLIDERS = ('MSC', 'DESS', 'NBS', 'AllPairs')


def engines(collider='MSC'):
    """The paper's engines: the broad phase named `collider` (an engine of
    COLLIDERS, default MSC, the paper's method) and the DDA integrator with
    the paper's step controls (max dt, allowed step displacement), gravity g."""
    if collider not in COLLIDERS:
        raise SystemExit('unknown collider %r (one of %s)' % (collider, ', '.join(COLLIDERS)))
    return [getattr(yade_dda, collider + 'Collider')(label='collider'),
            DDAIntegrator(dt=scenes.STEP['dt'], gravity=(0, 0, -scenes.G),
                          maxDisplacement=scenes.STEP['maxDisplacement'], label='dda')]


def build(blocks, mat):
    """Appends the blocks [(vertices, fixed)] with material dict ``mat``; returns the body ids."""
    rock = O.materials.append(wrapper.PolyhedraMat(young=mat['young'], poisson=mat['poisson'],
                                                   density=mat['density'], frictionAngle=mat['frictionAngle']))
    return [O.bodies.append(ddaBlock(vertices, material=rock, fixed=fixed)) for vertices, fixed in blocks]


class Run:
    """Runs ``steps`` steps of the current scene and reports; ``free`` are the moving bodies."""

    def __init__(self, name, ids, blocks, steps):
        self.name, self.ids, self.steps = name, ids, int(steps)
        self.nfixed = sum(1 for _, fixed in blocks if fixed)
        self.free = [i for i, (_, fixed) in zip(ids, blocks) if not fixed]
        self.start = {}
        self.problems = []
        self.peakPenetration = 0.0
        self.peakPenetrationStep = 0
        self.peakContacts = 0
        self.smallestDt = float('inf')
        self.wall = 0.0
        self.detection = dict(samples=0, candidatePairs=0, subUnitTests=0, seconds=0.0)

    def firstStep(self):
        """One step, then the initial checks: no NaN, no block starting inside another."""
        self.start = {i: tuple(block(i).centroid) for i in self.free}
        t0 = time.perf_counter()
        O.step()
        self.wall += time.perf_counter() - t0
        s = stats()
        self.sample(s, step=1)
        initialGap = min([c.gap for c in contacts()] or [0.0])
        if s['maxPenetration'] > PENETRATION_TOLERANCE or initialGap < -PENETRATION_TOLERANCE:
            self.problems.append('initial penetration: maxPenetration %.3e m, smallest gap %.3e m after step 1'
                                 % (s['maxPenetration'], initialGap))
        print('%s: %d blocks (%d fixed, %d free); step 1: %d candidate pairs, %d contact pairs, '
              '%d sub-contacts, max penetration %.3e m, smallest initial gap %.3e m'
              % (self.name, len(self.ids), self.nfixed, len(self.free), s['candidatePairs'], s['contactPairs'],
                 s['contacts'], s['maxPenetration'], initialGap))

    def sample(self, s=None, step=None):
        """Keeps the peaks of stats() (in a PyRunner, O.iter + 1 is the number of the step just taken)."""
        s = stats() if s is None else s
        if s['maxPenetration'] > self.peakPenetration:
            self.peakPenetration = s['maxPenetration']
            self.peakPenetrationStep = O.iter + 1 if step is None else step
        self.peakContacts = max(self.peakContacts, s['contacts'])
        self.smallestDt = min(self.smallestDt, s['dt'])
        d = self.detection
        d['samples'] += 1
        d['candidatePairs'] += s['candidatePairs']
        d['subUnitTests'] += s['subUnitTests']
        d['seconds'] += s['time']['broadPhase'] + s['time']['narrowPhase']

    def runBatch(self):
        """Blocking run of the remaining steps (batch mode)."""
        left = self.steps - O.iter
        if left > 0:
            t0 = time.perf_counter()
            O.run(left, True)
            self.wall += time.perf_counter() - t0
        return self.finish()

    def startGui(self):
        """Non-blocking run of the remaining steps; a PyRunner prints the summary in the last one."""
        left = self.steps - O.iter
        if left <= 0:
            return self.finish()
        self._t0 = time.perf_counter()
        self._done = False
        O.engines = O.engines + [wrapper.PyRunner(iterPeriod=1, label='paperSummary', command='paperRun.guiStep()')]
        O.run(left)

    def guiStep(self):
        # O.iter is the step being taken; the summary follows the DDA step of the last one.
        if not self._done and O.iter + 1 >= self.steps:
            self._done = True
            self.finish(gui=True)

    def displacements(self):
        out = []
        for i in self.free:
            c, c0 = block(i).centroid, self.start[i]
            out.append(math.sqrt(sum((c[k] - c0[k]) ** 2 for k in range(3))))
        return out

    def finish(self, gui=False):
        """Prints the summary; returns True when every check passed."""
        steps = O.iter + (1 if gui else 0)
        if gui:
            self.wall += time.perf_counter() - self._t0
        s = stats()
        self.sample(s, step=steps)
        d = self.displacements()
        finite = all(math.isfinite(x) for i in self.free for x in tuple(block(i).centroid) + tuple(block(i).velocity))
        if not finite:
            self.problems.append('NaN or inf in a block state')
        closed = sum(1 for c in contacts('closed'))
        print()
        print('%s summary' % self.name)
        print('  blocks             %d (%d fixed, %d free)' % (len(self.ids), self.nfixed, len(self.free)))
        print('  steps              %d' % steps)
        print('  simulated time     %.4f s (mean dt %.3e s, smallest sampled %.3e s)'
              % (O.time, O.time / max(steps, 1), self.smallestDt))
        print('  contacts now       %d sub-contacts (%d closed) in %d pairs; most sampled %d'
              % (s['contacts'], closed, s['contactPairs'], self.peakContacts))
        print('  block displacement max %.4f m, mean %.4f m (centroids since start)'
              % (max(d or [0.0]), sum(d) / max(len(d), 1)))
        print('  penetration        now %.3e m, largest sampled %.3e m (step %d)'
              % (s['maxPenetration'], self.peakPenetration, self.peakPenetrationStep))
        print('  displacement-limit misses %d, open-close failures %d (cumulative)'
              % (s['displacementLimitMisses'], s['openCloseFailures']))
        print('  wall time          %.2f s, %.2f ms/step' % (self.wall, 1e3 * self.wall / max(steps, 1)))
        n = max(self.detection['samples'], 1)
        print('  detection (%s)   %.1f candidate pairs, %.0f sub-unit tests, %.3f ms per step (mean of %d samples)'
              % (s['collider'], self.detection['candidatePairs'] / n,
                 self.detection['subUnitTests'] / n, 1e3 * self.detection['seconds'] / n, self.detection['samples']))
        printStats()
        if self.peakPenetration > s['allowedDisplacement']:
            print('WARNING: a contact penetrated %.3e m, more than the allowed step displacement %.3e m '
                  '(an impact too hard for the penalty spring, or a contact found late)'
                  % (self.peakPenetration, s['allowedDisplacement']))
        for p in self.problems:
            print('PROBLEM: ' + p)
        print('%s: %s' % (self.name, 'OK' if not self.problems else 'FAILED'))
        return not self.problems


def run(name, ids, blocks, steps):
    """First step and checks, then the rest: blocking in batch mode (exits 1
    on a failed check), non-blocking in the GUI. Returns the Run."""
    r = Run(name, ids, blocks, steps)
    sys.modules['__main__'].paperRun = r          # for the GUI's summary PyRunner
    r.firstStep()
    # Samples stats() every SAMPLE_PERIOD steps (it makes the DDA integrator
    # write the moving bodies then, which costs little). A PyRunner rather
    # than a loop of short blocking O.run(n, True) calls: each of those
    # waits about 40 ms for YADE's run thread.
    O.engines = O.engines + [wrapper.PyRunner(iterPeriod=SAMPLE_PERIOD, initRun=False, label='paperSampler',
                                              command='paperRun.sample()')]
    if batchMode():
        if not r.runBatch():
            raise SystemExit(1)
    else:
        r.startGui()
    return r
