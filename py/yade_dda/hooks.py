"""The one place where yade_dda changes YADE's own classes: ``installHooks``.

YADE knows nothing of the DDA core, which holds the true state of every DDA
block. Four of YADE's classes are wrapped so that what a script does to the
YADE scene reaches the core too; each wrapper calls YADE's original method
(kept as the wrapper's ``_yadeDDA`` attribute) and adds the DDA part.
"""
import os
import tempfile

from ._yade import O, wrapper
from . import guards as _guards
from . import saveload as _saveload
from . import scene as _scene
from .params import finite

_OMEGA_SAVES = ('save', 'saveTmp')
_OMEGA_LOADS = ('load', 'loadTmp', 'reload')
_OMEGA_RUNS = ('run', 'step', 'wait')


def _original(cls, name):
    """YADE's own method `name` of `cls`, under any wrapper installed before."""
    method = getattr(cls, name)
    return getattr(method, '_yadeDDA', method)


def _wrapping(function, original):
    """`function` (a wrapper of YADE's `original` method) with its doc, and `original` kept as its ``_yadeDDA``."""
    function.__doc__ = original.__doc__
    function._yadeDDA = original
    return function


# ------------------------------------------------------------------ BodyContainer

def _wrapErase(original):
    def erase(self, id, *args, **kw):
        scene = _scene.current(create=False)
        if scene is not None and isinstance(id, int):
            index = scene.core.blockOfBody(id)
            if index is not None:
                raise RuntimeError(
                    'body %d is DDA block %d of a running scene; the DDA core cannot remove blocks yet, so it was '
                    'not erased. Erase DDA blocks before the first step after their append, or rebuild the scene '
                    '(O.reset()).' % (id, index))
            scene.pending = [(body, spec) for body, spec in scene.pending if body.id != id]
        return original(self, id, *args, **kw)
    return _wrapping(erase, original)


def _wrapClear(original):
    def clear(self, *args, **kw):
        result = original(self, *args, **kw)
        _scene.freshScene()
        return result
    return _wrapping(clear, original)


def _wrapReplace(original):
    def replace(self, bodies, *args, **kw):
        bodies = list(bodies)
        # YADE's replace clears the container in C++ (not through clear) and appends bodies.
        result = original(self, bodies, *args, **kw)
        _scene.freshScene(bodies)
        return result
    return _wrapping(replace, original)


class _WrappedProperty(property):
    """A YADE property with a yade_dda setter; ``yadeOriginal`` is YADE's property."""
    yadeOriginal = None


def _yadeProperty(cls, name):
    current = cls.__dict__[name]
    return getattr(current, 'yadeOriginal', None) or current


def _wrapBodyObject(original):
    """Body.state and Body.shape: YADE's setter, then the scene's C++ writer, which keeps the State
    and Polyhedra objects of DDA bodies it wrote to, forgets them (pkg/py/YadeSync.hpp)."""
    def assign(self, value):
        original.fset(self, value)
        writer = _scene.writerOfCurrent()
        if writer is not None:
            writer.forgetBodies()
    wrapped = _WrappedProperty(original.fget, assign, None, original.__doc__)
    wrapped.yadeOriginal = original
    return wrapped


# ------------------------------------------------------------------ InteractionContainer

def _wrapInteractionErase(original):
    def erase(self, id1, id2, *args, **kw):
        result = original(self, id1, id2, *args, **kw)
        writer = _scene.writerOfCurrent()
        if writer is not None:
            writer.forgetInteraction(id1, id2)
        return result
    return _wrapping(erase, original)


def _wrapInteractionClear(original):
    def clear(self, *args, **kw):
        result = original(self, *args, **kw)
        writer = _scene.writerOfCurrent()
        if writer is not None:
            writer.forgetInteractions()
        return result
    return _wrapping(clear, original)


# ------------------------------------------------------------------ Omega

def _fileArgument(args, kwargs):
    """The file name given to O.save or O.load (their first argument, or `file`)."""
    return args[0] if args else kwargs.get('file')


def _checkSavePath(path):
    """Refuses, before YADE writes anything, a file name that YADE would silently not write."""
    if not isinstance(path, str) or not path:
        raise TypeError('O.save needs a file name, got %r' % (path,))
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise FileNotFoundError('O.save(%r): the directory %r does not exist; nothing was saved' % (path, directory))
    if os.path.isdir(path):
        raise IsADirectoryError('O.save(%r): is a directory; nothing was saved' % (path,))
    if not os.access(directory, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise PermissionError('O.save(%r): not writable; nothing was saved' % (path,))


def _wrapSave(original):
    toFile = original.__name__ == 'save'

    def save(self, *args, **kwargs):
        path = _fileArgument(args, kwargs) if toFile else None
        if toFile:
            _checkSavePath(path)
        stored = _saveload.storeState()
        try:
            result = original(self, *args, **kwargs)
        finally:
            if stored:
                O.tags[_saveload.STATE_TAG] = ''
        if toFile:
            if not os.path.isfile(path) or os.path.getsize(path) == 0:
                raise OSError('O.save(%r): YADE wrote nothing' % (path,))
        return result
    save.__doc__ = original.__doc__ + \
        '\n\n(yade_dda: also saves the DDA state, see yade_dda.saveload; a path that cannot be written raises.)'
    save._yadeDDA = original
    return save


def _checkLoadPath(path):
    if not isinstance(path, str) or not path:
        raise TypeError('O.load needs a file name, got %r%s' % (
            path, ' (yade_dda.latestCheckpoint(..., missingOk=True) found no checkpoint?)' if path is None else ''))
    if not os.path.isfile(path):
        raise FileNotFoundError('O.load(%r): no such file; the running scene is unchanged' % (path,))


def _wrapLoad(original):
    fromFile = original.__name__ == 'load'

    def load(self, *args, **kwargs):
        if fromFile:
            _checkLoadPath(_fileArgument(args, kwargs))
        before = _saveload.currentToken()
        # YADE empties the running scene when a load fails half-way: keep a copy to put back.
        keep = _keepScene(self)
        try:
            result = original(self, *args, **kwargs)
            _saveload.afterLoad(before)
        except Exception as error:
            if keep is None:
                raise
            _restoreScene(self, keep)
            try:
                annotated = type(error)('%s; the running scene was put back as it was' % (error,))
            except Exception:   # an exception type that takes other arguments: raise it as it is
                raise error from None
            raise annotated from error
        finally:
            if keep is not None:
                os.remove(keep)
        return result
    load.__doc__ = original.__doc__ + \
        '\n\n(yade_dda: also restores the DDA state, see yade_dda.saveload; a load that fails leaves the running ' \
        'scene as it was.)'
    load._yadeDDA = original
    return load


def _keepScene(omega):
    """A temporary file holding the running scene (YADE and DDA state), or None when it has no bodies."""
    if len(omega.bodies) == 0:
        return None
    handle, path = tempfile.mkstemp(prefix='yade_dda-before-load-', suffix='.yade.gz')
    os.close(handle)
    try:
        omega.save(path, True)
    except BaseException:
        os.remove(path)
        raise
    return path


def _restoreScene(omega, path):
    """Puts back the scene _keepScene saved (the DDA state with it), as it was before the failed load."""
    before = _saveload.currentToken()
    _original(wrapper.Omega, 'load')(omega, path, True)
    _saveload.afterLoad(before)


def _wrapRun(original):
    """O.run, O.step and O.wait.

    - Before O.run and O.step: with a live NewtonIntegrator and no DDAIntegrator in O.engines (where no
      DDA step would check the engines), refuse to let YADE move DDA blocks as plain polyhedra. A scene
      with a DDAIntegrator is checked by its step; one without NewtonIntegrator costs a pass over O.engines.
    - A DDA step that raised: YADE reports it as RuntimeError('PyRunner error. COMMAND ... ERROR ...
      STACK TRACE ...'); the exception the step raised is raised instead (guards.raiseStepError), so a
      script catches a ValueError as a ValueError."""
    checks = original.__name__ in ('run', 'step')

    def run(self, *args, **kwargs):
        if checks:
            engines = self.engines
            if any(isinstance(e, wrapper.NewtonIntegrator) and not e.dead for e in engines) \
                    and not any(_guards.isIntegrator(e) for e in engines):
                scene = _scene.current(create=False)
                if scene is not None:
                    _guards.checkNewtonMask(scene, engines)
        try:
            return original(self, *args, **kwargs)
        except RuntimeError as error:
            _guards.raiseStepError(error)
            raise
    return _wrapping(run, original)


# ------------------------------------------------------------------ Omega.dt

USER_DT_TAG = 'yade_dda.userDt'
"""O.tags entry holding a time step the script assigned to O.dt, until the integrator's next step takes it."""


class _DtProperty(property):
    """Omega.dt with the assignment noted for the DDA integrator; ``yadeOriginal`` is YADE's property."""
    yadeOriginal = None


def _yadeDt():
    return _yadeProperty(wrapper.Omega, 'dt')


def writeDt(value):
    """Sets O.dt as the integrator does after its step, through YADE's own setter (not a script's assignment)."""
    _yadeDt().fset(O, value)


def _wrapDt(original):
    def assign(self, value):
        # Noted in every scene (a script may set O.dt before its first block); checked where DDA
        # blocks exist, elsewhere YADE's own rules hold (the integrator checks it when it takes it).
        if _scene.current(create=False) is not None:
            value = finite('O.dt', value, 0, lowOpen=True, unit=' s')
        original.fset(self, value)
        O.tags[USER_DT_TAG] = repr(float(value))
    dt = _DtProperty(original.fget, assign, None, (original.__doc__ or '') + (
        '\n\n(yade_dda: with a DDAIntegrator, a time step assigned here becomes its dt, the largest step, from the '
        'next step on; it must be finite and > 0.)'))
    dt.yadeOriginal = original
    return dt


# ------------------------------------------------------------------ utils.unbalancedForce

def unbalancedForce(useMaxForce=False):
    """YADE's ``utils.unbalancedForce``, with DDA blocks' gravity: the mean (or
    with ``useMaxForce`` the largest) norm of the resultant force on the
    dynamic bodies over the mean norm of the real interactions' forces
    (``normalForce + shearForce``) [-]. YADE adds ``mass x gravity`` of the
    first NewtonIntegrator in O.engines to every dynamic body's ``O.forces``
    (which excludes gravity); a DDA block gets the gravity of the DDA step
    instead (``O.forces`` holds its contacts, point loads and fixed points,
    yade_dda.views), other bodies YADE's. A resting pile then reads about 0,
    as YADE's spheres do, with no NewtonIntegrator in the scene. Clumps are
    taken as YADE takes them when their forces are current. NaN when nothing
    is dynamic or no interaction is real, as YADE's."""
    scene = _scene.current(create=False)
    original = unbalancedForce._yadeDDA
    if scene is None or not scene.bodyOfBlock:
        return original(useMaxForce)
    newton = next((e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator)), None)
    yadeGravity = newton.gravity if newton is not None else None
    settings = scene.settings
    ddaGravity = settings.gravity if settings is not None else None
    blocks = set(scene.bodyOfBlock)
    clumps = scene.clumpMembers   # a concave block: its clump's force plus its members' (their contacts)
    forces = O.forces
    norms = []
    for body in O.bodies:
        if body is None or body.isClumpMember or not body.dynamic:
            continue
        f = forces.f(body.id, True) if not norms else forces.f(body.id)
        for member in clumps.get(body.id, ()):
            f = f + forces.f(member)
        gravity = ddaGravity if body.id in blocks or body.id in clumps else yadeGravity
        if gravity is not None:
            f = f + body.state.mass * gravity
        norms.append(f.norm())
    contacts = [(i.phys.normalForce + i.phys.shearForce).norm() for i in O.interactions
                if isinstance(i.phys, wrapper.NormShearPhys)]
    if not norms or not contacts:
        return float('nan')
    body = max(norms) if useMaxForce else sum(norms) / len(norms)
    return body / (sum(contacts) / len(contacts))


def _installUnbalancedForce():
    """Puts unbalancedForce in place of YADE's in yade.utils, yade._utils and a
    running script's namespace (YADE's launcher binds the name there before
    the script runs ``import yade_dda``)."""
    import sys
    from yade import _utils, utils as yadeUtils
    current = yadeUtils.unbalancedForce
    unbalancedForce._yadeDDA = getattr(current, '_yadeDDA', current)
    for namespace in (yadeUtils.__dict__, _utils.__dict__, getattr(sys.modules.get('__main__'), '__dict__', {})):
        if namespace.get('unbalancedForce') is unbalancedForce._yadeDDA:
            namespace['unbalancedForce'] = unbalancedForce


def installHooks():
    """Wraps YADE's ``BodyContainer`` and ``Omega`` methods so that the DDA core
    follows the YADE scene. ``import yade_dda`` calls it once; calling it
    again changes nothing (each wrapper wraps YADE's original, never another
    wrapper). YADE's own method stays reachable as ``<method>._yadeDDA``.

    - ``BodyContainer.erase`` (``O.bodies.erase``): refuses to erase a DDA
      block that has entered the core (the core cannot remove blocks from a
      running scene yet) and forgets a pending one (doc/guide/reference.md, "Bad input").
    - ``BodyContainer.clear`` and ``replace``: give the YADE scene a fresh,
      empty DDA scene that keeps the pending blocks among the new bodies and
      those made by ``ddaBlock()`` but not yet appended (scene.freshScene).
    - ``Omega.save`` and ``saveTmp``: put the DDA state into
      ``O.tags['yade_dda.state']`` before YADE writes the scene, so every
      file format carries it (saveload.storeState).
    - ``Omega.load``, ``loadTmp`` and ``reload``: after YADE reads a scene,
      drop the stale DDA scenes and rebuild the loaded one from that tag
      (saveload.afterLoad); a load that fails puts the running scene back.
      ``Omega.save`` refuses a path it cannot write; ``Omega.load`` a name
      that is no file.
    - ``InteractionContainer.erase`` and ``clear`` (``O.interactions``), and
      the ``Body.state`` and ``Body.shape`` setters: YADE's own, then the
      scene's C++ writer forgets the YADE objects it kept that they replaced
      or removed (pkg/py/YadeSync.hpp).
    - ``Omega.dt``: a time step the script assigns is noted in ``O.tags``
      (USER_DT_TAG), and checked (finite, > 0) in a scene with DDA blocks;
      the integrator's next step makes it ``DDAIntegrator.dt``, its largest
      step (engines.integratorStep). The integrator's own writes go through
      YADE's setter (writeDt).
    - ``Omega.run`` and ``step``: a live NewtonIntegrator that would move DDA
      blocks while no DDAIntegrator is in O.engines is refused before YADE
      runs (guards.checkNewtonMask; with a DDAIntegrator its step checks).
      ``run``, ``step`` and ``wait`` raise a failed DDA step's own exception
      in place of YADE's RuntimeError('PyRunner error ...') that quotes it
      (guards.raiseStepError).
    - ``utils.unbalancedForce`` (in yade.utils, yade._utils and the running
      script's namespace): DDA blocks count with the DDA step's gravity,
      which YADE would take from a NewtonIntegrator (unbalancedForce above).
    """
    for cls, names, wrap in ((wrapper.BodyContainer, ('erase',), _wrapErase),
                             (wrapper.BodyContainer, ('clear',), _wrapClear),
                             (wrapper.BodyContainer, ('replace',), _wrapReplace),
                             (wrapper.InteractionContainer, ('erase',), _wrapInteractionErase),
                             (wrapper.InteractionContainer, ('clear',), _wrapInteractionClear),
                             (wrapper.Omega, _OMEGA_SAVES, _wrapSave),
                             (wrapper.Omega, _OMEGA_LOADS, _wrapLoad),
                             (wrapper.Omega, _OMEGA_RUNS, _wrapRun)):
        for name in names:
            setattr(cls, name, wrap(_original(cls, name)))
    wrapper.Omega.dt = _wrapDt(_yadeDt())
    for name in ('state', 'shape'):
        setattr(wrapper.Body, name, _wrapBodyObject(_yadeProperty(wrapper.Body, name)))
    _installUnbalancedForce()
