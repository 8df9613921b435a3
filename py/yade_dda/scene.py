"""The DDA state of the current YADE scene, and its link to YADE's bodies.

The compiled core (``yade_dda._core.Scene``) is the source of truth for every
DDA block: geometry, 12-unknown velocity, stress. YADE bodies show that state;
``sync`` writes it into them (position, orientation, velocity, angular
velocity and, for strained blocks, the local vertices of the Polyhedra shape).

One core scene belongs to one YADE scene. It is found through a token stored in
``O.tags``, so ``O.reset()`` (which clears the tags) starts a fresh DDA scene.
"""
import textwrap
import time
import uuid

from ._yade import O, wrapper, utils
from . import _core
from . import state as _state
from . import views as _views

TAG = 'yade_dda.scene'
_scenes = {}


class DDAScene:
    """Core scene plus the bookkeeping between blocks and YADE bodies. Every field is declared here
    (__slots__): a module that needs another declares it, it cannot hang one on the scene."""

    __slots__ = ('token', 'core', 'pending', 'bodyOfBlock', 'clumpMembers', 'syncTime', 'syncParts', 'yadeSync',
                 'viewsStarted', 'syncedBodies', 'syncs', 'syncTimeTotal', 'stepTimeTotal', 'checkedEngines',
                 'colliderChoice', 'cover', 'settings', 'progressMark', 'overlapsChecked', 'blockCountCache')

    def __init__(self, token):
        self.token = token
        self.core = _core.Scene()
        self.pending = []          # [(body, BlockSpec)] made by ddaBlock, not yet in the core
        self.bodyOfBlock = []      # block index -> body id (a concave block's parts: its members)
        self.clumpMembers = {}     # clump id of a concave block -> its member ids
        self.syncTime = 0.0        # wall time of the last sync [s]
        self.syncParts = dict(bodies=0.0, views=0.0)   # its parts [s]: bodies, and views.update
        self.yadeSync = None       # _core.YadeSync, made by writer()
        self.viewsStarted = False  # views.update has run (it looked for a loaded scene's DDA interactions)
        self.syncedBodies = 0
        self.syncs = 0             # number of syncs done
        self.syncTimeTotal = 0.0   # wall time of all syncs [s]
        self.stepTimeTotal = 0.0   # wall time of all engine calls, sync included [s]
        self.checkedEngines = None  # signature of the engine list last checked for conflicts
        self.colliderChoice = None  # (iteration, strategy, its parameters) of a collider engine (colliders.py)
        self.cover = None           # MSC's (criticalLength, segments) last given to the core (engines.py)
        self.settings = None        # the last step's _core.IntegratorSettings (engines.py; views, sync read it)
        self.progressMark = None    # (wall time, O.iter, O.time) of the last progress line (engines.py)
        self.overlapsChecked = 0    # blocks of the core whose initial overlaps were checked (guards.py)
        self.blockCountCache = None  # (core, parts, blocks) of _blockCount

    def register(self, body, spec):
        self.pending.append((body, spec))

    def resolvePending(self):
        """Moves blocks whose bodies are now in O.bodies into the core."""
        if not self.pending:
            return
        waiting = []
        self.core.reserveBlocks(len(self.pending))    # one allocation for the batch, sized to it
        for body, spec in self.pending:
            if body.id < 0:
                waiting.append((body, spec))   # made but not (yet) appended: not simulated
                continue
            if hasattr(spec, 'members'):
                self._addConcave(spec)
                continue
            index = self.core.addBlock(spec.corners(), spec.density, spec.young, spec.poisson, spec.frictionAngle,
                                       spec.cohesion, spec.tensileStrength, spec.fixed, bool(spec.rigid))
            self.core.linkBody(index, body.id, body.state.pos, body.state.ori, list(body.shape.v))
            # The body's state is read here, so a script may still set
            # b.state.vel / b.state.angVel between ddaBlock() and the first step.
            self._setState(index, spec, body.state)
            assert index == len(self.bodyOfBlock)
            self.bodyOfBlock.append(body.id)
        self.pending = waiting

    def _setState(self, index, spec, state):
        """A new block's velocity (from `state`, a YADE State), fixed points, loads and initial stress."""
        if not spec.fixed:
            self.core.setVelocity(index, state.vel, state.angVel)
        for point, stiffness in spec.fixedPoints:
            self.core.addFixedPoint(index, point, stiffness)
        for point, force in spec.loads:
            self.core.addPointLoad(index, point, force)
        if spec.stress is not None:
            self.core.setStress(index, spec.stress)

    def _addConcave(self, spec):
        """A concave block (concaveBlock) whose members are in O.bodies: into the core, each member linked to
        its part and the clump to the block."""
        ids = [member.id for member in spec.members]
        clumps = {O.bodies[i].clumpId if i >= 0 and O.bodies[i] is not None else -1 for i in ids}
        if len(clumps) != 1 or -1 in clumps:
            raise ValueError('the members of a concave block (bodies %s) must be appended together, as one clump: '
                             'O.bodies.appendClumped(concaveBlock(parts, ...)); they are not one clump now (clump '
                             'ids %s)' % (ids, sorted(clumps)))
        clumpId = clumps.pop()
        clump = O.bodies[clumpId]
        index = self.core.addConcaveBlock(spec.partCorners(), spec.density, spec.young, spec.poisson,
                                          spec.frictionAngle, spec.cohesion, spec.tensileStrength, spec.fixed,
                                          bool(spec.rigid))
        for part, member in enumerate(spec.members):
            self.core.linkBody(index + part, member.id, member.state.pos, member.state.ori, list(member.shape.v))
        self.core.linkClump(index, clumpId, clump.state.ori)
        if spec.fixed:
            clump.dynamic = False   # as its members: YADE's tools (unbalancedForce, Newton) then skip it
        # The clump's state when a script set it after appendClumped, else what concaveBlock was given.
        state = clump.state if (clump.state.vel.norm() > 0 or clump.state.angVel.norm() > 0) else \
            spec.members[0].state
        self._setState(index, spec, state)
        assert index == len(self.bodyOfBlock)
        self.bodyOfBlock.extend(ids)
        self.clumpMembers[clumpId] = tuple(ids)

    def blockIndex(self, body):
        """Block index of a body (a Body or an id); raises for non-DDA bodies."""
        bodyId = _bodyId(body)
        self.resolvePending()
        index = self.core.blockOfBody(bodyId)
        if index is None:
            raise KeyError('body %d is not a DDA block (unknown body id, or not yet appended to O.bodies)' % bodyId)
        return index

    def writer(self):
        """The scene's C++ writer into YADE's containers (_core.YadeSync, pkg/py/YadeSync.hpp), made on first use."""
        if self.yadeSync is None:
            self.yadeSync = _core.YadeSync(wrapper.PolyhedraGeom, wrapper.PolyhedraPhys, utils.createInteraction)
        return self.yadeSync

    def sync(self, everything=False):
        """Writes the core state of moving blocks (all blocks if everything) into YADE's bodies, and
        the views of views.py (O.interactions, O.forces, O.energy).

        The writes are made in C++ (pkg/py/YadeSync.cpp) through YADE's own attributes, with the
        YADE objects looked up once and kept, and no Python object made per block: nothing for
        Python's garbage collector (the Python loop this replaced made a tuple of vectors per block,
        and the collector's passes took two thirds of its time at 10,000 blocks)."""
        start = time.perf_counter()
        settings = self.settings
        self.syncedBodies = self.writer().writeBodies(self.core, O.bodies, everything,
                                                      settings.threads if settings is not None else 0)
        middle = time.perf_counter()
        _views.update(self)
        end = time.perf_counter()
        self.syncTime = end - start
        self.syncParts = dict(bodies=middle - start, views=end - middle)
        self.syncTimeTotal += self.syncTime
        self.syncs += 1


def newToken():
    return uuid.uuid4().hex


def register(scene):
    """Makes scene the DDA scene of the current YADE scene."""
    _scenes[scene.token] = scene
    O.tags[TAG] = scene.token


def drop(token):
    """Forgets a DDA scene (its YADE scene was replaced by O.load)."""
    _scenes.pop(token, None)

def _bodyId(body):
    """The id of a Body or of an int id; TypeError for anything else."""
    if isinstance(body, int) and not isinstance(body, bool):
        return body
    bodyId = getattr(body, 'id', None)
    if not isinstance(bodyId, int):
        raise TypeError('expected a YADE Body or a body id (int), got %r' % (body,))
    return bodyId


def writerOfCurrent():
    """The C++ writer (YadeSync) of the current YADE scene's DDA scene, or None when there is none
    yet; never restores or makes a scene (what yade_dda.hooks needs to tell it what a script did)."""
    token = O.tags[TAG] if TAG in O.tags.keys() else None
    scene = _scenes.get(token) if token else None
    return scene.yadeSync if scene is not None else None


def current(create=True):
    """The DDA scene of the current YADE scene (made on demand when create).

    A YADE scene loaded with DDA blocks whose core scene this process does not
    hold (loaded before yade_dda was imported) is restored from its saved DDA
    state (restoreState)."""
    token = O.tags[TAG] if TAG in O.tags.keys() else None
    if token and token in _scenes:
        return _scenes[token]
    if token:
        try:
            return restoreState()
        except ValueError as error:
            raise RuntimeError('this YADE scene holds DDA blocks whose DDA state cannot be restored: %s' % error) from None
    if not create:
        return None
    scene = DDAScene(newToken())
    register(scene)
    return scene


def restoreState():
    """Rebuilds the DDA scene of the current YADE scene from
    ``O.tags['yade_dda.state']`` (what the wrapped O.load does after YADE
    reads). Returns the new DDA scene, or None when the YADE scene has no DDA
    blocks. Raises ValueError naming the problem when the state is missing for
    a DDA scene, stale, corrupt or of another version; then nothing changes."""
    token = _state.tag(TAG)
    text = _state.tag(_state.STATE_TAG)
    if not token:
        return None
    if not text:
        raise ValueError(
            'this YADE scene has DDA blocks but was saved without their DDA state (a file saved before yade_dda '
            'could save it, or by a path that bypasses O.save); its DDA blocks cannot continue')
    info, state = _state.decodeState(text)
    if info['token'] != token:
        raise ValueError("O.tags['%s'] belongs to another DDA scene (token %s, this scene's is %s): stale state, "
                         'not used' % (_state.STATE_TAG, info['token'], token))
    if info['iter'] != O.iter:
        raise ValueError("O.tags['%s'] was written at iteration %d but the scene is at iteration %d: stale state "
                         '(the scene was saved again without yade_dda?), not used'
                         % (_state.STATE_TAG, info['iter'], O.iter))
    core = _core.Scene()
    core.loadState(state)
    bodies = info['bodies']
    checked = info.get('checked', core.blockCount() if core.steps() > 0 else 0)
    if (core.steps() != info['steps'] or core.blockCount() != len(bodies) or not isinstance(checked, int)
            or isinstance(checked, bool) or not 0 <= checked <= len(bodies)):
        raise ValueError("O.tags['%s'] is corrupt: its header and its core state disagree" % _state.STATE_TAG)
    for index, bodyId in enumerate(bodies):
        body = O.bodies[bodyId] if 0 <= bodyId < len(O.bodies) else None
        if body is None or not isinstance(body.shape, wrapper.Polyhedra):
            raise ValueError('DDA block %d is shown by body %d, which is %s in the loaded scene: the saved DDA state '
                             'does not match its bodies' % (index, bodyId, 'missing' if body is None
                                                             else 'a %s' % type(body.shape).__name__))
    scene = DDAScene(newToken())
    scene.core = core
    scene.bodyOfBlock = list(bodies)
    scene.clumpMembers = {clumpId: tuple(bodies[index:index + core.partCount(index)])
                          for index, clumpId in core.clumps()}
    for index, clumpId in core.clumps():
        if core.isFixed(index) and O.bodies[clumpId] is not None:
            O.bodies[clumpId].dynamic = False   # as _addConcave makes it (a file saved before it did)
    scene.cover = tuple(info['cover']) if info.get('cover') is not None else None
    # The blocks the saved scene had already checked for initial overlaps (guards.checkInitialOverlaps)
    # stay checked: checked again, blocks pressed into each other by their contacts (an impact, a block
    # sliding into a step) would be refused as overlapping and the run could not resume. Blocks that
    # entered the core when the scene was saved (pending ones) are still checked at the next step, as
    # they would have been without the save. States written before this was stored: all blocks of a
    # scene that has stepped count as checked, none of one that has not.
    scene.overlapsChecked = checked
    register(scene)
    O.tags[_state.STATE_TAG] = ''
    return scene


def freshScene(bodies=()):
    """Replaces the current DDA scene (its blocks are gone from O.bodies) by an
    empty one that keeps the pending blocks among `bodies` and those made by
    ddaBlock() but never appended (id < 0); what O.bodies.clear() and
    replace() do after YADE's (yade_dda.installHooks).
    (O.tags has no __delitem__, so the token is replaced rather than removed.)"""
    old = current(create=False)
    if old is None:
        return
    kept = {id(body) for body in bodies}
    token = newToken()
    fresh = DDAScene(token)
    fresh.pending = [(body, spec) for body, spec in old.pending if body.id < 0 or id(body) in kept]
    _scenes.pop(old.token, None)
    _scenes[token] = fresh
    O.tags[TAG] = token


def _require():
    scene = current(create=False)
    if scene is None:
        raise RuntimeError('this YADE scene has no DDA blocks (make them with ddaBlock)')
    return scene


def sync(everything=True):
    """Writes the DDA state into the YADE bodies now (normally automatic, see DDAIntegrator.syncPeriod)."""
    scene = current(create=False)
    if scene is not None:
        scene.resolvePending()
        scene.sync(everything)


def stats():
    scene = _require()
    result = scene.core.lastStep()
    result['parts'] = result['blocks']   # the core counts convex parts
    result['blocks'] = _blockCount(scene, result['parts'])
    result['time']['sync'] = scene.syncTime
    result['time']['syncBodies'] = scene.syncParts['bodies']
    result['time']['syncViews'] = scene.syncParts['views']
    result['syncedBodies'] = scene.syncedBodies
    result['syncs'] = scene.syncs
    result['syncTimeTotal'] = scene.syncTimeTotal
    result['stepTimeTotal'] = scene.stepTimeTotal
    result['pendingBodies'] = sum(1 for body, _ in scene.pending if body.id >= 0)
    result['steps'] = scene.core.steps()
    result['collider'] = scene.core.collider()
    result['unsettledBlocks'] = sorted({scene.bodyOfBlock[b] for b in scene.core.unsettledBlocks()})
    result['effects'] = _effects(result)
    return result


# What stats() adds to the core's report (_core.statisticsTable(), from pkg/dda/solver/Statistics.def),
# or says of it in the user's terms: (group, key, unit, doc), group '' for a top-level key.
_PYTHON_STATS = (
    ('', 'blocks', '', 'DDA blocks (a concave block counts once)'),
    ('', 'parts', '', 'their convex parts (a concave block\'s each)'),
    ('', 'collider', '', "the broad phase used: 'MSC', 'DESS', 'NBS' or 'AllPairs'"),
    ('', 'steps', '', 'DDA steps taken so far'),
    ('', 'pendingBodies', '', 'DDA blocks appended that enter the core at the next step'),
    ('', 'unsettledBlocks', '', 'body ids the start from rest could not hold: with friction locked (the scene '
     'started as placed, settleConverged False) or at its true value (blocks that must slide: the locked state '
     'was kept); empty when it settled'),
    ('', 'syncedBodies', '', 'bodies written by the last sync'),
    ('', 'syncs', '', 'syncs so far'),
    ('', 'syncTimeTotal', 's', 'wall time of all syncs'),
    ('', 'stepTimeTotal', 's', 'wall time of all integrator calls, syncs included'),
    ('time', 'sync', 's', 'wall time of the last sync'),
    ('time', 'syncBodies', 's', 'of which writing the bodies'),
    ('time', 'syncViews', 's', 'of which interactions, forces and energy (views.py)'),
    ('energy', 'kinetic', 'J', 'kinetic energy now'),
    ('energy', 'gravity', 'J', "potential of the last step's gravity, -m g . c summed over the moving blocks"),
    ('energy', 'gravityChange', 'J', "the same less its value at the blocks' initial centroids (0 at the start; "
     "O.energy's ddaGravity)"),
    ('energy', 'strain', 'J', "the blocks' elastic energy now"),
    ('energy', 'contact', 'J', "the closed contacts' springs now"),
    ('energy', 'friction', 'J', 'dissipated by sliding (cumulative)'),
    ('energy', 'damping', 'J', 'dissipated by the time scheme, strain viscosity and velocityRatio < 1 (cumulative)'),
    ('energy', 'loads', 'J', 'work of point loads and fixed points (cumulative)'),
    ('energy', 'boundaryWork', 'J', 'work done on the moving blocks by prescribed motions of fixed blocks '
     '(baseMotion; cumulative)'),
    ('energy', 'contactChanges', 'J', "what the contacts' springs gained between steps: new penetrating contacts, "
     'gaps linearised again, springs lost when contacts vanish (cumulative). kinetic + gravity + strain + '
     'contact + friction + damping - loads - boundaryWork - contactChanges is conserved (doc/guide/reference.md, "The energy '
     'account")'),
    ('memory', 'collider', 'bytes', "the broad phase's arrays (boxes, shells, grid, caches), after the detection"),
    ('memory', 'contacts', 'bytes', "the contact store, the previous step's contacts kept for their history"),
    ('memory', 'narrowPhase', 'bytes', 'per-block planes and per-pair results'),
    ('memory', 'solver', 'bytes', 'per moving block its solution and motion, the systems of the blocks with '
     'springs, the coupled system\'s blocks (after the step)'),
    ('effects', 'friction', '', 'some contact has a friction angle > 0'),
    ('effects', 'gravity', '', 'a body force was assembled'),
    ('effects', 'static', '', 'velocityRatio == 0'),
    ('effects', 'bonds', '', 'some contact is a bonded joint'),
    ('effects', 'fixedBlocks', '', 'blocks without unknowns (never paired together)'),
    ('effects', 'restingReuse', '', 'the broad phase was served from its pair cache'),
    ('effects', 'rigidBlocks', '', 'blocks with 6 unknowns'),
    ('effects', 'baseMotion', '', 'a prescribed motion moved fixed blocks (baseMotion)'),
)

_STATS_GROUPS = (('', 'The step, its contacts and solves'),
                 ('time', "``time``: wall seconds per phase"),
                 ('cpuTime', "``cpuTime``: the process's CPU seconds (all threads) in the contact detection; with "
                             "one thread the work without the machine's waits, steadier than wall time"),
                 ('energy', '``energy``: the energy account, each term from its own formula'),
                 ('memory', '``memory``: heap bytes held'),
                 ('effects', "``effects``: which effects the last step simulated (what it paid for), from the "
                             "counters above"))


def statisticsRows():
    """Every key of stats() as (group, key, unit, doc): the core's rows (pkg/dda/solver/Statistics.def) with
    what stats() says or adds in the user's terms (_PYTHON_STATS) in place of or after them."""
    own = {(g, k): (g, k, u, d) for g, k, u, d in _PYTHON_STATS}
    rows, seen = [], set()
    for row in _core.statisticsTable():
        key = (row['group'], row['key'])
        rows.append(own.get(key, (row['group'], row['key'], row['unit'], row['doc'])))
        seen.add(key)
    rows += [r for r in _PYTHON_STATS if (r[0], r[1]) not in seen]
    return rows


def _statsDoc():
    """stats()'s docstring: the rows of statisticsRows by group."""
    def fill(text, first='', later=''):
        return textwrap.fill(text, 100, initial_indent='    ' + first, subsequent_indent='    ' + later)
    lines = ['Diagnostics of the last DDA step as a dict (SI units).', '',
             fill('Generated from the core\'s declaration of the step\'s report (pkg/dda/solver/Statistics.def) '
                  'and what the package adds (scene._PYTHON_STATS). "all attempts": over every attempt of the step '
                  '(a step cut redoes it); "cumulative": over the run.')]
    rows = statisticsRows()
    for group, title in _STATS_GROUPS:
        lines += ['', fill(title + ':'), '']
        lines += [fill('``%s``%s: %s' % (key, ' [%s]' % unit if unit else '', doc), '- ', '  ')
                  for g, key, unit, doc in rows if g == group]
    return '\n'.join(lines) + '\n    '


stats.__doc__ = _statsDoc()


def _blockCount(scene, parts):
    """The DDA blocks among the core's first `parts` convex parts (a concave block's parts follow its
    first, which is its body: core.bodyOf), cached per core and part count (parts are only appended)."""
    cached = scene.blockCountCache
    if cached is None or cached[0] is not scene.core or cached[1] != parts:
        bodyOf = scene.core.bodyOf
        cached = scene.blockCountCache = (scene.core, parts, sum(1 for i in range(parts) if bodyOf(i) == i))
    return cached[2]


def _effects(s):
    """Which effects the last step simulated, from its counters (each key's meaning: _PYTHON_STATS)."""
    return {
        'friction': s['frictionContacts'] > 0,
        'gravity': s['bodyForceBlocks'] > 0,
        'static': bool(s['staticAnalysis']),
        'bonds': s['bondedContacts'] > 0,
        'fixedBlocks': s['fixedBlocks'],
        'restingReuse': bool(s['broadPhaseSkipped']),
        'rigidBlocks': s['rigidBlocks'],
        'baseMotion': s['shakenBlocks'] > 0,
    }


def printStats():
    """Prints the last step's diagnostics as a table."""
    s = stats()
    parts = ' (%d parts)' % s['parts'] if s['parts'] != s['blocks'] else ''
    print('DDA step: dt %.3e s, %d cuts, %d/%d moving blocks%s, %d unknowns, max displacement %.3e m (allowed %.3e m)'
          % (s['dt'], s['stepCuts'], s['movingBlocks'], s['blocks'], parts, s['unknowns'], s['maxDisplacement'],
             s['allowedDisplacement']))
    print('  contacts: %d pairs of %d candidates, %d sub-contacts (%d closed, %d sliding), '
          '%d open-close iterations, %d cuts, max penetration %.3e m'
          % (s['contactPairs'], s['candidatePairs'], s['contacts'], s['closedContacts'], s['slidingContacts'],
             s['openCloseIterations'], s['openCloseCuts'], s['maxPenetration']))
    for phase in ('broadPhase', 'narrowPhase', 'assembly', 'solve', 'update', 'core', 'sync'):
        print('  %-9s %10.3f ms' % (phase, 1e3 * s['time'][phase]))


class BlockView:
    """Read-only view of one block's core state (SI units)."""

    def __init__(self, scene, index):
        self._core, self.index = scene.core, index

    vertices = property(lambda self: self._core.vertices(self.index), doc='current vertices [m]')
    faces = property(lambda self: self._core.faces(self.index), doc='faces as vertex-index tuples, CCW from outside')
    edges = property(lambda self: self._core.edges(self.index), doc='edges as vertex-index pairs')
    centroid = property(lambda self: self._core.centroid(self.index), doc='centroid [m]')
    volume = property(lambda self: self._core.volume(self.index), doc='volume [m^3]')
    mass = property(lambda self: self._core.mass(self.index), doc='mass [kg] (conserved)')
    secondMoment = property(lambda self: self._core.secondMoment(self.index),
                            doc='integral of (x-c)(x-c)^T dV [m^5]')
    velocity = property(lambda self: self._core.velocity(self.index),
                        doc='rates of the 12 unknowns: (vx, vy, vz, wx, wy, wz, exx, eyy, ezz, gxy, gyz, gzx)')
    stress = property(lambda self: self._core.stress(self.index), doc='(sxx, syy, szz, sxy, syz, szx) [Pa]')
    strain = property(lambda self: self._core.strain(self.index), doc='accumulated (ex, ey, ez, gxy, gyz, gzx) [-]')
    rotation = property(lambda self: self._core.rotation(self.index), doc='rotation since creation (Quaternion)')
    fixed = property(lambda self: self._core.isFixed(self.index), doc='True for a fixed block (no unknowns)')
    rigid = property(lambda self: self._core.isRigid(self.index), doc='a rigid block: 6 unknowns, no strain or stress')
    partCount = property(lambda self: 1, doc='number of convex parts (concaveBlock: more than 1)')
    parts = property(lambda self: [self.vertices], doc="each convex part's current corners [m]")
    fixedPoints = property(lambda self: self._core.fixedPoints(self.index), doc='current fixed-point positions [m]')


class ConcaveBlockView(BlockView):
    """Read-only view of a concave block (concaveBlock): its state is its body's (SI units); its geometry is
    every part's. ``vertices`` lists the corners of all parts, part after part, and ``faces`` and ``edges``
    index into it (the faces the parts share are included, once per part); ``parts`` gives each part's
    corners alone."""

    partCount = property(lambda self: self._core.partCount(self.index), doc='number of convex parts')
    parts = property(lambda self: self._core.parts(self.index), doc="each part's current corners [m]")

    @property
    def vertices(self):
        return [x for part in self.parts for x in part]

    def _allParts(self, what):
        out, offset = [], 0
        for p in range(self.partCount):
            out.extend(tuple(v + offset for v in item) for item in what(self.index + p))
            offset += len(self._core.vertices(self.index + p))
        return out

    faces = property(lambda self: self._allParts(self._core.faces), doc='faces of every part, into vertices')
    edges = property(lambda self: self._allParts(self._core.edges), doc='edges of every part, into vertices')


class ContactView:
    """One vertex-face or edge-edge sub-contact at the end of the last step (SI units).

    ``id1``, ``id2``: body ids; id1 owns the vertex (kind 'VF') or the first
    edge ('EE'), id2 the entrance face or the second edge. ``type``: the
    structural type of the pair ('VV', 'VE', 'VF', 'EE', 'EEp', 'EF', 'FF').
    ``state``: 'open', 'sliding' or 'locked'. ``normal``: unit, from id2
    towards id1. ``point`` [m]: the contact point on id1. ``normalForce`` [N]:
    compressive normal force (>= 0). ``shearForce`` [N]: tangential force on
    id1 (shear spring when locked, friction when sliding). ``gap`` [m]: normal
    distance at the start of the step (< 0 penetrating). ``bonded``: an
    intact bonded joint (see ddaBlock's cohesion); its normalForce may be
    negative (tension).
    """

    __slots__ = ('id1', 'id2', 'kind', 'type', 'state', 'normal', 'point', 'normalForce', 'shearForce', 'gap',
                 'bonded')

    def __init__(self, *values):
        for name, value in zip(self.__slots__, values):
            setattr(self, name, value)

    @property
    def force(self):
        """Total contact force on id1 [N]: normalForce along normal plus shearForce."""
        return self.normal * self.normalForce + self.shearForce

    def __repr__(self):
        return ('<DDA contact %s %d-%d (%s) %s, N=%.4g N>'
                % (self.kind, self.id1, self.id2, self.type, self.state, self.normalForce))


def coupledSystem():
    """The coupled system K D = F of the last step's last solve, as NumPy arrays.

    One row per moving block that closed contacts or fixed points couple
    (a block row of 12 unknowns: translation [m], rotation [rad], normal and
    engineering shear strains, at its centroid; a rigid block's strain rows
    are not unknowns), and one link per pair of rows that a closed contact
    joins. A dict:

    - ``bodies``: the body id of each row (a list of n ints);
    - ``sizes``: (n,) its unknowns, 12, or 6 for a rigid block;
    - ``centroids``: (n, 3) the points its unknowns refer to [m];
    - ``diagonal``: (n, 12, 12) K's diagonal blocks (symmetric) [N/m, N, N m];
    - ``links``: (m, 2) the rows (lo, hi), lo < hi, of each off-diagonal block;
    - ``offDiagonal``: (m, 12, 12) K[lo][hi] (K[hi][lo] is its transpose);
    - ``force``: (n, 12) F [N, N m];
    - ``components``: (c + 1,) independent systems' first rows (component
      i is rows components[i] .. components[i+1]-1).

    Example: the dense matrix, and the solution the solve found::

        s = yade_dda.coupledSystem()
        n = len(s['bodies'])
        K = numpy.zeros((12 * n, 12 * n))
        for k, d in enumerate(s['diagonal']):
            K[12 * k:12 * k + 12, 12 * k:12 * k + 12] = d
        for (lo, hi), b in zip(s['links'], s['offDiagonal']):
            K[12 * lo:12 * lo + 12, 12 * hi:12 * hi + 12] = b
            K[12 * hi:12 * hi + 12, 12 * lo:12 * lo + 12] = b.T
        D = numpy.linalg.solve(K, s['force'].ravel()).reshape(n, 12)

    (With rigid blocks, strike their strain rows and columns first.)
    """
    import numpy
    scene = _require()
    raw = scene.core.coupledSystem()
    n, m = raw['rows'], raw['links']
    bodyOf = scene.bodyOfBlock
    blocks = numpy.frombuffer(raw['blocks'], dtype=numpy.int32)
    return dict(bodies=[int(bodyOf[b]) for b in blocks],
                sizes=numpy.frombuffer(raw['sizes'], dtype=numpy.int32).copy(),
                centroids=numpy.frombuffer(raw['centroids'], dtype=numpy.float64).reshape(n, 3).copy(),
                diagonal=numpy.frombuffer(raw['diagonal'], dtype=numpy.float64).reshape(n, 12, 12).copy(),
                links=numpy.frombuffer(raw['linkRows'], dtype=numpy.int32).reshape(m, 2).copy(),
                offDiagonal=numpy.frombuffer(raw['offDiagonal'], dtype=numpy.float64).reshape(m, 12, 12).copy(),
                force=numpy.frombuffer(raw['force'], dtype=numpy.float64).reshape(n, 12).copy(),
                components=numpy.frombuffer(raw['componentStarts'], dtype=numpy.int32).copy())


def contacts(state=None):
    """The DDA sub-contacts of the last step as a list of ContactView.

    ``state`` ('open', 'sliding', 'locked' or 'closed' for the last two)
    filters the list. Example::

        for c in contacts('closed'):
            print(c.id1, c.id2, c.type, c.normalForce)
    """
    scene = _require()
    if state not in (None, 'open', 'sliding', 'locked', 'closed'):
        raise ValueError("state must be None, 'open', 'sliding', 'locked' or 'closed', got %r" % (state,))
    bodyOf = scene.bodyOfBlock
    out = []
    for i, j, kind, ctype, cstate, normal, point, fn, fs, gap, bonded in scene.core.contacts():
        if state is not None and cstate != state and not (state == 'closed' and cstate != 'open'):
            continue
        out.append(ContactView(bodyOf[i], bodyOf[j], kind, ctype, cstate, normal, point, fn, fs, gap, bonded))
    return out


class Ig2_DDABlock_DDABlock_DDAContact:
    """The pair functor of the DDA narrow phase (YADE's Ig2 naming), callable on
    any two DDA blocks at their current geometry.

    ``go(body1, body2, contactDistance)`` [m] returns None when the blocks are
    farther apart than the contact distance, else a dict: ``type`` (structural
    type of Wu et al.'s Table 1: 'VV', 'VE', 'VF', 'EE', 'EEp', 'EF', 'FF'),
    ``normal`` (entrance normal, unit, from body1 towards body2),
    ``separation`` [m] (the largest over the separating axes tested, face
    normals and crossing edges: > 0 apart, a lower bound of the distance that
    equals it unless the closest features are corners or a corner and an
    edge; <= 0 overlapping or touching, minus the penetration depth),
    ``entranceSeparation`` [m] (along the entrance normal; the entrance rules
    prefer faces, so it may be negative for blocks that are apart, a corner
    beside an edge) and ``contacts``: the
    vertex-face ('VF', the Ig2_Vertex_Face sub-functor) and edge-edge ('EE',
    Ig2_Edge_Edge) sub-contacts, each a dict with ``kind``, ``id1``/``id2``
    (id1 owns the vertex or first edge), ``feature1``/``feature2`` (vertex,
    face or edge indices as in ``block(body).faces``/``.edges``), ``gap`` [m],
    ``normal`` (from id2 towards id1), ``point1``/``point2`` [m].
    The integrator runs the same functor every step. For a concave block give
    the members' ids (each its part); the clump's id stands for its first part. Example::

        print(Ig2_DDABlock_DDABlock_DDAContact().go(b1, b2, 0.01))
    """

    def go(self, body1, body2, contactDistance=0.0):
        """The pair's contact at the blocks' current geometry within contactDistance [m] (a dict, see the
        class), or None when they are farther apart."""
        scene = _require()
        # A concave block's member: its own part (the clump stands for its first part).
        scene.blockIndex(body1), scene.blockIndex(body2)   # KeyError for a body that is no DDA block
        i, j = scene.core.partOfBody(_bodyId(body1)), scene.core.partOfBody(_bodyId(body2))
        try:
            contactDistance = float(contactDistance)
        except (TypeError, ValueError):
            raise TypeError('contactDistance must be a number [m], got %r' % (contactDistance,)) from None
        result = scene.core.detectPair(i, j, contactDistance)
        if result is None:
            return None
        ctype, normal, separation, entranceSeparation, subs = result
        bodyOf = scene.bodyOfBlock
        return dict(type=ctype, normal=normal, separation=separation, entranceSeparation=entranceSeparation,
                    contacts=[dict(kind=kind, id1=bodyOf[bi], id2=bodyOf[bj], feature1=f1, feature2=f2, gap=gap,
                                   normal=n, point1=p1, point2=p2)
                              for kind, bi, bj, f1, f2, gap, n, p1, p2 in subs])


def block(body):
    """The core state of a DDA body (a Body or its id) as a BlockView."""
    scene = _require()
    index = scene.blockIndex(body)
    return ConcaveBlockView(scene, index) if scene.core.partCount(index) > 1 else BlockView(scene, index)


def blockOf(body):
    """Block index of a DDA body, or None for a body that is not a DDA block."""
    scene = current(create=False)
    if scene is None:
        return None
    bodyId = _bodyId(body)
    scene.resolvePending()
    return scene.core.blockOfBody(bodyId)


def setVelocity(body, velocity=(0, 0, 0), angularVelocity=(0, 0, 0)):
    """Sets a block's velocity [m/s] and angular velocity [rad/s]; strain rates become zero."""
    scene = _require()
    index = scene.blockIndex(body)
    scene.core.setVelocity(index, velocity, angularVelocity)


def addPointLoad(body, point, force):
    """Adds a constant force [N] at a material point [m] of a block."""
    scene = _require()
    scene.core.addPointLoad(scene.blockIndex(body), point, force)


def addFixedPoint(body, point, stiffness=0):
    """Holds the material point now at point [m] with a penalty spring [N/m] (0: default)."""
    scene = _require()
    stiffness = float(stiffness)
    if not (stiffness >= 0 and stiffness < float('inf')):
        raise ValueError('fixed point stiffness must be finite and >= 0 N/m (0: default), got %r' % stiffness)
    scene.core.addFixedPoint(scene.blockIndex(body), point, stiffness)
