"""Checks that keep a DDA scene in a state the core can simulate (README, "Bad input").

- ``O.bodies.erase(id)`` of a DDA block that has entered the core (after the
  first step) raises and erases nothing: the core cannot remove a block from
  a running scene yet. Blocks not yet in the core (before the first step
  after their ``append``) may be erased. ``O.bodies.clear()`` also clears the
  DDA state of the scene, and ``O.bodies.replace(bodies)`` clears it and
  makes the DDA blocks among ``bodies`` the new scene's blocks (they enter
  the core at the next step). Blocks made by ``ddaBlock()`` but not yet
  appended stay appendable across both.
- Blocks entering the scene overlapping deeper than the initial-overlap
  tolerance (dda/solver/InitialOverlaps.hpp) are refused with the two body
  ids and the depth; nothing is added and no step is taken.
- Two DDA integrators in ``O.engines`` (each would advance the blocks once
  per iteration while ``O.time`` advances once) are refused.
- A YADE ``InteractionLoop`` with a functor that handles ``Polyhedra`` (the
  shape DDA blocks carry) and a non-DDA body sharing a ``groupMask`` bit with
  a DDA block would make YADE contacts DDA never sees: refused, with the
  mask bits to change.
"""
import uuid

from ._yade import O, wrapper
from . import scene as _scene

_INTEGRATOR_COMMAND = 'import yade_dda.engines'


# ------------------------------------------------------------------ erasing bodies

_originalErase = wrapper.BodyContainer.erase
_originalClear = wrapper.BodyContainer.clear
_originalReplace = wrapper.BodyContainer.replace


def _erase(self, id, *args, **kw):
    scene = _scene.current(create=False)
    if scene is not None and isinstance(id, int):
        index = scene.core.blockOfBody(id)
        if index is not None:
            raise RuntimeError(
                'body %d is DDA block %d of a running scene; the DDA core cannot remove blocks yet, so it was not '
                'erased. Erase DDA blocks before the first step after their append, or rebuild the scene '
                '(O.reset()).' % (id, index))
        scene.pending = [(body, spec) for body, spec in scene.pending if body.id != id]
    return _originalErase(self, id, *args, **kw)


def _freshScene(bodies=()):
    """Replaces the current DDA scene (its blocks are gone from O.bodies) by an
    empty one that keeps the pending blocks among `bodies` and those made by
    ddaBlock() but never appended (id < 0).
    (O.tags has no __delitem__, so the token is replaced rather than removed.)"""
    old = _scene.current(create=False)
    if old is None:
        return
    kept = {id(body) for body in bodies}
    token = uuid.uuid4().hex
    fresh = _scene.DDAScene(token)
    fresh.pending = [(body, spec) for body, spec in old.pending if body.id < 0 or id(body) in kept]
    _scene._scenes.pop(old.token, None)
    _scene._scenes[token] = fresh
    O.tags[_scene.TAG] = token


def _clear(self, *args, **kw):
    result = _originalClear(self, *args, **kw)
    _freshScene()
    return result


def _replace(self, bodies, *args, **kw):
    bodies = list(bodies)
    # YADE's replace clears the container in C++ (not through _clear) and appends bodies.
    result = _originalReplace(self, bodies, *args, **kw)
    _freshScene(bodies)
    return result


_erase.__doc__ = _originalErase.__doc__
_clear.__doc__ = _originalClear.__doc__
_replace.__doc__ = _originalReplace.__doc__
wrapper.BodyContainer.erase = _erase
wrapper.BodyContainer.clear = _clear
wrapper.BodyContainer.replace = _replace


# ------------------------------------------------------------------ initial overlaps

def checkInitialOverlaps(scene, settings):
    """Raises ValueError if blocks entering the scene (pending bodies with an id,
    and core blocks not yet checked) overlap deeper than their tolerance.

    Nothing is added to the core by this check; run it before resolvePending.
    """
    ready = [(body, spec) for body, spec in scene.pending if body.id >= 0]
    first = getattr(scene, 'overlapsChecked', 0)
    count = scene.core.blockCount()
    if not ready and first >= count:
        return
    added = [(spec.corners(), spec.density, spec.young, spec.poisson, spec.fixed) for _, spec in ready]
    overlaps = scene.core.initialOverlaps(first, added, settings)
    if overlaps:
        def bodyOf(index):
            return scene.bodyOfBlock[index] if index < count else ready[index - count][0].id
        a, b, depth, tolerance = overlaps[0]
        more = ' (and %d more overlapping pairs)' % (len(overlaps) - 1) if len(overlaps) > 1 else ''
        raise ValueError(
            'DDA blocks body %d and body %d overlap by %.4g m as they enter the scene, more than the %.4g m '
            'accepted%s: their contact springs would push them apart with a spurious energy. Move them apart; the '
            'tolerance is min(d0, max(2 W / kn, 1e-6 x block size)) (README, "Bad input"). Nothing was added and '
            'no step was taken.' % (bodyOf(a), bodyOf(b), depth, tolerance, more))


def markOverlapsChecked(scene):
    scene.overlapsChecked = scene.core.blockCount()


# ------------------------------------------------------------------ engines

def _isIntegrator(engine):
    return (isinstance(engine, wrapper.PyRunner) and not engine.dead
            and engine.command.startswith(_INTEGRATOR_COMMAND))


def checkSingleIntegrator(engines):
    positions = [k for k, engine in enumerate(engines) if _isIntegrator(engine)]
    if len(positions) > 1:
        raise RuntimeError('O.engines holds %d DDA integrators (at positions %s); each would advance the blocks '
                           'once per iteration while O.time advances once. Keep one.'
                           % (len(positions), ', '.join(map(str, positions))))


def _handlesPolyhedra(engine):
    if not isinstance(engine, wrapper.InteractionLoop):
        return False
    return any('Polyhedra' in type(f).__name__ for f in engine.geomDispatcher.functors)


def checkYadeContacts(scene, engines):
    """Refuses YADE interactions between DDA blocks and YADE bodies (not modelled)."""
    loops = [type(e).__name__ for e in engines if _handlesPolyhedra(e)]
    if not loops or not scene.bodyOfBlock:
        return
    blockIds = set(scene.bodyOfBlock)
    bodies = O.bodies
    ddaMask, firstBlock = 0, {}
    for bodyId in scene.bodyOfBlock:
        body = bodies[bodyId]
        if body is None:
            continue
        for bit in range(64):
            if body.groupMask >> bit & 1 and bit not in firstBlock:
                firstBlock[bit] = bodyId
        ddaMask |= body.groupMask
    for body in bodies:
        if body is None or body.id in blockIds or not (body.groupMask & ddaMask):
            continue
        shared = body.groupMask & ddaMask
        bit = (shared & -shared).bit_length() - 1
        raise RuntimeError(
            'YADE body %d (%s) shares groupMask bit %d with DDA block body %d, and O.engines has an '
            'InteractionLoop with a Polyhedra functor: YADE would make contacts with the DDA block that DDA never '
            'sees (contact between YADE bodies and DDA blocks is not modelled). Give them disjoint mask bits, e.g. '
            'ddaBlock(..., mask=2) and mask=1 for YADE bodies.'
            % (body.id, type(body.shape).__name__, bit, firstBlock[bit]))
