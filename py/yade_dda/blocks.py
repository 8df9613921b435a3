"""Making DDA blocks: YADE bodies with a Polyhedra shape, backed by the DDA core."""
import math
import random

from ._yade import O, utils, wrapper
from . import _core
from . import scene as _scene
from .params import vector


class BlockSpec:
    """What the core needs to build a block once its body is in O.bodies."""

    # points: the corners as given to YADE's Polyhedra, i.e. shifted by `shift` (None: not shifted; see
    # _nearOrigin). The block's corners are corners(): the shift adds back exactly.
    __slots__ = ('points', 'shift', 'density', 'young', 'poisson', 'frictionAngle', 'cohesion', 'tensileStrength',
                 'fixed', 'rigid', 'fixedPoints', 'loads', 'stress')

    def __init__(self, **kw):
        for cls in type(self).__mro__:
            for key in getattr(cls, '__slots__', ()):
                setattr(self, key, kw.get(key))

    def corners(self):
        """The block's corners [m], as given to ddaBlock."""
        if self.shift is None:
            return self.points
        x, y, z = self.shift
        return [(p[0] + x, p[1] + y, p[2] + z) for p in self.points]


_PALETTE = random.Random(20140101)
"""Colours of blocks made without one: a generator of our own, so Python's ``random`` (which YADE's
``randomColor`` draws from) is left alone and a script's colours are the same on every run."""


def _nextColor():
    return tuple(_PALETTE.random() for _ in range(3))


def _finiteNonNegative(value, what, unit):
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise TypeError('%s must be a number [%s], got %r' % (what, unit, value)) from None
    if not (math.isfinite(value) and value >= 0):
        raise ValueError('%s must be finite and >= 0 %s, got %r' % (what, unit, value))
    return value


def _points(vertices):
    if hasattr(vertices, 'corners') and not hasattr(vertices, '__len__'):
        vertices = vertices.corners   # a RockBlock of cutRockMass: its corners
    try:
        items = list(vertices)
    except TypeError:
        raise TypeError('vertices must be a sequence of points, got %r' % (vertices,)) from None
    points = []
    for i, p in enumerate(items):
        try:
            coords = [float(x) for x in p]
        except (TypeError, ValueError):
            raise TypeError('point %d must be a sequence of 3 numbers, got %r' % (i, p)) from None
        if len(coords) != 3:
            raise ValueError('point %d must have 3 coordinates, got %d' % (i, len(coords)))
        # YADE's converter of a point list (Polyhedra(v=...) in utils.polyhedron) keeps a reference to every
        # item it reads and never drops it, so an item made here would never be freed (64 bytes a point,
        # 26 MB on 50,000 boxes). A point that is already a tuple of 3 floats is passed on as it is.
        points.append(p if type(p) is tuple and all(type(x) is float for x in p) else tuple(coords))
    return points


def _nearOrigin(points):
    """The corners shifted near the origin, exactly, and the shift [m] (None when no axis needs one).

    YADE's Polyhedra joins two hull facets when their planes, as unit 4-vectors
    (a, b, c, d)/|(a, b, c, d)|, differ by less than 1e-9 (squared norm): far
    from the origin d dominates and faces at an angle theta merge once their
    distance from the origin exceeds about theta / 3e-5 m, e.g. a cube's faces
    from 5e4 m. The joined faces are not planar; YADE's volume, centroid and
    inertia come out wrong (a turned 1 m cube at 1e4 m: volume 4/3), or the
    hull collapses to nothing (0 corners, most blocks at 1e5 m). Shifted near
    the origin, the test sees the block's own dihedral angles. Per axis the
    shift is the corners' smallest coordinate when all lie within a factor 2 of
    it (then every difference is exact, Sterbenz), else 0 (the block then
    reaches within its own extent of the origin on that axis).
    """
    shift = []
    # p - shift is exact, so shift + (p - shift) gives p back exactly (BlockSpec.corners).
    for axis in range(3):
        lo = min(p[axis] for p in points)
        hi = max(p[axis] for p in points)
        if 0 < lo and hi <= 2 * lo:
            shift.append(lo)
        elif hi < 0 and lo >= 2 * hi:
            shift.append(hi)
        else:
            shift.append(0.0)
    if not any(shift):
        return points, None
    return [(p[0] - shift[0], p[1] - shift[1], p[2] - shift[2]) for p in points], tuple(shift)


def _material(material):
    """Resolves YADE's ways of naming a material: None (default), id, label or instance."""
    if material is None:
        return wrapper.PolyhedraMat()
    if isinstance(material, bool):
        raise TypeError('material must be a YADE Material, its id or its label, got %r' % (material,))
    if isinstance(material, int):
        if not 0 <= material < len(O.materials) and not -len(O.materials) <= material < 0:
            raise IndexError('no material with id %d (O.materials has %d)' % (material, len(O.materials)))
        return O.materials[material]
    if isinstance(material, str):
        for m in O.materials:
            if m.label == material:
                return m
        raise KeyError('no material labelled %r in O.materials' % material)
    if callable(material) and not isinstance(material, wrapper.Material):
        return _material(material())
    if not isinstance(material, wrapper.Material):
        raise TypeError('material must be a YADE Material, its id or its label, got %r' % (material,))
    return material


def _elasticConstants(material):
    missing = [name for name in ('density', 'young', 'poisson') if not hasattr(material, name)]
    if missing:
        raise TypeError('material %s has no %s; use PolyhedraMat (or another elastic material)'
                        % (type(material).__name__, ', '.join(missing)))
    # Materials without friction (plain ElastMat) make frictionless joints.
    friction = float(getattr(material, 'frictionAngle', 0.0))
    return float(material.density), float(material.young), float(material.poisson), friction


def boxCorners(lower, upper):
    """The 8 corners [m] of the axis-aligned box from corner `lower` (x0, y0, z0) to `upper` (x1, y1, z1),
    for ``ddaBlock`` or a ``cutRockMass`` domain. ValueError unless every coordinate is finite and
    lower < upper on every axis. Example::

        O.bodies.append(ddaBlock(boxCorners((0, 0, 0), (1, 2, 3)), material=rock))
    """
    try:
        lo, hi = [tuple(float(x) for x in p) for p in (lower, upper)]
    except (TypeError, ValueError):
        raise TypeError('boxCorners takes two points (x, y, z) [m], got %r and %r' % (lower, upper)) from None
    if len(lo) != 3 or len(hi) != 3:
        raise ValueError('boxCorners takes two points (x, y, z) [m], got %r and %r' % (lower, upper))
    for axis, a, b in zip('xyz', lo, hi):
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise ValueError('boxCorners: %s from %r to %r is not a finite, positive extent [m]' % (axis, a, b))
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def ddaBlock(vertices, material=None, fixed=False, color=None, velocity=(0, 0, 0),
             angularVelocity=(0, 0, 0), fixedPoints=(), loads=(), stress=None, mask=1, wire=False,
             cohesion=0.0, tensileStrength=0.0, rigid=False, hull=False):
    """A DDA block as a YADE Body, ready for ``O.bodies.append``.

    The block is the convex polyhedron whose corners are ``vertices`` [m]
    (every point must be a corner). Its volume, centroid and second moments are
    exact integrals; the body's mass and inertia follow from them and the
    material's density. The body carries a ``Polyhedra`` shape, so YADE's GUI,
    VTK export and ``O.bodies`` see it like any polyhedron.

    :param vertices: corner points [m], at least 4, not coplanar; or a
        ``RockBlock`` of ``cutRockMass``, taken as its ``corners``.
    :param material: a ``PolyhedraMat`` (or other elastic material with
        ``young`` [Pa], ``poisson`` and ``density`` [kg/m^3]), its id in
        ``O.materials`` or its label; None makes a default ``PolyhedraMat``.
        Its ``frictionAngle`` [rad] is the joint friction of the block's
        contacts (a contact takes the smaller angle of its two blocks). Note
        YADE's default ``frictionAngle`` is 0.5 rad; set 0 for frictionless
        joints.
    :param fixed: a fixed block never moves and has no unknowns.
    :param rigid: a rigid block (a bool) has 6 unknowns, the translation [m]
        and rotation [rad] of its centroid, instead of 12: no strain, no
        stress, no elastic term, and the solver factorises 6 rows for it
        instead of 12. Its material's ``young`` [Pa] still sets the stiffness
        of its contacts (``contactPenaltyFactor x`` the smaller ``E x size``
        of the two blocks). A rigid block cannot take ``stress``. Use it for
        blocks whose strain ``stress/E`` is negligible against the motion of
        interest. For every block of a material, see ``rigidBlock``.
    :param velocity: initial velocity of the centroid [m/s].
    :param angularVelocity: initial angular velocity [rad/s].
    :param fixedPoints: material points [m] held by penalty springs; each entry
        a point, or ``(point, stiffness)`` with stiffness in N/m (0 = default,
        see ``DDAIntegrator.fixedPointPenaltyFactor``).
    :param loads: ``(point, force)`` pairs: constant forces [N] at material points [m].
    :param stress: initial stress (sxx, syy, szz, sxy, syz, szx) [Pa].
    :param mask: YADE groupMask of the body.
    :param cohesion: joint cohesion [Pa] of the block's contacts that are
        closed when the scene starts (bonded joints); a contact takes the
        smaller value of its two blocks and its share of the pair's contact
        area. A bond breaks for good when shear exceeds friction plus
        cohesion x area, or tension exceeds tensileStrength x area.
    :param tensileStrength: joint tensile strength [Pa] of bonded joints.
    :param hull: True: the block is the convex hull of ``vertices``, any
        points (a bool). Points inside the hull, repeats, and points on its
        surface that are no corner (inside a face or an edge, or a corner so
        flat that YADE's ``Polyhedra`` or the core merges the faces around
        it, within 1e-9 of the bounding-box diagonal) are left out, so the YADE shape
        and the DDA block have the same corners. The block's volume is the
        hull's, less what those merges cut off: at most the merge tolerance
        times the hull's area. ``block(body).vertices`` are the corners kept.

    Raises ValueError naming the problem for bad geometry (fewer than 4 points,
    coplanar, duplicated, NaN/inf, a point that is not a corner of the hull),
    bad material constants, non-finite vectors, or an initial stress on a
    rigid block; TypeError for a ``rigid`` that is not a bool; nothing is
    added then.

    Example::

        b = O.bodies.append(ddaBlock([(0,0,0),(1,0,0),(0,1,0),(1,1,0),(0,0,1),(1,0,1),(0,1,1),(1,1,1)],
                                     material=mat, velocity=(1, 0, 0)))
    """
    if not isinstance(hull, bool):
        raise TypeError('hull must be True or False, got %r' % (hull,))
    points = _points(vertices)
    if hull:
        points = [points[i] for i in _core.hullCorners(points)]
    o = _options(material, fixed, rigid, velocity, angularVelocity, fixedPoints, loads, stress, mask, color,
                 cohesion, tensileStrength)
    _checkCorners(points, o.constants, hull)
    _requireYadeSize(points)
    body, corners, yadePoints, shift = _body(points, hull, dict(fixed=fixed, wire=wire, color=o.color,
                                                                 material=o.material, mask=mask))
    if len(corners) != len(points):   # hull=True, and YADE merged corners away
        _core.checkBlock(corners, *o.constants)
    if not fixed:
        body.state.vel = o.velocity
        body.state.angVel = o.angularVelocity
    spec = BlockSpec(points=yadePoints, shift=shift, **o.spec())
    _scene.current().register(body, spec)
    return body


_NOT_A_CORNER = ('strictly inside the hull', 'on the hull surface but is not a corner')
"""The core's refusals (ConvexPolyhedron.cpp) of a point that is no corner of the points' convex hull."""


def _checkCorners(points, constants, hull):
    """The core's check of a block's corners; where a point is no corner of the hull (concave points,
    e.g. an L's), the refusal also names the ways out: concaveBlock, and hull=True."""
    try:
        _core.checkBlock(points, *constants)
    except ValueError as error:
        if hull or not any(text in str(error) for text in _NOT_A_CORNER):
            raise
        raise ValueError('%s. These points are not the corners of a convex polyhedron: for a concave block use '
                         'concaveBlock(parts) (convex parts) or concaveBlock(surface=(points, triangles)); for the '
                         'convex hull of the points pass ddaBlock(..., hull=True)' % error) from None


class _Options:
    """The keywords ddaBlock and concaveBlock share, checked (see _options)."""

    def __init__(self, **kw):
        self.__dict__.update(kw)

    def spec(self):
        """The BlockSpec fields other than the corners."""
        # Tuples: the spec waits in the scene's pending list until the body is appended, for every block of a
        # scene built in one go, and an empty tuple is one shared object where an empty list is 56 bytes a block.
        return dict(density=self.density, young=self.young, poisson=self.poisson, frictionAngle=self.frictionAngle,
                    cohesion=self.cohesion, tensileStrength=self.tensileStrength, fixed=self.fixed,
                    rigid=self.rigid, fixedPoints=tuple(self.fixedPoints), loads=tuple(self.loads),
                    stress=self.stress)


def _options(material, fixed, rigid, velocity, angularVelocity, fixedPoints, loads, stress, mask, color, cohesion,
             tensileStrength):
    """Checks the keywords a block shares with every other; raises TypeError or ValueError naming the problem."""
    if not isinstance(rigid, bool):
        raise TypeError('rigid must be True or False, got %r' % (rigid,))
    mat = _material(material)
    density, young, poisson, frictionAngle = _elasticConstants(mat)
    cohesion = _finiteNonNegative(cohesion, 'cohesion', 'Pa')
    tensileStrength = _finiteNonNegative(tensileStrength, 'tensileStrength', 'Pa')
    velocity = vector(velocity, 'velocity')
    angularVelocity = vector(angularVelocity, 'angularVelocity')
    if fixed and (any(velocity) or any(angularVelocity)):
        raise ValueError('a fixed block cannot have an initial velocity')
    try:
        fixedPoints, loads = list(fixedPoints), list(loads)
    except TypeError:
        raise TypeError('fixedPoints and loads must be sequences, got %r and %r' % (fixedPoints, loads)) from None
    if fixed and (fixedPoints or loads):
        raise ValueError('a fixed block cannot have fixed points or point loads (they would have no effect)')
    fixedList = []
    for i, entry in enumerate(fixedPoints):
        if not hasattr(entry, '__len__'):
            raise TypeError('fixed point %d must be a point or (point, stiffness), got %r' % (i, entry))
        if len(entry) == 2 and not isinstance(entry[0], (int, float)):
            point, stiffness = entry
        else:
            point, stiffness = entry, 0.0
        point = vector(point, 'fixed point %d' % i)
        stiffness = _finiteNonNegative(stiffness, 'fixed point %d stiffness' % i, 'N/m')
        fixedList.append((point, stiffness))
    loadList = []
    for i, entry in enumerate(loads):
        try:
            point, force = entry
        except (TypeError, ValueError):
            raise TypeError('load %d must be a pair (point [m], force [N]), got %r' % (i, entry)) from None
        loadList.append((vector(point, 'load %d point' % i), vector(force, 'load %d force' % i)))
    if stress is not None:
        stress = vector(stress, 'stress', 6)
        if rigid and any(stress):
            raise ValueError('a rigid block has no strain and carries no stress; got stress=%r [Pa] with rigid=True '
                             '(make the block deformable, or drop the stress)' % (stress,))
    if not isinstance(mask, int) or isinstance(mask, bool):
        raise TypeError('mask must be an int, got %r' % (mask,))
    color = vector(color, 'color') if color is not None else _nextColor()
    return _Options(material=mat, density=density, young=young, poisson=poisson, frictionAngle=frictionAngle,
                    cohesion=cohesion, tensileStrength=tensileStrength, fixed=bool(fixed), rigid=rigid,
                    velocity=velocity, angularVelocity=angularVelocity, fixedPoints=fixedList, loads=loadList,
                    stress=stress, color=color,
                    constants=(density, young, poisson, frictionAngle, cohesion, tensileStrength))


MAX_EXTENT = 1e4
"""The largest extent of a block [m] (its corners' largest bounding-box side) that YADE's Polyhedra
carries: measured on YADE 2023.02a with random 30-point clouds, its absolute tolerances drop true corners
from about 1e4 m (ddaBlock then refuses the block, or with hull=True drops them too) and from about 1e5 m
its hull hangs or corrupts the heap (malloc aborts the process). Refused before YADE sees the block."""


def _requireYadeSize(points):
    extent = max(max(p[k] for p in points) - min(p[k] for p in points) for k in range(3))
    if not extent <= MAX_EXTENT:
        raise ValueError('the block is %g m across (the largest side of its corners\' bounding box), more than the '
                         '%g m YADE\'s Polyhedra can carry (its absolute tolerances drop true corners of larger '
                         'blocks, and from about 1e5 m its hull hangs or crashes); split it into blocks of at most '
                         '%g m' % (extent, MAX_EXTENT, MAX_EXTENT))


def _body(points, hull, options):
    """(body, corners, YADE's corners, shift): the YADE body with a Polyhedra shape of `points` [m].

    YADE's shape is made from the corners shifted near the origin (see _nearOrigin); the body is then put
    back: pos = shift + YADE's centroid (rounded; SceneLink's vertex match allows for it). The spec keeps
    the shifted tuples, which YADE's converter keeps anyway (see _points), and the shift, not a second copy.
    YADE's Polyhedra builds its own hull with its own, absolute tolerances (a 1e9 m cube lost a corner);
    its distance from the origin no longer matters (the corners were shifted), its size does. A corner it
    merges away refuses the block, or with `hull` drops that corner too (the hull of what YADE kept, which
    the core accepts as it is: a subset of a hull's corners)."""
    for attempt in range(4):
        yadePoints, shift = _nearOrigin(points)
        body = utils.polyhedron(yadePoints, **options)
        if shift is not None:
            pos = body.state.pos
            body.state.pos = body.state.refPos = (pos[0] + shift[0], pos[1] + shift[1], pos[2] + shift[2])
        if len(body.shape.v) == len(points):
            return body, points, yadePoints, shift
        if not hull:
            break
        kept = _cornersYadeKept(body, points)
        points = [kept[i] for i in _core.hullCorners(kept)]
    raise ValueError('YADE\'s Polyhedra shape of this block has %d corners instead of %d (YADE merged corners '
                     'its own absolute tolerances cannot tell apart, for a block of this size); rescale the block'
                     '%s' % (len(body.shape.v), len(points), '' if hull else ', or pass hull=True to drop them'))


def _cornersYadeKept(body, points):
    """The points [m] nearest to the corners of the body's Polyhedra, in input order."""
    pos, ori = body.state.pos, body.state.ori
    kept = set()
    for v in body.shape.v:
        x = pos + ori * v
        kept.add(min(range(len(points)), key=lambda i: sum((points[i][k] - x[k]) ** 2 for k in range(3))))
    return [points[i] for i in sorted(kept)]


def rigidBlock(vertices, material=None, **kw):
    """``ddaBlock(vertices, material, rigid=True, **kw)``: a block with 6 unknowns.

    Rigidity is chosen per block, not by the material: the material's
    ``young`` [Pa] still sets the stiffness of the block's contacts, so no
    value of it can mean "does not deform" without also changing the contacts,
    and YADE does not save extra attributes of a material. To make every block
    of one material rigid, build them all with this function (or pass
    ``rigid=True``). Example::

        rock = O.materials.append(PolyhedraMat(young=1e10, poisson=0.25, density=2600))
        b = O.bodies.append(rigidBlock(corners, material=rock))
    """
    return ddaBlock(vertices, material=material, rigid=True, **kw)


class ConcaveSpec(BlockSpec):
    """A concave block waiting for its clump: its parts' corners as given to YADE (each shifted by its own
    shift, see _nearOrigin) and the member bodies, in part order."""

    __slots__ = ('parts', 'members')

    def partCorners(self):
        """The corners of each part [m], as given to concaveBlock."""
        return [BlockSpec(points=points, shift=shift).corners() for points, shift in self.parts]


def concaveBlock(parts=None, material=None, fixed=False, color=None, velocity=(0, 0, 0), angularVelocity=(0, 0, 0),
                 fixedPoints=(), loads=(), stress=None, mask=1, wire=False, cohesion=0.0, tensileStrength=0.0,
                 rigid=False, surface=None):
    """A concave DDA block made of convex parts, as the member bodies of a YADE clump:
    ``O.bodies.appendClumped(concaveBlock(parts, ...))`` returns ``(clumpId, memberIds)``.

    It is one DDA block (Wu et al. 2014, Section 4): 12 unknowns (6 when
    ``rigid``), one stress and strain, mass, centroid and inertia exact for
    the union of the parts; the parts never contact each other, and the faces
    they share are inside the block (no contact is made on them). Each part
    is a member body with a ``Polyhedra`` shape (what YADE draws and exports);
    the clump stands for the block: ``block(clumpId)`` (or a member's id)
    gives its state, the sync writes the clump's position (the block's
    centroid), orientation and velocity, and the members' own. Contacts, and
    the interactions in ``O.interactions``, are between members, as for
    YADE's clumps; ``O.forces`` holds each member's contact forces and the
    clump's point loads and fixed points.

    :param parts: a list of convex parts, each a list of corner points [m]
        (every point a corner, as for ``ddaBlock``). They must meet face to
        face without overlapping and make one piece. Where two parts share
        only part of each other's faces (staggered bricks), one is split
        along the other's face edges (``conformParts`` in the core), so the
        block may have more parts, and members, than given:
        ``block(clumpId).partCount``. A part alone makes a convex block.
    :param surface: instead of ``parts``, ``(points, triangles)``: a closed
        triangulated surface (points [m], triangles as index triples, either
        orientation) bounding the block, any shape without self-intersection;
        it is split into convex parts with CGAL's exact
        ``convex_decomposition_3`` (cuts through the reflex edges), then as
        above. ValueError names an open, non-manifold or self-intersecting
        surface.
    :param material, fixed, color, velocity, angularVelocity, fixedPoints, loads, stress, mask, wire, cohesion,
        tensileStrength, rigid: as for ``ddaBlock``, for the block as a whole
        (velocities of its centroid [m/s] and about it [rad/s]). ``hull`` is
        not offered: a part's corners are taken as given.

    Raises ValueError naming the part and the problem (a part that is not a
    convex polyhedron, two parts that overlap or do not make one piece) and TypeError for bad keyword types; nothing is made
    then. At the first step a ValueError is raised if the members were not
    appended together with ``O.bodies.appendClumped``.

    Example (an L of three unit cubes)::

        cube = lambda x, y: [(x+i, y+j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]
        clumpId, members = O.bodies.appendClumped(concaveBlock([cube(0, 0), cube(1, 0), cube(0, 1)]))
        print(block(clumpId).volume)   # 3.0
    """
    if (parts is None) == (surface is None):
        raise TypeError('concaveBlock takes parts or surface=(points, triangles), exactly one of them')
    if surface is not None:
        try:
            surfacePoints, triangles = surface
        except (TypeError, ValueError):
            raise TypeError('surface must be (points, triangles), got %r' % (surface,)) from None
        parts = _core.convexDecomposition(_points(surfacePoints), [tuple(t) for t in triangles])
    try:
        partList = list(parts)
    except TypeError:
        raise TypeError('parts must be a list of corner lists, got %r' % (parts,)) from None
    points = []
    for k, corners in enumerate(partList):
        try:
            points.append(_points(corners))
        except (TypeError, ValueError) as error:
            raise type(error)('part %d: %s' % (k, error)) from None
    o = _options(material, fixed, rigid, velocity, angularVelocity, fixedPoints, loads, stress, mask, color,
                 cohesion, tensileStrength)
    points = [[tuple(x) for x in part] for part in _core.conformParts(points)]
    _core.checkConcaveBlock(points, *o.constants)
    for part in points:
        _requireYadeSize(part)
    members, shifted = [], []
    for part in points:
        body, _, yadePoints, shift = _body(part, False, dict(fixed=fixed, wire=wire, color=o.color,
                                                             material=o.material, mask=mask))
        if not fixed:
            body.state.vel = o.velocity
            body.state.angVel = o.angularVelocity
        members.append(body)
        shifted.append((yadePoints, shift))
    spec = ConcaveSpec(parts=tuple(shifted), members=tuple(members), **o.spec())
    _scene.current().register(members[0], spec)
    return members
