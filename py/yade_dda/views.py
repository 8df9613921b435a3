"""What YADE sees of the DDA scene: interactions, forces and energy
(doc/guide/explanation.md, "What YADE sees: interactions, forces, energy").

Written at every sync (scene.DDAScene.sync), so under the same policy as the
bodies: only when something may read them.

- **Interactions.** Every body pair with a closed DDA contact is a real
  interaction in ``O.interactions`` with a ``PolyhedraGeom`` (contactPoint
  [m], normal from id1 to id2) and a ``PolyhedraPhys`` (normalForce and
  shearForce [N] on id2, the force on id1 being their opposite, as YADE's
  Polyhedra law writes them; kn, ks [N/m]; tangensOfFrictionAngle), id1 <
  id2. These are YADE's own classes for Polyhedra contacts: the GUI draws
  them as force chains (Gl1_PolyhedraPhys), PolyhedraPhys is a NormShearPhys
  (``utils.unbalancedForce``) and the exporters read them. Pairs that open or
  separate are erased. They are made by ``utils.createInteraction(id1, id2,
  True)`` (virtual: no dispatcher, no YADE geometry) and made real by setting
  their geom and phys, so no YADE functor ever runs on them. A live YADE
  ``InteractionLoop`` (a mixed scene with YADE contacts) visits every
  interaction but leaves alone a pair it has no geometry functor for, so DDA
  interactions are kept beside it, unless it has a functor for Polyhedra
  (which would compute YADE's own contact on them): then none are kept.
- **Forces.** ``O.forces.f(id)`` and ``t(id)`` of a DDA block are the sum of
  the forces [N] on it (contacts, point loads, fixed-point springs) and their
  torque about its centroid [N m]: gravity excluded, as YADE's
  ``O.forces`` for its own bodies (NewtonIntegrator adds gravity to the
  acceleration). Other bodies' forces are not touched. YADE's
  ``utils.unbalancedForce`` adds ``mass x gravity`` of the first
  NewtonIntegrator in O.engines; yade_dda's replacement (hooks.unbalancedForce)
  adds the DDA step's gravity to DDA blocks instead.
- **Energy.** With ``O.trackEnergy``, ``O.energy`` holds the core's energy
  account (``stats()['energy']``) under ENERGY_NAMES, signed so that
  ``O.energy.total()`` is the conserved balance.
"""
from ._yade import O, wrapper
from . import _core

ENERGY_NAMES = (
    # (stats()['energy'] key, O.energy name, sign)
    ('kinetic', 'ddaKinetic', 1),                # current [J]
    ('gravityChange', 'ddaGravity', 1),          # potential relative to the blocks' initial places [J]
    ('strain', 'ddaStrain', 1),                  # current [J]
    ('contact', 'ddaContact', 1),                # current, the closed contacts' springs [J]
    ('friction', 'ddaFriction', 1),              # cumulative, dissipated [J]
    ('damping', 'ddaDamping', 1),                # cumulative, dissipated [J]
    ('loads', 'ddaLoads', -1),                   # cumulative, minus the work of loads and fixed points [J]
    ('boundaryWork', 'ddaBoundaryWork', -1),     # cumulative, minus the work of prescribed motions (baseMotion) [J]
    ('contactChanges', 'ddaContactChanges', -1),  # cumulative, minus what detection gave the springs [J]
)

_DEFAULT_SETTINGS = _core.IntegratorSettings()
_enabled = True


def setEnabled(flag):
    """Keeps O.interactions, O.forces and O.energy in step with the DDA scene
    (True, the default) or not (False: nothing is written; what was written
    stays)."""
    global _enabled
    _enabled = bool(flag)


def update(scene, engines=None):
    """Writes the DDA scene's interactions, forces and energy into YADE's
    containers (called by DDAScene.sync); the writes are made in C++
    (pkg/py/YadeSync.hpp: what it keeps of YADE's objects, and why that holds)."""
    if not _enabled:
        return
    settings = scene.settings or _DEFAULT_SETTINGS
    writer = scene.writer()
    engines = O.engines if engines is None else engines
    keep = not any(_runsPolyhedraFunctor(e) for e in engines)
    # The first update of a scene also erases DDA interactions it did not make (a loaded scene's).
    foreign = [] if scene.viewsStarted else sorted(_ddaPairs(scene))
    # O.forces: YADE resets it only where a ForceResetter runs (a DDA scene need not have one), so the
    # writer adds what is missing; see YadeSync::writeForces for how it knows what is there.
    writer.writeViews(scene.core, settings, O.forces, O.interactions, keep, foreign)
    scene.viewsStarted = True
    if O.trackEnergy:
        _writeEnergy(scene)


def _runsPolyhedraFunctor(engine):
    """Whether `engine` is a live InteractionLoop (or IGeomDispatcher) with a geometry functor for
    Polyhedra, which would run YADE's own contact on a DDA pair in O.interactions. One without leaves
    such a real interaction alone: InteractionLoop::action finds no functor for the pair, marks it and
    skips it (checked on a sphere scene beside DDA blocks, tests/py/yade/test_yade_views.py)."""
    if isinstance(engine, wrapper.InteractionLoop):
        functors = engine.geomDispatcher.functors
    elif isinstance(engine, wrapper.IGeomDispatcher):
        functors = engine.functors
    else:
        return False
    return not engine.dead and any('Polyhedra' in type(f).__name__ for f in functors)


def _ddaPairs(scene):
    """Real interactions between two DDA blocks now in O.interactions (those
    a loaded scene brought along)."""
    blocks = set(scene.bodyOfBlock)
    return {(i.id1, i.id2) for i in O.interactions if i.id1 in blocks and i.id2 in blocks}


def _writeEnergy(scene):
    account = scene.core.lastStep()['energy']
    energy = O.energy
    for key, name, sign in ENERGY_NAMES:
        energy[name] = sign * account[key]
