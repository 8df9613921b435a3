"""yade_dda's engines back with their own classes after ``O.load``.

YADE saves a Python subclass of ``PyRunner`` as a plain ``PyRunner``: its
class is not serialized, its command is. Every yade_dda engine keeps all its
parameters in its command, so the engine a loaded scene brings back can be
made again from it: ``typedEngines`` replaces each plain ``PyRunner`` whose
command is one of ours by an engine of its class with those parameters, its
label and its YADE bookkeeping (``dead``, the last run's iteration, times and
count). ``O.engines[0].gravity`` then reads and sets the loaded integrator's
gravity as before the save; a command that is not ours is left alone.
"""
import ast

from ._yade import O, wrapper
from . import colliders, engines, recorder, saveload

_BOOKKEEPING = ('dead', 'iterLast', 'virtLast', 'realLast', 'nDone')
"""YADE's PeriodicEngine attributes carried from the loaded engine to the rebuilt one."""


def _call(command):
    """(function name, positional literals, keyword literals) of the last statement of `command` when it
    is a call of literals, else None."""
    try:
        body = ast.parse(command).body
    except SyntaxError:
        return None
    if not body or not isinstance(body[-1], ast.Expr) or not isinstance(body[-1].value, ast.Call):
        return None
    call = body[-1].value
    name = call.func.attr if isinstance(call.func, ast.Attribute) else getattr(call.func, 'id', None)
    try:
        args = [ast.literal_eval(a) for a in call.args]
        kwargs = {k.arg: ast.literal_eval(k.value) for k in call.keywords}
    except ValueError:
        return None
    return name, args, kwargs


def _typed(engine):
    """The yade_dda engine that a plain PyRunner with `engine`'s command stands for, or None."""
    command = engine.command
    call = _call(command)
    if call is None:
        return None
    name, args, kwargs = call
    try:
        typed = _build(engine, command, name, args, kwargs)
    except (ImportError, TypeError, ValueError):   # e.g. no VTK here: the plain PyRunner still runs the command
        return None
    if typed is None or typed.command != command:   # not a command our classes write: left as YADE loaded it
        return None
    for attribute in _BOOKKEEPING:
        typed._setYade(attribute, getattr(engine, attribute))
    if engine.label:
        typed._setYade('label', engine.label)
    return typed


def _build(engine, command, name, args, kwargs):
    """A new engine of the class whose command `command` is (its call parsed: `name`, `args`, `kwargs`)."""
    if command.startswith('import yade_dda.engines ') and name == 'integratorStep' and len(args) == 1:
        return engines.DDAIntegrator(**ast.literal_eval(args[0]))
    if command.startswith(colliders.COLLIDER_COMMAND) and name == '_select' and len(args) == 1:
        cls = colliders.ENGINES.get(args[0])
        return cls(**kwargs) if cls is not None else None
    if command.startswith('import yade_dda.recorder ') and name == 'record' and len(args) == 1:
        return recorder.DDAVTKRecorder(fileName=args[0], iterPeriod=engine.iterPeriod,
                                       virtPeriod=engine.virtPeriod, realPeriod=engine.realPeriod)
    if command.startswith('import yade_dda.saveload ') and name == 'writeCheckpoint' and len(args) == 4:
        directory, stem, keep, form = args
        typed = saveload.Checkpoint(period=engine.iterPeriod, directory=directory, name=stem, keep=keep,
                                    format=form)
        for period in ('virtPeriod', 'realPeriod'):   # YADE's own periods a checkpoint may also have
            typed._setYade(period, getattr(engine, period))
        return typed
    return None


def typedEngines():
    """Replaces, in ``O.engines``, every plain PyRunner that runs a yade_dda engine's command by that engine
    (run by the wrapped ``O.load``, ``loadTmp`` and ``reload``: saveload.onLoad). Returns how many were
    replaced."""
    current = list(O.engines)
    replaced = 0
    for k, engine in enumerate(current):
        if type(engine) is wrapper.PyRunner:
            typed = _typed(engine)
            if typed is not None:
                current[k] = typed
                replaced += 1
    if replaced:
        O.engines = current   # YADE maps the labels to the new engines
    return replaced
