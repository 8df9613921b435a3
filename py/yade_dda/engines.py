"""YADE engines of yade-dda.

YADE runs Python from engines only through ``PyRunner``; each engine here is a
``PyRunner`` subclass whose command calls the compiled core once per step.
The command string carries every parameter, so an engine that comes back from
``O.save()``/``O.load()`` as a plain PyRunner still knows its settings.
"""
import ast
import math
import sys
import textwrap
import time

from ._yade import O, wrapper
from . import _core
from . import guards as _guards
from . import scene as _scene
from .blocks import _vector


def _finite(name, value, low=None, high=None, lowOpen=False, unit='', highOpen=False, bounds=None):
    """float(value) if it is finite and in the range from low to high (None: unbounded;
    lowOpen, highOpen: that end excluded); else TypeError or ValueError naming the
    parameter, the range (bounds: its text, by default made from the ends) and the value."""
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
        ok = value < high if highOpen else value <= high
    if not ok:
        if bounds is None:
            bounds = '%s%s, %s' % ('(' if lowOpen else '[', low, '%s%s' % (high, ')' if highOpen else ']')
                                   if high is not None else 'inf)')
        raise ValueError('%s must be finite and in %s, got %r%s' % (name, bounds, value, unit))
    return value


class _Parameter:
    """A typed engine parameter: default, unit, validation; stored in the command."""

    def __init__(self, default, check, doc):
        self.default, self.check, self.__doc__ = default, check, doc

    def __set_name__(self, owner, name):
        self.name = name

    @classmethod
    def fromRow(cls, row):
        """The parameter of a row of _core.settingsTable() (pkg/dda/solver/Settings.def)."""
        parameter = cls(row['default'], _check(row), row['doc'])
        parameter.name = row['name']
        return parameter

    def __get__(self, engine, owner=None):
        if engine is None:
            return self
        return engine._params[self.name]

    def __set__(self, engine, value):
        engine._params[self.name] = self.check(value)
        engine._updateCommand()


_COLLIDERS = tuple(_core.colliderNames())   # the core's broad phases (pkg/dda/collider/ColliderFactory.cpp)


_INT_MAX = 2 ** 31 - 1   # the core's counters are C ints


def _integer(name, low, high=_INT_MAX, bounds=None):
    """Validator of an integer parameter in [low, high]; rejects 1.5, '3', True."""
    def check(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
            raise TypeError('%s must be an integer, got %r' % (name, value))
        if not low <= value <= high:
            raise ValueError('%s must be an integer in %s, got %r' % (name, bounds or '[%d, %d]' % (low, high), value))
        return int(value)
    return check


def _choice(name, choices):
    def check(value):
        if value not in choices:
            raise ValueError('%s must be one of %s, got %r' % (name, ', '.join(choices), value))
        return value
    return check


def _check(row):
    """The validator of a row of _core.settingsTable(), by its kind; the range and its
    text come from the row."""
    name, kind = row['name'], row['kind']
    if kind == 'real':
        unit = '' if row['unit'] in ('', '-') else ' ' + row['unit']
        return lambda value: _finite(name, value, row['low'], row['high'], row['lowOpen'], unit, row['highOpen'],
                                     row['range'])
    if kind == 'integer':
        return _integer(name, max(row['low'], -_INT_MAX - 1), min(row['high'], _INT_MAX), row['range'])
    if kind == 'boolean':
        return bool
    if kind == 'vector':
        return _vector3(name)
    if kind == 'choice':
        return _choice(name, row['choices'])
    raise TypeError('setting %s has an unknown kind %r' % (name, kind))


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


_SETTINGS = _core.settingsTable()
"""Every DDAIntegrator parameter, from the core's one declaration of the settings
(pkg/dda/solver/Settings.def): dicts with name, member (the IntegratorSettings
attribute, None for the engine's own), kind, default, range (and low, high,
lowOpen, highOpen or choices), unit, doc."""


RULES = '``newmarkBeta = newmarkGamma / 2``, ``minTimeStepShrink <= maxTimeStepShrink``'
"""The rules between settings that validateSettings (pkg/dda/solver/Settings.cpp) checks at each step."""


def parameterLine(row):
    """'``dt`` [s], default 0.001, in (0, inf): largest time step; ...' for docstrings."""
    unit = ' [%s]' % row['unit'] if row['unit'] else ''
    where = ''
    if row['kind'] in ('real', 'integer'):
        where = ', in %s' % row['range']
    elif row['kind'] == 'choice':
        where = ', %s' % row['range']
    return '``%s``%s, default %r%s: %s' % (row['name'], unit, row['default'], where, row['doc'])


_INTEGRATOR_DOC = """Shi's implicit DDA time integration of all DDA blocks, with their contacts
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

    Parameters (SI units; generated from pkg/dda/solver/Settings.def, as is
    doc/parameters.md). Each is checked against its range when set; the rules
    between them (%s) when the engine steps.

%s

    Example::

        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
        O.run(1000, True)
    """ % (RULES, '\n'.join(textwrap.fill(parameterLine(row), 79, initial_indent='    - ', subsequent_indent='      ')
                               for row in _SETTINGS))


class DDAIntegrator(wrapper.PyRunner):
    __doc__ = _INTEGRATOR_DOC
    _names = tuple(row['name'] for row in _SETTINGS)

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


for _row in _SETTINGS:
    setattr(DDAIntegrator, _row['name'], _Parameter.fromRow(_row))


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
    for row in _SETTINGS:
        if row['member'] is not None:
            setattr(settings, row['member'], params[row['name']])
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
