"""Checks that keep a DDA scene in a state the core can simulate (doc/guide/reference.md, "Bad input").

- ``O.bodies.erase(id)`` of a DDA block that has entered the core (after the
  first step) raises and erases nothing: the core cannot remove a block from
  a running scene yet. Blocks not yet in the core (before the first step
  after their ``append``) may be erased. ``O.bodies.clear()`` also clears the
  DDA state of the scene, and ``O.bodies.replace(bodies)`` clears it and
  makes the DDA blocks among ``bodies`` the new scene's blocks (they enter
  the core at the next step). Blocks made by ``ddaBlock()`` but not yet
  appended stay appendable across both. (Wrappers installed on YADE's
  ``BodyContainer`` by ``yade_dda.installHooks``, in hooks.py.)
- Blocks entering the scene overlapping deeper than the initial-overlap
  tolerance (dda/solver/InitialOverlaps.hpp) are refused with the two body
  ids and the depth; nothing is added and no step is taken.
- A ``NewtonIntegrator`` whose mask reaches a dynamic DDA block is refused:
  beside ``DDAIntegrator`` it would move the block twice an iteration,
  without one it would move it as a plain polyhedron (checked by the DDA
  step, and by ``O.run``/``O.step`` when no DDAIntegrator is there).
- Two DDA integrators in ``O.engines`` (each would advance the blocks once
  per iteration while ``O.time`` advances once) are refused.
- A YADE ``InteractionLoop`` with a functor that handles ``Polyhedra`` (the
  shape DDA blocks carry) and a non-DDA body sharing a ``groupMask`` bit with
  a DDA block would make YADE contacts DDA never sees: refused, with the
  mask bits to change.
"""
from ._yade import O, wrapper

INTEGRATOR_COMMAND = 'import yade_dda.engines'
"""How the command of a DDAIntegrator (yade_dda.engines) starts."""
COLLIDER_COMMAND = 'import yade_dda.colliders as _ddac; _ddac._select('
"""How the command of a collider engine (yade_dda.colliders) starts; files saved by YADE carry it."""


# ------------------------------------------------------------------ initial overlaps

def checkInitialOverlaps(scene, settings):
    """Raises ValueError if blocks entering the scene (pending bodies with an id,
    and core blocks not yet checked) overlap deeper than their tolerance.

    Nothing is added to the core by this check; run it before resolvePending.
    """
    ready = [(body, spec) for body, spec in scene.pending if body.id >= 0]
    first = scene.overlapsChecked
    count = scene.core.blockCount()
    if not ready and first >= count:
        return
    # A concave block enters part by part (its parts touch face to face: no overlap among them).
    added, addedIds = [], []
    for body, spec in ready:
        if hasattr(spec, 'members'):
            for corners, member in zip(spec.partCorners(), spec.members):
                added.append((corners, spec.density, spec.young, spec.poisson, spec.fixed))
                addedIds.append(member.id)
        else:
            added.append((spec.corners(), spec.density, spec.young, spec.poisson, spec.fixed))
            addedIds.append(body.id)
    overlaps = scene.core.initialOverlaps(first, added, settings)
    if overlaps:
        def bodyOf(index):
            return scene.bodyOfBlock[index] if index < count else addedIds[index - count]
        a, b, depth, tolerance = overlaps[0]
        more = ' (and %d more overlapping pairs)' % (len(overlaps) - 1) if len(overlaps) > 1 else ''
        raise ValueError(
            'DDA blocks body %d and body %d overlap by %.4g m as they enter the scene, more than the %.4g m '
            'accepted%s: their contact springs would push them apart with a spurious energy. Move them apart; the '
            'tolerance is min(d0, max(2 W / kn, 1e-6 x block size)) (doc/guide/reference.md, "Bad input"). Nothing was added and '
            'no step was taken.' % (bodyOf(a), bodyOf(b), depth, tolerance, more))


def markOverlapsChecked(scene):
    scene.overlapsChecked = scene.core.blockCount()


# ------------------------------------------------------------------ a step's error

STEP_ERROR = []
"""[exception, its traceback] of the last DDA step that raised (engines.integratorStep), until O.run raises it."""


def raiseStepError(error):
    """Raises, in place of YADE's RuntimeError 'PyRunner error' `error` that reports a failed DDA step, the
    exception that step raised (its type, message and traceback); returns when `error` is another one."""
    text = str(error)
    if len(STEP_ERROR) != 2 or not text.startswith('PyRunner error') or INTEGRATOR_COMMAND not in text:
        return
    stepError, traceback = STEP_ERROR
    del STEP_ERROR[:]
    if str(stepError) in text:
        raise stepError.with_traceback(traceback) from None


# ------------------------------------------------------------------ engines

def isIntegrator(engine):
    """A live DDAIntegrator (or the plain PyRunner of a loaded one)."""
    return (isinstance(engine, wrapper.PyRunner) and not engine.dead
            and engine.command.startswith(INTEGRATOR_COMMAND))


def checkSingleIntegrator(engines):
    positions = [k for k, engine in enumerate(engines) if isIntegrator(engine)]
    if len(positions) > 1:
        raise RuntimeError('O.engines holds %d DDA integrators (at positions %s); each would advance the blocks '
                           'once per iteration while O.time advances once. Keep one.'
                           % (len(positions), ', '.join(map(str, positions))))


def _ddaBodies(scene):
    """Ids of the YADE bodies that move with DDA blocks: blocks and concave blocks' members in the core,
    their clumps, and pending blocks already appended."""
    ids = list(scene.bodyOfBlock) + list(scene.clumpMembers)
    for body, spec in scene.pending:
        ids.extend(member.id for member in getattr(spec, 'members', (body,)) if member.id >= 0)
    return ids


def checkNewtonMask(scene, engines):
    """Refuses a live NewtonIntegrator whose mask reaches a dynamic DDA block: YADE would move it as a
    plain polyhedron (beside DDAIntegrator, twice an iteration)."""
    newtons = [e for e in engines if isinstance(e, wrapper.NewtonIntegrator) and not e.dead]
    if not newtons:
        return
    integrated = any(isIntegrator(e) for e in engines)
    for engine in newtons:
        for bodyId in _ddaBodies(scene):
            body = O.bodies[bodyId]
            if body is not None and body.dynamic and (engine.mask & body.groupMask):
                if integrated:
                    raise RuntimeError(
                        'NewtonIntegrator would also move DDA block body %d (its groupMask %d overlaps '
                        'NewtonIntegrator.mask %d). Give DDA blocks their own mask bit, e.g. '
                        'ddaBlock(..., mask=2) and NewtonIntegrator(mask=1), so YADE moves only its own bodies.'
                        % (bodyId, body.groupMask, engine.mask))
                raise RuntimeError(
                    'NewtonIntegrator would move DDA block body %d as a plain polyhedron: no DDAIntegrator in '
                    'O.engines moves the DDA blocks. Add DDAIntegrator(dt=..., gravity=...) (it replaces '
                    'NewtonIntegrator, collider and contact laws for DDA blocks); for YADE bodies beside them keep '
                    'NewtonIntegrator with a mask bit the blocks do not have, e.g. ddaBlock(..., mask=2) and '
                    'NewtonIntegrator(mask=1). Nothing was run.' % bodyId)


def checkColliderOrder(engines):
    """A collider engine must run before DDAIntegrator, and only one may be in `engines`."""
    colliders, integrator = [], None
    for index, engine in enumerate(engines):
        if isinstance(engine, wrapper.PyRunner) and not engine.dead:
            if engine.command.startswith(COLLIDER_COMMAND):
                colliders.append(index)
            elif engine.command.startswith(INTEGRATOR_COMMAND) and integrator is None:
                integrator = index
    if len(colliders) > 1:
        raise RuntimeError('O.engines holds %d DDA collider engines (at positions %s); keep one'
                           % (len(colliders), ', '.join(map(str, colliders))))
    if colliders and integrator is not None and integrator < colliders[0]:
        raise RuntimeError('the DDA collider engine (O.engines[%d]) must come before DDAIntegrator '
                           '(O.engines[%d]), as YADE colliders come before the interaction loop'
                           % (colliders[0], integrator))


def _handlesPolyhedra(engine):
    if not isinstance(engine, wrapper.InteractionLoop):
        return False
    return any('Polyhedra' in type(f).__name__ for f in engine.geomDispatcher.functors)


def checkYadeContacts(scene, engines):
    """Refuses YADE interactions between DDA blocks and YADE bodies (not modelled)."""
    loops = [type(e).__name__ for e in engines if _handlesPolyhedra(e)]
    if not loops or not scene.bodyOfBlock:
        return
    blockIds = set(scene.bodyOfBlock) | set(scene.clumpMembers)   # a concave block's clump is no YADE body
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
