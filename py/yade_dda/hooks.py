"""The one place where yade_dda changes YADE's own classes: ``installHooks``.

YADE knows nothing of the DDA core, which holds the true state of every DDA
block. Two of YADE's classes are wrapped so that what a script does to the
YADE scene reaches the core too; each wrapper calls YADE's original method
(kept as the wrapper's ``_yadeDDA`` attribute) and adds the DDA part.
"""
from ._yade import O, wrapper
from . import saveload as _saveload
from . import scene as _scene

_OMEGA_SAVES = ('save', 'saveTmp')
_OMEGA_LOADS = ('load', 'loadTmp', 'reload')


def _original(cls, name):
    """YADE's own method `name` of `cls`, under any wrapper installed before."""
    method = getattr(cls, name)
    return getattr(method, '_yadeDDA', method)


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
    erase.__doc__ = original.__doc__
    erase._yadeDDA = original
    return erase


def _wrapClear(original):
    def clear(self, *args, **kw):
        result = original(self, *args, **kw)
        _scene.freshScene()
        return result
    clear.__doc__ = original.__doc__
    clear._yadeDDA = original
    return clear


def _wrapReplace(original):
    def replace(self, bodies, *args, **kw):
        bodies = list(bodies)
        # YADE's replace clears the container in C++ (not through clear) and appends bodies.
        result = original(self, bodies, *args, **kw)
        _scene.freshScene(bodies)
        return result
    replace.__doc__ = original.__doc__
    replace._yadeDDA = original
    return replace


# ------------------------------------------------------------------ Omega

def _wrapSave(original):
    def save(self, *args, **kwargs):
        stored = _saveload.storeState()
        try:
            return original(self, *args, **kwargs)
        finally:
            if stored:
                O.tags[_saveload.STATE_TAG] = ''
    save.__doc__ = original.__doc__ + '\n\n(yade_dda: also saves the DDA state, see yade_dda.saveload.)'
    save._yadeDDA = original
    return save


def _wrapLoad(original):
    def load(self, *args, **kwargs):
        before = _saveload.currentToken()
        result = original(self, *args, **kwargs)
        _saveload.afterLoad(before)
        return result
    load.__doc__ = original.__doc__ + '\n\n(yade_dda: also restores the DDA state, see yade_dda.saveload.)'
    load._yadeDDA = original
    return load


def installHooks():
    """Wraps YADE's ``BodyContainer`` and ``Omega`` methods so that the DDA core
    follows the YADE scene. ``import yade_dda`` calls it once; calling it
    again changes nothing (each wrapper wraps YADE's original, never another
    wrapper). YADE's own method stays reachable as ``<method>._yadeDDA``.

    - ``BodyContainer.erase`` (``O.bodies.erase``): refuses to erase a DDA
      block that has entered the core (the core cannot remove blocks from a
      running scene yet) and forgets a pending one (README, "Bad input").
    - ``BodyContainer.clear`` and ``replace``: give the YADE scene a fresh,
      empty DDA scene that keeps the pending blocks among the new bodies and
      those made by ``ddaBlock()`` but not yet appended (scene.freshScene).
    - ``Omega.save`` and ``saveTmp``: put the DDA state into
      ``O.tags['yade_dda.state']`` before YADE writes the scene, so every
      file format carries it (saveload.storeState).
    - ``Omega.load``, ``loadTmp`` and ``reload``: after YADE reads a scene,
      drop the stale DDA scenes and rebuild the loaded one from that tag
      (saveload.afterLoad).
    """
    for cls, names, wrap in ((wrapper.BodyContainer, ('erase',), _wrapErase),
                             (wrapper.BodyContainer, ('clear',), _wrapClear),
                             (wrapper.BodyContainer, ('replace',), _wrapReplace),
                             (wrapper.Omega, _OMEGA_SAVES, _wrapSave),
                             (wrapper.Omega, _OMEGA_LOADS, _wrapLoad)):
        for name in names:
            setattr(cls, name, wrap(_original(cls, name)))
