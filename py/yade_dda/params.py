"""Engine parameters and their validation: the leaf of the yade_dda package.

Every engine (``DDAIntegrator``, the collider engines, ``Checkpoint``) keeps
its settings as typed ``Parameter`` descriptors, checked when set and stored
in the engine's command string. This module holds what they share: the
validators (``finite``, ``integer``, ``choice``, ``vector``), ``Parameter``,
``initEngine``, and the core's tables (``SETTINGS``: every ``DDAIntegrator``
parameter from pkg/dda/solver/Settings.def; ``COLLIDERS``: the broad phases of
this build). It imports only the compiled core, so every other module of the
package may import it (doc/DESIGN.md, "The Python package").
"""
import difflib
import math
import numbers
import os

from . import _core


def finite(name, value, low=None, high=None, lowOpen=False, unit='', highOpen=False, bounds=None):
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


def isPoint(p):
    """True for a sequence of 3 real numbers (bool excluded): a point [m], as opposed to a list of points."""
    try:
        return len(p) == 3 and all(isinstance(x, numbers.Real) and not isinstance(x, bool) for x in p)
    except TypeError:
        return False


def vector(value, what, length=3):
    """tuple of `length` finite floats; TypeError or ValueError naming `what` and the bad component."""
    try:
        values = [float(x) for x in value]
    except (TypeError, ValueError):
        raise TypeError('%s must be a sequence of %d numbers, got %r' % (what, length, value)) from None
    if len(values) != length:
        raise ValueError('%s must have %d components, got %d' % (what, length, len(values)))
    for i, x in enumerate(values):
        if not math.isfinite(x):
            raise ValueError('%s has a non-finite component %d: %r' % (what, i, x))
    return tuple(values)


INT_MAX = 2 ** 31 - 1   # the core's counters are C ints


def integer(name, low, high=INT_MAX, bounds=None):
    """Validator of an integer parameter in [low, high]; rejects 1.5, '3', True."""
    def check(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or value != int(value):
            raise TypeError('%s must be an integer, got %r' % (name, value))
        if not low <= value <= high:
            raise ValueError('%s must be an integer in %s, got %r' % (name, bounds or '[%d, %d]' % (low, high), value))
        return int(value)
    return check


def choice(name, choices):
    """Validator of a parameter that takes one of `choices`."""
    def check(value):
        if value not in choices:
            raise ValueError('%s must be one of %s, got %r' % (name, ', '.join(choices), value))
        return value
    return check


PROCESSORS = os.cpu_count() or 1
"""Processors of this machine: the most worker threads a step may ask for."""


def _threads(check):
    def checkThreads(value):
        value = check(value)
        if value > PROCESSORS:
            raise ValueError('threads must be at most the %d processors of this machine (0 = all), got %d'
                             % (PROCESSORS, value))
        return value
    return checkThreads


def checkOf(row):
    """The validator of a row of _core.settingsTable(), by its kind; the range and its
    text come from the row (``threads`` is also bounded by this machine's processors)."""
    check = _checkOfKind(row)
    return _threads(check) if row['name'] == 'threads' else check


def _checkOfKind(row):
    name, kind = row['name'], row['kind']
    if kind == 'real':
        unit = '' if row['unit'] in ('', '-') else ' ' + row['unit']
        return lambda value: finite(name, value, row['low'], row['high'], row['lowOpen'], unit, row['highOpen'],
                                    row['range'])
    if kind == 'integer':
        return integer(name, max(row['low'], -INT_MAX - 1), min(row['high'], INT_MAX), row['range'])
    if kind == 'boolean':
        return bool
    if kind == 'vector':
        return lambda value: vector(value, name)
    if kind == 'choice':
        return choice(name, row['choices'])
    raise TypeError('setting %s has an unknown kind %r' % (name, kind))


class Parameter:
    """A typed engine parameter: default, unit, validation; stored in the command."""

    def __init__(self, default, check, doc):
        self.default, self.check, self.__doc__ = default, check, doc

    def __set_name__(self, owner, name):
        self.name = name

    @classmethod
    def fromRow(cls, row):
        """The parameter of a row of _core.settingsTable() (pkg/dda/solver/Settings.def)."""
        parameter = cls(row['default'], checkOf(row), row['doc'])
        parameter.name = row['name']
        return parameter

    def __get__(self, engine, owner=None):
        if engine is None:
            return self
        return engine._params[self.name]

    def __set__(self, engine, value):
        engine._params[self.name] = self.check(value)
        engine._updateCommand()


_PERIODS = ('iterPeriod', 'virtPeriod', 'realPeriod', 'nDo')


class Engine:
    """What every yade_dda engine (a ``PyRunner`` subclass) adds to YADE's
    attributes: assigning a name that is neither one of its parameters nor an
    attribute of YADE's engine raises AttributeError with the nearest names
    (``dda.gravty = ...`` is a typo, not a new attribute), and its periods are
    checked by ``_checkPeriod``.

    By default an engine must run at every iteration (iterPeriod 1, no
    virtPeriod, realPeriod or nDo): the integrator advances the blocks by the
    step it takes, while YADE advances ``O.time`` by ``O.dt`` at every
    iteration whether the engine ran or not, so ``iterPeriod = 2`` would let
    ``O.time`` run ahead of the blocks; a collider engine's choice holds for
    the iteration it ran in only."""

    def __setattr__(self, name, value):
        cls = type(self)
        if not name.startswith('_') and name not in cls._names:
            if not hasattr(cls, name):
                known = sorted(set(cls._names) | {n for n in dir(cls) if not n.startswith('_')})
                near = difflib.get_close_matches(name, known, 3)
                raise AttributeError('%s has no parameter or attribute %r%s (its parameters: %s)' % (
                    cls.__name__, name, '; did you mean %s?' % ' or '.join(map(repr, near)) if near else '',
                    ', '.join(cls._names) or 'none but label'))
            if name in _PERIODS:
                self._checkPeriod(name, value)
        super().__setattr__(name, value)

    _periodAdvice = ''
    """What to use instead of a period, appended to the refusal (an engine class's own)."""

    def _checkPeriod(self, name, value):
        if value != {'iterPeriod': 1, 'nDo': -1}.get(name, 0):
            raise ValueError(
                '%s runs at every iteration: %s = %r would let O.time advance by O.dt at iterations where it '
                'does not run (iterPeriod is fixed at 1, virtPeriod and realPeriod at 0, nDo at -1); set dead = '
                'True to stop it%s' % (type(self).__name__, name, value, self._periodAdvice))

    def _setYade(self, name, value):
        """Sets YADE's engine attribute `name` without the checks (the engine's own bookkeeping)."""
        super().__setattr__(name, value)


def keywordsOnly(cls, args):
    """Refuses positional arguments to engine class `cls` with a TypeError naming the keyword to write.
    YADE's engines take keyword arguments only (PyRunner's positional ones are iterPeriod and command, which
    ours set themselves), so ``DDAIntegrator(1e-3)`` is refused rather than read as dt or as the label."""
    if not args:
        return
    first, names = args[0], cls._names
    if isinstance(first, str) and not (names and isinstance(getattr(cls, names[0]).default, str)):
        hint = '; write %s(label=%r, ...)' % (cls.__name__, first)
    elif names:
        hint = '; write %s(%s=%r, ...)' % (cls.__name__, names[0], first)
    else:
        hint = ''
    raise TypeError("%s takes keyword arguments only, as YADE's engines do: got the positional argument%s %s%s "
                    "(its parameters: %s)" % (cls.__name__, 's' if len(args) > 1 else '', ', '.join(map(repr, args)),
                                              hint, ', '.join(names) or 'none but label'))


def initEngine(engine, label, params):
    """Checks and stores an engine's typed parameters (its class's ``_names``,
    each a Parameter), runs it every step from the first, sets the label and
    writes the command. Unknown names raise TypeError naming them; YADE's
    periods (iterPeriod, virtPeriod, realPeriod, nDo) are checked by the
    engine's ``_checkPeriod``, as when assigned, and set."""
    names = type(engine)._names
    periods = {name: params.pop(name) for name in _PERIODS if name in params}
    unknown = set(params) - set(names)
    if unknown:
        near = sorted({m for name in unknown for m in difflib.get_close_matches(name, names, 2)})
        raise TypeError('%s has no parameter %s%s%s' % (
            type(engine).__name__, ', '.join(sorted(unknown)),
            ' (did you mean %s?)' % ', '.join(near) if near else '',
            ' (parameters: %s)' % ', '.join(names) if names else ' (it takes none but label)'))
    engine._params = {}
    for name in names:
        descriptor = type(engine).__dict__[name]
        engine._params[name] = descriptor.check(params.get(name, descriptor.default))
    for name, value in periods.items():
        engine._checkPeriod(name, value)
    if not isinstance(label, str):
        raise TypeError('label must be a string, got %r' % (label,))
    engine._setYade('iterPeriod', 1)
    engine._setYade('initRun', True)
    if label:
        engine.label = label
    engine._updateCommand()
    for name, value in periods.items():
        setattr(engine, name, value)


COLLIDERS = tuple(_core.colliderNames())
"""The core's broad phases in this build (pkg/dda/collider/ColliderFactory.cpp)."""


SETTINGS = _core.settingsTable()
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
