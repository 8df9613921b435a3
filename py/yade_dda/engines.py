"""YADE engines of yade-dda.

YADE runs Python from engines only through ``PyRunner``; each engine here is a
``PyRunner`` subclass whose command calls the compiled core once per step.
The command string carries every parameter, so an engine that comes back from
``O.save()``/``O.load()`` (YADE saves it as a plain PyRunner) is made again from it
(typedengines.py).
"""
import ast
import sys
import textwrap
import time

from ._yade import O, wrapper
from . import _core
from . import guards as _guards
from . import scene as _scene
from .hooks import USER_DT_TAG, writeDt
from .state import tag
from .params import Engine, Parameter, RULES, SETTINGS, initEngine, keywordsOnly, parameterLine


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

    Keyword arguments only, as every YADE engine takes them: ``DDAIntegrator(1e-3)`` is a TypeError
    that says to write ``DDAIntegrator(dt=0.001, ...)``. A positional dt is not accepted because no YADE
    engine reads one, and the positional arguments of ``PyRunner``, whose subclass this is, are
    ``iterPeriod`` and ``command``: a script written as for a PyRunner must not be read as a time step.

    It runs at every iteration: ``iterPeriod`` is fixed at 1 (``virtPeriod`` and ``realPeriod`` at 0,
    ``nDo`` at -1), given here or assigned later, because YADE advances ``O.time`` by ``O.dt`` at every
    iteration whether the engine ran or not. For longer steps raise ``dt``; to write YADE's bodies less
    often set ``syncPeriod``; for work every n iterations add a ``PyRunner(iterPeriod=n, command=...)``;
    ``dead = True`` stops it.
    """ % (RULES, '\n'.join(textwrap.fill(parameterLine(row), 79, initial_indent='    - ', subsequent_indent='      ')
                               for row in SETTINGS))


class DDAIntegrator(Engine, wrapper.PyRunner):
    __doc__ = _INTEGRATOR_DOC
    _names = tuple(row['name'] for row in SETTINGS)
    _periodAdvice = ('; it takes one DDA step per iteration: for longer steps raise dt, to write the YADE bodies '
                     'less often set syncPeriod=n, for work every n iterations add a PyRunner(iterPeriod=n, '
                     'command=...)')

    def __init__(self, *args, label='', **params):
        keywordsOnly(type(self), args)
        wrapper.PyRunner.__init__(self)
        initEngine(self, label, params)

    @classmethod
    def _defaults(cls):
        return {name: cls.__dict__[name].default for name in cls._names}

    def _updateCommand(self):
        self._setYade('command', _command(self._params))


_COMMAND = 'import yade_dda.engines as _dda; _dda.integratorStep(%r)'


def _text(params):
    """The parameters that differ from the defaults, as the text integratorStep receives: one string
    literal in the command, parsed once per distinct string (see _parse) and cached."""
    defaults = DDAIntegrator._defaults()
    return repr({k: v for k, v in params.items() if v != defaults[k]})


def _command(params):
    """DDAIntegrator's command for its parameters."""
    return _COMMAND % (_text(params),)


for _row in SETTINGS:
    setattr(DDAIntegrator, _row['name'], Parameter.fromRow(_row))


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
    for row in SETTINGS:
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
    _guards.checkColliderOrder(engines)   # here too: a collider engine after us would run only after our step
    _guards.checkYadeContacts(scene, engines)
    _guards.checkNewtonMask(scene, engines)


def _takeUserDt(text):
    """The parameter text with ``dt`` set to the time step the script assigned to O.dt
    (hooks.USER_DT_TAG), written into the engine that runs `text`; the tag is cleared."""
    value = float(tag(USER_DT_TAG))
    O.tags[USER_DT_TAG] = ''
    params = dict(_parse(text)[0], dt=value)
    for engine in O.engines:
        if isinstance(engine, wrapper.PyRunner) and engine.command == _COMMAND % (text,):
            if isinstance(engine, DDAIntegrator):
                engine.dt = value
            else:   # an engine back from O.load is a plain PyRunner with our command
                engine.command = _command(params)
            break
    return _text(params)


def integratorStep(text):
    """One DDA step; called by DDAIntegrator's command every iteration with its parameters.

    An exception is raised on to YADE with its traceback cut to this line
    (YADE prints it in its "PyRunner error" report, twice) and kept whole for
    the wrapped ``O.run``, ``O.step`` and ``O.wait``, which raise it again in
    place of YADE's RuntimeError (guards.raiseStepError)."""
    try:
        _step(text)
    except Exception as error:
        _guards.STEP_ERROR[:] = [error, error.__traceback__]
        raise error.with_traceback(None) from None


def _step(text):
    start = time.perf_counter()
    if tag(USER_DT_TAG):
        text = _takeUserDt(text)
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
    choice = scene.colliderChoice   # (iteration, name, parameters) from a collider engine
    fromEngine = choice is not None and choice[0] == O.iter
    collider = choice[1] if fromEngine else params['collider']
    cover = (choice[2].get('criticalLength', 0.0), choice[2].get('segments', 3)) if fromEngine else (0.0, 3)
    if scene.core.collider() != collider:
        scene.core.setCollider(collider)
        scene.cover = None
    if collider == 'MSC' and scene.cover != cover:
        scene.core.setCover(float(cover[0]), int(cover[1]))
        scene.cover = cover
    writeDt(scene.core.step(settings))
    scene.settings = settings   # what views.update reads (fixed-point stiffness, gravity)
    if _syncNeeded(params, engines):
        scene.sync()
    scene.stepTimeTotal += time.perf_counter() - start
    period = params['progressPeriod']
    if period != 0:
        _progress(scene, period if period > 0 else AUTO_PROGRESS_PERIOD if sys.stdout.isatty() else 0)


AUTO_PROGRESS_PERIOD = 30.0
"""Wall seconds between progress lines when ``progressPeriod`` < 0 and stdout is a terminal."""


def _progress(scene, period):
    """Prints one progress line every `period` wall seconds of a run (DDAIntegrator.progressPeriod):
    steps/s and simulated seconds per wall second since the last line, O.time, dt, closed contacts, and
    an ETA from O.stopAtIter (O.run(n)) or else O.stopAtTime."""
    if period <= 0:
        return
    now = time.perf_counter()
    last = scene.progressMark
    if last is None or O.iter < last[1]:
        scene.progressMark = (now, O.iter, O.time)
        return
    wall, iteration, simulated = last
    if now - wall < period:
        return
    scene.progressMark = (now, O.iter, O.time)
    stepsPerSecond = (O.iter - iteration) / (now - wall)
    timeRate = (O.time - simulated) / (now - wall)
    eta = ''
    if O.stopAtIter > O.iter and stepsPerSecond > 0:
        eta = ', ETA %s (O.stopAtIter %d)' % (_duration((O.stopAtIter - O.iter) / stepsPerSecond), O.stopAtIter)
    elif O.stopAtTime > O.time and timeRate > 0:
        eta = ', ETA %s (O.stopAtTime %g s)' % (_duration((O.stopAtTime - O.time) / timeRate), O.stopAtTime)
    counts = scene.core.lastStep()
    print('yade_dda: iter %d, %.1f steps/s, O.time %.6g s (%.3g s per wall s), dt %.3g s, %d closed contacts in '
          '%d pairs%s' % (O.iter, stepsPerSecond, O.time, timeRate, O.dt, counts['closedContacts'],
                          counts['contactPairs'], eta), flush=True)


def _duration(seconds):
    """'2 h 05 min', '3 min 20 s' or '45 s'."""
    seconds = int(round(seconds))
    if seconds >= 3600:
        return '%d h %02d min' % (seconds // 3600, seconds % 3600 // 60)
    if seconds >= 60:
        return '%d min %02d s' % (seconds // 60, seconds % 60)
    return '%d s' % seconds
