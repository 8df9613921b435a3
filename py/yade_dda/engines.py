"""YADE engines of yade-dda.

YADE runs Python from engines only through ``PyRunner``; each engine here is a
``PyRunner`` subclass whose command calls the compiled core once per step.
The command string carries every parameter, so an engine that comes back from
``O.save()``/``O.load()`` as a plain PyRunner still knows its settings.
"""
import ast
import math
import sys
import time

from ._yade import O, wrapper
from . import _core
from . import guards as _guards
from . import scene as _scene
from .blocks import _vector


def _finite(name, value, low=None, high=None, lowOpen=False, unit=''):
    if isinstance(value, bool):
        raise TypeError('%s must be a number, got %r' % (name, value))
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise TypeError('%s must be a number, got %r' % (name, value)) from None
    ok = math.isfinite(value)
    if ok and low is not None:
        ok = value > low if lowOpen else value >= low
    if ok and high is not None:
        ok = value <= high
    if not ok:
        bounds = '%s%s, %s]' % ('(' if lowOpen else '[', low, high if high is not None else 'inf')
        raise ValueError('%s must be finite and in %s, got %r%s' % (name, bounds, value, unit))
    return value


class _Parameter:
    """A typed engine parameter: default, unit, validation; stored in the command."""

    def __init__(self, default, check, doc):
        self.default, self.check, self.__doc__ = default, check, doc

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, engine, owner=None):
        if engine is None:
            return self
        return engine._params[self.name]

    def __set__(self, engine, value):
        engine._params[self.name] = self.check(value)
        engine._updateCommand()


_COLLIDERS = tuple(_core.colliderNames())   # the core's broad phases (pkg/dda/collider/ColliderFactory.cpp)


_INT_MAX = 2 ** 31 - 1   # the core's counters are C ints


def _integer(name, low, high=_INT_MAX):
    """Validator of an integer parameter in [low, high]; rejects 1.5, '3', True."""
    def check(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
            raise TypeError('%s must be an integer, got %r' % (name, value))
        if not low <= value <= high:
            raise ValueError('%s must be an integer in [%d, %d], got %r' % (name, low, high, value))
        return int(value)
    return check


def _colliderName(value):
    if value not in _COLLIDERS:
        raise ValueError('collider must be one of %s, got %r' % (', '.join(_COLLIDERS), value))
    return value


def _initEngine(engine, label, params):
    """Checks and stores an engine's typed parameters (its class's ``_names``,
    each a _Parameter), runs it every step from the first, sets the label and
    writes the command. Unknown names raise TypeError naming them."""
    names = type(engine)._names
    unknown = set(params) - set(names)
    if unknown:
        raise TypeError('%s has no parameter %s%s' % (
            type(engine).__name__, ', '.join(sorted(unknown)),
            ' (parameters: %s)' % ', '.join(names) if names else ' (it takes none but label)'))
    engine._params = {}
    for name in names:
        descriptor = type(engine).__dict__[name]
        engine._params[name] = descriptor.check(params.get(name, descriptor.default))
    if not isinstance(label, str):
        raise TypeError('label must be a string, got %r' % (label,))
    engine.iterPeriod = 1
    engine.initRun = True
    if label:
        engine.label = label
    engine._updateCommand()


def _vector3(name):
    return lambda value: _vector(value, name)


class DDAIntegrator(wrapper.PyRunner):
    """Shi's implicit DDA time integration of all DDA blocks, with their contacts
    (replaces NewtonIntegrator, and YADE's collider and contact laws).

    Each step solves, for the 12 unknowns D of every moving block
    (translation, rotation, strain; Wu et al. 2014 Eq. 1-6),
    ``K D = F`` with inertia ``(2/dt^2) M D = (2/dt) M v0`` (constant
    acceleration over the step), elastic stiffness ``V E``, the stress of the
    previous step, gravity, fixed-point penalty springs, point loads and the
    contacts: vertex-face and edge-edge sub-contacts within the contact
    distance, each with a normal penalty spring when closed, a shear spring
    when locked and Coulomb friction when sliding (Eq. 7-9). The open-close
    iteration repeats the solve until no contact changes state; if that takes
    more than ``maxOpenCloseIterations`` solves, the step is redone with
    ``dt x openCloseShrink``. Then each block moves by an exact rotation about
    its centroid followed by the strain, ``v1 = 2 D / dt - v0``, and the
    stress gains ``E * strain``. A step whose largest vertex displacement
    exceeds the allowed one is redone with a smaller dt. ``O.dt`` and
    ``O.time`` follow the step actually taken.

    Parameters (SI units):

    - ``dt`` [s]: largest time step, > 0.
    - ``gravity`` [m/s^2]: body acceleration.
    - ``velocityRatio`` [-]: Shi's dynamic coefficient in [0, 1]; 1 is fully
      dynamic, 0 static analysis (velocities reset every step).
    - ``newmarkBeta``, ``newmarkGamma`` [-]: the member of Newmark's family
      (``D = v0 dt + dt^2 ((1/2 - beta) a0 + beta a1)``, ``v1 = v0 + dt ((1 -
      gamma) a0 + gamma a1)``). Default 1/2 and 1: Shi's scheme, which damps
      high frequencies (a bounce loses energy, contacts stop ringing within a
      step or two). 1/4 and 1/2: average acceleration, second order, keeps
      the energy of an elastic bounce (contacts take the secant force whose
      work is exactly minus their spring energy's change). Accepted: 1/2 <=
      gamma <= 1 and beta = gamma/2 (positions by the trapezoidal rule:
      every such member dissipates 2 gamma - 1 times the Bregman divergence
      of the elastic and contact energies, so none creates energy; checked
      when the engine steps).
    - ``startFromRest`` (True): before the first step, blocks at rest that
      touch (through contacts) a fixed block or a fixed point are brought to
      static equilibrium under gravity, loads and stresses, every touching
      contact held by its springs with friction locked; the dynamics starts
      from there, contacts loaded, velocities zero (``stats()['settleSteps']``,
      ``'settledBlocks'``, ``'settleConverged'``; a scene without such an
      equilibrium, e.g. a block on a frictionless slope, starts as placed).
      False: start as placed, contacts unloaded.
    - ``maxDisplacement`` [m]: largest vertex displacement per step; 0 means
      ``maxDisplacementRatio`` x half the largest extent of the scene.
    - ``maxDisplacementRatio`` [-]: Shi's g2, default 0.01.
    - ``timeStepGrowth`` [-]: after an accepted step the next one tries dt x this.
    - ``maxStepCuts``: redos allowed per step before a step is accepted anyway
      (counted in ``stats()['displacementLimitMisses']``).
    - ``fixedPointPenaltyFactor`` [-]: default fixed-point stiffness is this x E x
      block size (cube root of the volume).
    - ``threads``: worker threads for the core, 0 = all; results do not depend on it.
    - ``contactDistance`` [m]: d0, within which features become contacts; 0
      (default) = 2.5 x the allowed step displacement (Shi's rule).
    - ``contactPenaltyFactor`` [-]: normal contact stiffness [N/m] is this x
      the smaller E x size of the two blocks (default 40; Shi: 40-100 x E).
    - ``shearStiffnessRatio`` [-]: shear / normal contact stiffness (0.4).
    - ``maxOpenCloseIterations``: solves per step before dt is cut (40;
      the iteration makes passes with fixed friction limits, see README).
    - ``openCloseShrink`` [-]: dt factor for a step whose iteration did not
      converge (0.3).
    - ``collider``: the broad phase, ``'MSC'`` (multi-shell cover, with its
      default cover; use ``MSCCollider`` to set lambda and N), ``'DESS'`` (one
      sorted box per block, default), ``'NBS'`` (one bounding sphere per
      block, binned in cells) or
      ``'AllPairs'`` (every pair: the reference, O(n^2)). All give the same
      contacts; only the time differs. A collider engine before the
      integrator (``DESSCollider``, ``NBSCollider``, ...) overrides it.
    - ``reuseCandidatePairs``: diagnostic; True (default) lets the DESS
      and MSC broad phases reuse their candidate (MSC: shell) pairs while no
      block has moved past its allowance (d0 per box side), False searches
      every step. The
      contacts are the same either way (``stats()['broadPhaseSkipped']``
      counts the skipped searches); False exists to measure what the cache
      saves.
    - ``syncPeriod``: write the DDA state into YADE's bodies every n steps; 0
      (default) = when something may read it: the last step of ``O.run(n)``,
      ``O.step()``, a step after which another periodic engine (a PyRunner
      recorder, VTK export, ...) is due, or an open GUI view.

    Example::

        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
        O.run(1000, True)
    """

    dt = _Parameter(1e-3, lambda v: _finite('dt', v, 0, lowOpen=True, unit=' s'), 'largest time step [s]')
    gravity = _Parameter((0.0, 0.0, 0.0), _vector3('gravity'), 'body acceleration [m/s^2]')
    velocityRatio = _Parameter(1.0, lambda v: _finite('velocityRatio', v, 0, 1), "Shi's dynamic coefficient [-]")
    newmarkBeta = _Parameter(0.5, lambda v: _finite('newmarkBeta', v, 0.25, 0.5),
                             "Newmark's beta [-]: 1/2 with gamma 1 is Shi's scheme, 1/4 with gamma 1/2 average acceleration")
    newmarkGamma = _Parameter(1.0, lambda v: _finite('newmarkGamma', v, 0.5, 1), "Newmark's gamma [-]")
    startFromRest = _Parameter(True, lambda v: bool(v),
                               'bring touching blocks at rest to static equilibrium before the first step')
    maxDisplacement = _Parameter(0.0, lambda v: _finite('maxDisplacement', v, 0, unit=' m'),
                                 'largest vertex displacement per step [m]; 0 = use maxDisplacementRatio')
    maxDisplacementRatio = _Parameter(0.01, lambda v: _finite('maxDisplacementRatio', v, 0, 1, lowOpen=True),
                                      'allowed displacement / half scene size [-]')
    timeStepGrowth = _Parameter(1.3, lambda v: _finite('timeStepGrowth', v, 1), 'dt growth after a step [-]')
    maxStepCuts = _Parameter(30, _integer('maxStepCuts', 0), 'redos allowed per step')
    fixedPointPenaltyFactor = _Parameter(1000.0, lambda v: _finite('fixedPointPenaltyFactor', v, 0, lowOpen=True),
                                         'default fixed-point stiffness / (E x block size) [-]')
    threads = _Parameter(0, _integer('threads', 0), 'core threads, 0 = all')
    syncPeriod = _Parameter(0, _integer('syncPeriod', 0), 'steps between syncs, 0 = automatic')
    contactDistance = _Parameter(0.0, lambda v: _finite('contactDistance', v, 0, unit=' m'),
                                 'contact distance d0 [m]; 0 = 2.5 x allowed step displacement')
    contactPenaltyFactor = _Parameter(40.0, lambda v: _finite('contactPenaltyFactor', v, 0, lowOpen=True),
                                      'contact normal stiffness / min(E x block size) [-]')
    shearStiffnessRatio = _Parameter(0.4, lambda v: _finite('shearStiffnessRatio', v, 0),
                                     'contact shear / normal stiffness [-]')
    maxOpenCloseIterations = _Parameter(40, _integer('maxOpenCloseIterations', 1),
                                        'open-close iterations before dt is cut')
    openCloseShrink = _Parameter(0.3, lambda v: _finite('openCloseShrink', v, 0, 0.99, lowOpen=True),
                                 'dt factor when the open-close iteration does not converge [-]')
    collider = _Parameter('DESS', lambda v: _colliderName(v),
                          "broad phase: 'MSC' (multi-shell cover), 'DESS' (sorted boxes, default), 'NBS' (binned spheres) or "
                          "'AllPairs' (every pair, the oracle)")
    reuseCandidatePairs = _Parameter(True, lambda v: bool(v),
                                     'diagnostic: reuse broad-phase candidate pairs while blocks rest (same contacts)')

    _names = ('dt', 'gravity', 'velocityRatio', 'newmarkBeta', 'newmarkGamma', 'startFromRest', 'maxDisplacement', 'maxDisplacementRatio', 'timeStepGrowth',
              'maxStepCuts', 'fixedPointPenaltyFactor', 'threads', 'syncPeriod', 'contactDistance',
              'contactPenaltyFactor', 'shearStiffnessRatio', 'maxOpenCloseIterations', 'openCloseShrink',
              'collider',
              'reuseCandidatePairs')

    def __init__(self, label='', **params):
        wrapper.PyRunner.__init__(self)
        _initEngine(self, label, params)

    @classmethod
    def _defaults(cls):
        return {name: cls.__dict__[name].default for name in cls._names}

    def _updateCommand(self):
        # Parameters that differ from the defaults travel as one string literal,
        # parsed once per distinct string (see _parse) and cached.
        defaults = self._defaults()
        changed = {k: v for k, v in self._params.items() if v != defaults[k]}
        self.command = 'import yade_dda.engines as _dda; _dda.integratorStep(%r)' % (repr(changed),)


_paramsCache = {}


def _parse(text):
    """(params dict, IntegratorSettings) for an engine's parameter string, cached."""
    cached = _paramsCache.get(text)
    if cached is None:
        params = DDAIntegrator._defaults()
        params.update(ast.literal_eval(text))
        cached = _paramsCache[text] = (params, _settings(params))
    return cached


def _settings(params):
    settings = _core.IntegratorSettings()
    settings.maxTimeStep = params['dt']
    settings.gravity = params['gravity']
    settings.velocityRatio = params['velocityRatio']
    settings.newmarkBeta = params['newmarkBeta']
    settings.startFromRest = params['startFromRest']
    settings.newmarkGamma = params['newmarkGamma']
    settings.maxDisplacement = params['maxDisplacement']
    settings.maxDisplacementRatio = params['maxDisplacementRatio']
    settings.timeStepGrowth = params['timeStepGrowth']
    settings.maxStepCuts = params['maxStepCuts']
    settings.fixedPointPenaltyFactor = params['fixedPointPenaltyFactor']
    settings.threads = params['threads']
    settings.contactDistance = params['contactDistance']
    settings.contactPenaltyFactor = params['contactPenaltyFactor']
    settings.shearStiffnessRatio = params['shearStiffnessRatio']
    settings.maxOpenCloseIterations = params['maxOpenCloseIterations']
    settings.openCloseShrink = params['openCloseShrink']
    settings.reuseCandidatePairs = params['reuseCandidatePairs']
    return settings


def _readerDue(engine):
    """True when a periodic engine other than ours may run before our next step."""
    if engine.dead:
        return False
    if engine.iterPeriod > 0 and O.iter + 1 - engine.iterLast >= engine.iterPeriod:
        return True
    if engine.virtPeriod > 0 and O.time + O.dt - engine.virtLast >= engine.virtPeriod:
        return True
    if engine.realPeriod > 0 and time.time() - engine.realLast >= 0.9 * engine.realPeriod:
        return True
    return False


def _guiOpen():
    qt = sys.modules.get('yade.qt')
    return qt is not None and len(qt.views()) > 0


def _syncNeeded(params, engines):
    period = params['syncPeriod']
    if period > 0:
        return (O.iter + 1) % period == 0 or O.iter + 1 == O.stopAtIter
    if not O.running or O.iter + 1 >= O.stopAtIter > 0:
        return True
    for engine in engines:
        if isinstance(engine, wrapper.PeriodicEngine) and not _isOwnCommand(engine) and _readerDue(engine):
            return True
    return _guiOpen()


def _isOwnCommand(engine):
    return isinstance(engine, wrapper.PyRunner) and engine.command.startswith('import yade_dda.')


def _checkEngines(scene, engines):
    """Refuses engine lists that would move DDA blocks twice, or make YADE contacts with them."""
    _guards.checkSingleIntegrator(engines)
    from .colliders import _checkOrder   # (colliders imports this module)
    _checkOrder()   # here too: a collider engine after us would run only after our step
    _guards.checkYadeContacts(scene, engines)
    for engine in engines:
        if isinstance(engine, wrapper.NewtonIntegrator):
            for bodyId in scene.bodyOfBlock:
                body = O.bodies[bodyId]
                if body is not None and body.dynamic and (engine.mask & body.groupMask):
                    raise RuntimeError(
                        'NewtonIntegrator would also move DDA block body %d (its groupMask %d overlaps '
                        'NewtonIntegrator.mask %d). Give DDA blocks their own mask bit, e.g. '
                        'ddaBlock(..., mask=2) and NewtonIntegrator(mask=1), so YADE moves only its own bodies.'
                        % (bodyId, body.groupMask, engine.mask))


def integratorStep(text):
    """One DDA step; called by DDAIntegrator's command every iteration with its parameters."""
    start = time.perf_counter()
    params, settings = _parse(text)
    scene = _scene.current()
    before = len(scene.bodyOfBlock)
    _guards.checkInitialOverlaps(scene, settings)   # before the new blocks enter the core
    scene.resolvePending()
    _guards.markOverlapsChecked(scene)
    engines = O.engines
    signature = tuple((type(e).__name__, e.mask) if isinstance(e, wrapper.NewtonIntegrator) else type(e).__name__
                      for e in engines) + (len(O.bodies),)
    if len(scene.bodyOfBlock) != before or scene.checkedEngines != signature:
        _checkEngines(scene, engines)
        scene.checkedEngines = signature
    choice = getattr(scene, 'colliderChoice', None)   # (iteration, name, parameters) from a collider engine
    fromEngine = choice is not None and choice[0] == O.iter
    collider = choice[1] if fromEngine else params['collider']
    cover = (choice[2].get('criticalLength', 0.0), choice[2].get('segments', 3)) if fromEngine else (0.0, 3)
    if scene.core.collider() != collider:
        scene.core.setCollider(collider)
        scene.cover = None
    if collider == 'MSC' and getattr(scene, 'cover', None) != cover:
        scene.core.setCover(float(cover[0]), int(cover[1]))
        scene.cover = cover
    O.dt = scene.core.step(settings)
    if _syncNeeded(params, engines):
        scene.sync()
    scene.stepTimeTotal += time.perf_counter() - start
