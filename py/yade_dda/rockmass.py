"""Rock masses cut by joint sets: ``cutRockMass`` (doc/rock-mass.md).

The core (pkg/dda/geometry/RockMassCutter.hpp) cuts exactly: every corner is
the exact intersection of three planes, rounded toward zero, so neighbouring
blocks share faces bit for bit. This module checks the user's input, names
what is wrong, and wraps the result. Units: m, m^3; angles in degrees.
"""
import gc
import hashlib
import math
import numbers

from . import _core
from ._yade import O
from .blocks import ddaBlock, concaveBlock
from .params import isPoint

_SET_KEYS = ('dip', 'dipDirection', 'spacing', 'origin', 'persistence', 'fisherK', 'spacingDistribution',
             'spacingStd')
_SET_REQUIRED = ('dip', 'dipDirection', 'spacing')
_PLANE_KEYS = ('plane', 'persistence')
_EXCAVATE_KEYS = ('excavate',)
_DISTRIBUTIONS = ('fixed', 'exponential', 'lognormal')
_JOINT_KINDS = ('set', 'joint')


class RockPlane:
    """A plane of the cut: ``normal . x = offset`` [m] (normal as given, not unit length).

    ``kind``: 'bound' (the box the cut starts from; never bounds a block), 'domain' (a face of domain
    part ``source``, face ``number``), 'set' (plane ``number`` of joint set ``source``, 0 through its
    origin, counted along the pole), 'joint' (the single joint ``source``) or 'excavation' (entry
    ``source``; its normal points out of the removed region). ``source`` indexes the ``jointSets`` list
    for the last three."""
    __slots__ = ('kind', 'source', 'number', 'normal', 'offset', 'persistence')

    def __init__(self, kind, source, number, normal, offset, persistence):
        self.kind, self.source, self.number = kind, source, number
        self.normal, self.offset, self.persistence = normal, offset, persistence

    def __repr__(self):
        return 'RockPlane(%r, source=%d, number=%d, normal=%r, offset=%r)' % (
            self.kind, self.source, self.number, self.normal, self.offset)


class RockBlock:
    """One block of a cut rock mass.

    ``corners``: list of (x, y, z) [m], ready for ``ddaBlock(corners)``; ``faces``: tuples of corner
    indices, counter-clockwise seen from outside; ``planes``: the plane (index into
    ``RockMass.planes``) of each face; ``joints``: those of them that are joints (kind 'set' or
    'joint'), sorted; ``volume`` [m^3]; ``part``: the domain part it was cut from; ``cornerPlanes``:
    for each corner the three planes whose exact intersection it is; ``problem``: for a sliver, why it
    was neither kept nor merged ('' for a block)."""
    __slots__ = ('corners', 'faces', 'planes', 'joints', 'volume', 'part', 'cornerPlanes', 'problem')

    def __init__(self, raw, planes):
        self.part, self.corners, self.faces, self.planes, self.volume, self.problem, self.cornerPlanes = raw
        self.joints = tuple(sorted({p for p in self.planes if planes[p].kind in _JOINT_KINDS}))

    def __repr__(self):
        return 'RockBlock(part=%d, %d corners, %d faces, volume=%.6g m^3)' % (
            self.part, len(self.corners), len(self.faces), self.volume)


class RockMass:
    """The result of ``cutRockMass``: a sequence of ``RockBlock`` (``len``, iteration, indexing).

    ``blocks``: the blocks; ``slivers``: blocks below ``minVolume`` (or whose corners ddaBlock would
    refuse) that no convex merge could take, each with its ``problem`` -- not in ``blocks``, never
    dropped; ``merged``: how many slivers were merged into a neighbour; ``planes``: every plane of the
    cut (``RockPlane``); ``domainVolume`` [m^3] of the domain before excavation; ``minVolume`` [m^3] as
    applied; ``seed``; ``stats``: counts and phase times [s] of the cut; ``groups``: the DDA blocks as
    tuples of indices into ``blocks`` (one for a convex block, several for a concave one of
    ``concave=True``); ``jointArea`` and ``absentArea`` [m^2]: with ``concave=True``, the touching area
    of non-persistent joint planes and the part of it where the joint is absent (rock bridges)."""

    def __init__(self, raw, seed):
        self.planes = [RockPlane(*p) for p in raw['planes']]
        self.blocks = [RockBlock(b, self.planes) for b in raw['blocks']]
        self.slivers = [RockBlock(b, self.planes) for b in raw['slivers']]
        self.domainVolume = raw['domainVolume']
        self.minVolume = raw['minVolume']
        self.stats = raw['stats']
        self.merged = self.stats['mergedSlivers']
        self.seed = seed
        # The DDA blocks, each a tuple of block indices: one for a convex block, several for a concave
        # one (cutRockMass(..., concave=True) joins them).
        self.groups = [(i,) for i in range(len(self.blocks))]
        self.jointArea = self.absentArea = 0.0   # concave=True: non-persistent joints' touching area [m^2]

    def __len__(self):
        return len(self.blocks)

    def __iter__(self):
        return iter(self.blocks)

    def __getitem__(self, i):
        return self.blocks[i]

    def __repr__(self):
        concave = sum(len(g) > 1 for g in self.groups)
        return 'RockMass(%d blocks, %d slivers, %d merged, domain %.6g m^3%s)' % (
            len(self.blocks), len(self.slivers), self.merged, self.domainVolume,
            ', %d concave blocks' % concave if concave else '')

    def ddaBlocks(self, **kw):
        """``[ddaBlock(b.corners, **kw) for b in self.blocks]``: bodies for ``O.bodies.append``, one per
        convex block (the parts of a concave block each alone; see ``append`` for the blocks as grouped)."""
        return [ddaBlock(b.corners, **kw) for b in self.blocks]

    def append(self, fixed=False, **kw):
        """Appends every block of ``groups`` to ``O.bodies``: a single block with ``ddaBlock``, a group of
        several (a concave block) with ``O.bodies.appendClumped(concaveBlock(parts))``. ``fixed``: a bool,
        or a function of the group's ``RockBlock`` list returning one; other keywords go to ``ddaBlock`` /
        ``concaveBlock`` (``material=...``). Returns the body id of each group, in order: the clump's id
        for a concave block (what ``block()`` takes)."""
        ids = []
        for group in self.groups:
            blocks = [self.blocks[i] for i in group]
            isFixed = fixed(blocks) if callable(fixed) else fixed
            if len(group) == 1:
                ids.append(O.bodies.append(ddaBlock(blocks[0].corners, fixed=isFixed, **kw)))
            else:
                ids.append(O.bodies.appendClumped(concaveBlock([b.corners for b in blocks], fixed=isFixed, **kw))[0])
        return ids

    def _join(self, persistences):
        """groups for concave=True: blocks joined across the faces the domain's parts share (no joint there)
        and across the faces of a non-persistent joint plane where the joint is absent (a draw per pair of
        touching blocks: absent with probability 1 - persistence)."""
        n = len(self.blocks)
        root = list(range(n))

        def find(i):
            while root[i] != i:
                root[i] = root[root[i]]
                i = root[i]
            return i

        identity = [tuple(sorted(b.planes)) for b in self.blocks]   # a block is known by its planes
        joints = [(p, _unitPlane(p)) for p in self.planes if p.kind in _JOINT_KINDS]
        tolerance = 1e-9 * self.domainVolume ** (1.0 / 3.0)
        self.jointArea = self.absentArea = 0.0
        for a, f, b, g, area in _core.sharedFaces([(blk.corners, blk.faces) for blk in self.blocks]):
            plane = self.planes[self.blocks[a].planes[f]]
            if plane.kind == 'domain':
                # The boundary between two domain parts is no joint, unless a joint plane lies on it.
                plane = _jointOn(plane, joints, tolerance) or plane
            if plane.kind == 'domain':
                join = True
            elif plane.kind in _JOINT_KINDS and persistences[plane.source] < 1:
                draw = _uniform(self.seed, self.blocks[a].planes[f], *sorted((identity[a], identity[b])))
                join = draw >= persistences[plane.source]
                self.jointArea += area
                self.absentArea += area if join else 0.0
            else:
                join = False
            if join:
                ra, rb = find(a), find(b)
                root[max(ra, rb)] = min(ra, rb)
        members = {}
        for i in range(n):
            members.setdefault(find(i), []).append(i)
        self.groups = [tuple(members[r]) for r in sorted(members)]


def _jointOn(plane, joints, tolerance):
    """The joint plane among `joints` ((RockPlane, its _unitPlane) of kind 'set' or 'joint') that coincides
    with `plane`: normals parallel, offsets equal within `tolerance` [m]; None when there is none."""
    n, d = _unitPlane(plane)
    for joint, (m, e) in joints:
        c = sum(n[k] * m[k] for k in range(3))
        if abs(abs(c) - 1) < 1e-12 and abs(d - (e if c > 0 else -e)) <= tolerance:
            return joint
    return None


def _unitPlane(plane):
    """(unit normal, offset) of a RockPlane."""
    length = math.sqrt(sum(x * x for x in plane.normal))
    return tuple(x / length for x in plane.normal), plane.offset / length


def _uniform(seed, *what):
    """A number in [0, 1) that depends only on the seed and `what` (a hash; the same on every run and
    machine, unlike Python's hash() of strings)."""
    digest = hashlib.blake2b(repr((seed,) + what).encode('ascii'), digest_size=8).digest()
    return int.from_bytes(digest, 'little') / 2.0 ** 64


def pole(dip, dipDirection):
    """The upward unit normal of a plane of ``dip`` and ``dipDirection`` [deg]:
    ``(sin d sin a, sin d cos a, cos d)`` (z up, y north; exact 0 and 1 at multiples of 90)."""
    return _core.pole(_angle(dip, 'dip', 0, 90, 'pole'), _angle(dipDirection, 'dipDirection', 0, 360, 'pole'))


def _number(value, what):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError('%s must be a number, got %r' % (what, value))
    value = float(value)
    if not math.isfinite(value):
        raise ValueError('%s must be finite, got %r' % (what, value))
    return value


def _angle(value, name, lo, hi, where):
    value = _number(value, '%s: %s' % (where, name))
    if not lo <= value <= hi:
        raise ValueError('%s: %s must be in [%g, %g] degrees, got %r' % (where, name, lo, hi, value))
    return value


def _point(p, what):
    try:
        items = list(p)
    except TypeError:
        raise ValueError('%s must be a point (x, y, z) [m], got %r' % (what, p)) from None
    if len(items) != 3:
        raise ValueError('%s must have 3 coordinates, got %d' % (what, len(items)))
    return tuple(_number(x, what) for x in items)


def _parts(domain):
    """The domain as a list of convex corner lists, each point checked."""
    try:
        items = list(domain)
    except TypeError:
        raise ValueError('domain must be a convex corner list or a list of convex parts, got %r' % (domain,)) from None
    if not items:
        raise ValueError('domain is empty: give a convex corner list or a list of convex parts')
    parts = [items] if isPoint(items[0]) else items
    checked = []
    for i, part in enumerate(parts):
        try:
            corners = list(part)
        except TypeError:
            raise ValueError('domain part %d must be a list of corners, got %r' % (i, part)) from None
        if len(corners) < 4:
            raise ValueError('domain part %d has %d corners: a closed convex domain needs at least 4 (not all '
                             'in one plane)' % (i, len(corners)))
        checked.append([_point(p, 'domain part %d, corner %d' % (i, j)) for j, p in enumerate(corners)])
    return checked


def _unknownKeys(entry, known, where):
    unknown = sorted(set(entry) - set(known), key=str)
    if unknown:
        raise ValueError('%s: unknown key%s %s (known: %s)' % (where, 's' if len(unknown) > 1 else '',
                                                                ', '.join(repr(k) for k in unknown), ', '.join(known)))


def _persistence(entry, where):
    value = _number(entry.get('persistence', 1.0), '%s: persistence' % where)
    if not 0 < value <= 1:
        raise ValueError('%s: persistence must be in (0, 1] (the chance a plane cuts a block it crosses), got %r'
                         % (where, value))
    return value


def _jointSet(entry, where):
    _unknownKeys(entry, _SET_KEYS, where)
    missing = [k for k in _SET_REQUIRED if k not in entry]
    if missing:
        raise ValueError('%s: missing %s (a joint set is dict(dip=deg, dipDirection=deg, spacing=m, origin=(x, y, z)))'
                         % (where, ', '.join(missing)))
    spacing = _number(entry['spacing'], '%s: spacing' % where)
    if not spacing > 0:
        raise ValueError('%s: spacing must be > 0 m, got %r' % (where, spacing))
    fisherK = entry.get('fisherK')
    fisherK = 0.0 if fisherK is None else _number(fisherK, '%s: fisherK' % where)
    if 'fisherK' in entry and entry['fisherK'] is not None and not fisherK > 0:
        raise ValueError('%s: fisherK must be > 0 (the Fisher concentration; None: no scatter), got %r'
                         % (where, fisherK))
    distribution = entry.get('spacingDistribution', 'fixed')
    if distribution not in _DISTRIBUTIONS:
        raise ValueError('%s: spacingDistribution must be one of %s, got %r' % (where, ', '.join(_DISTRIBUTIONS),
                                                                                distribution))
    if 'spacingStd' in entry and distribution != 'lognormal':
        raise ValueError("%s: spacingStd is for spacingDistribution='lognormal' only" % where)
    spacingStd = _number(entry.get('spacingStd', 0.5 * spacing), '%s: spacingStd' % where)
    if distribution == 'lognormal' and not spacingStd > 0:
        raise ValueError('%s: spacingStd must be > 0 m, got %r' % (where, spacingStd))
    return dict(kind='set', dip=_angle(entry['dip'], 'dip', 0, 90, where),
                dipDirection=_angle(entry['dipDirection'], 'dipDirection', 0, 360, where), spacing=spacing,
                origin=_point(entry.get('origin', (0, 0, 0)), '%s: origin' % where),
                persistence=_persistence(entry, where), fisherK=fisherK, spacingDistribution=distribution,
                spacingStd=spacingStd if distribution == 'lognormal' else 0.0)


def _pointNormal(value, where, name):
    try:
        point, normal = value
    except (TypeError, ValueError):
        raise ValueError('%s: %s must be (point, normal), got %r' % (where, name, value)) from None
    point = _point(point, '%s: %s point' % (where, name))
    normal = _point(normal, '%s: %s normal' % (where, name))
    if not any(normal):
        raise ValueError('%s: %s normal must not be zero' % (where, name))
    return point, normal


def _region(corners, where, r):
    try:
        corners = list(corners)
    except TypeError:
        raise ValueError('%s: excavated region %d must be a list of corners, got %r' % (where, r, corners)) from None
    if len(corners) < 4:
        raise ValueError('%s: excavated region %d has %d corners: a convex region needs at least 4' % (where, r,
                                                                                                     len(corners)))
    return [_point(p, '%s: excavated region %d, corner %d' % (where, r, j)) for j, p in enumerate(corners)]


def _joint(entry, i):
    """One entry of jointSets, normalised for _core.cutRockMass."""
    where = 'jointSets[%d]' % i
    if not isinstance(entry, dict):
        raise ValueError('%s must be a dict (a joint set, dict(plane=...) or dict(excavate=...)), got %r'
                         % (where, entry))
    if 'excavate' in entry:
        _unknownKeys(entry, _EXCAVATE_KEYS, where)
        try:
            items = list(entry['excavate'])
        except TypeError:
            items = []
        if len(items) == 2 and all(isPoint(p) for p in items):      # (point, normal): a half-space
            point, normal = _pointNormal(items, where, 'excavate')
            return dict(kind='excavate', point=point, normal=normal)
        if not items:
            raise ValueError('%s: excavate must be (point, normal), a convex corner list or a list of them, got %r'
                             % (where, entry['excavate']))
        regions = [items] if isPoint(items[0]) else items
        return dict(kind='excavateRegion', regions=[_region(region, where, r) for r, region in enumerate(regions)])
    if 'plane' in entry:
        _unknownKeys(entry, _PLANE_KEYS, where)
        point, normal = _pointNormal(entry['plane'], where, 'plane')
        return dict(kind='plane', point=point, normal=normal, persistence=_persistence(entry, where))
    return _jointSet(entry, where)


def cutRockMass(domain, jointSets=(), seed=0, minVolume=None, checkShapes=True, concave=False):
    """The blocks of a rock domain cut by joint sets, single joints and excavations.

    :param domain: the corners [m] of a convex block, or a list of such corner lists: the convex parts
        of a concave domain (a slope with a bench, a box around a tunnel), meeting face to face and not
        overlapping. Each part is cut on its own; every block says which ``part`` it came from (for
        ``concaveBlock`` later).
    :param jointSets: a list of dicts, applied in this order (all fully persistent entries first, then
        those with ``persistence < 1``, then the excavations):

        - a joint set ``dict(dip=deg, dipDirection=deg, spacing=m, origin=(x, y, z))``: planes of dip
          ``dip`` in [0, 90] and dip direction ``dipDirection`` in [0, 360] (azimuth clockwise from north,
          +y, of the downward dip line; z is up), through ``origin`` (default (0, 0, 0)) and at every
          multiple of ``spacing`` > 0 along the pole ``(sin d sin a, sin d cos a, cos d)``. Optional:
          ``persistence`` in (0, 1] (default 1): each block a plane crosses is cut with this probability,
          drawn from the seed, the plane and the block; ``fisherK`` > 0: each plane's pole drawn from a
          Fisher distribution of this concentration about the mean pole (the plane keeps its anchor
          ``origin + offset * pole``); ``spacingDistribution``: 'fixed' (default), 'exponential' (mean
          ``spacing``) or 'lognormal' (mean ``spacing``, standard deviation ``spacingStd`` [m], default
          ``spacing / 2``);
        - a single joint ``dict(plane=(point, normal))`` (optional ``persistence``);
        - an excavation ``dict(excavate=(point, normal))``: removes the side the normal points to; or
          ``dict(excavate=corners)``: removes the convex hull of the corners, ``dict(excavate=[corners, ...])``
          the union of several such regions (blocks crossing a region's surface
          are cut by its face planes, only they).
    :param seed: an int: every random choice (Fisher poles, random spacings, non-persistent cuts) is a
        hash of it and what it is for, so the same seed gives bitwise the same blocks.
    :param minVolume: blocks below this volume [m^3] (default 1e-6 x the domain's volume) are merged
        into the neighbour they share the largest face with when the union is convex (decided exactly);
        those that cannot be merged are returned in ``slivers``, not in ``blocks``. 0 keeps every block.
    :param checkShapes: also merge, or return in ``slivers``, blocks whose corners ``ddaBlock`` would
        refuse (corners closer than 1e-12 of the block's size, or within 1e-9 of it of a face plane).
    :param concave: False (default): every block is convex and a DDA block of its own; a non-persistent
        joint stops at a block's face, never inside a block. True (3DEC's joined blocks): the blocks are
        cut as convex cells and then joined into concave blocks (``groups``) across the faces the domain's
        parts share (the domain's inside, no joint) and across the faces of a non-persistent plane where
        the joint is absent: every plane with ``persistence`` p < 1 cuts every block it crosses, and each
        pair of blocks it separates stays apart (a joint) with probability p, drawn from the seed, the
        plane and the two blocks (so about p of the plane's area inside the rock is joint:
        ``jointArea``, ``absentArea``). ``append()`` adds them to ``O.bodies``.
    :returns: a ``RockMass``: ``blocks`` (``RockBlock``: ``corners``, ``faces``, ``planes``, ``joints``,
        ``volume``, ``part``), ``groups`` (the DDA blocks as tuples of block indices), ``slivers``,
        ``merged``, ``planes``, ``domainVolume``, ``stats``. Raises ValueError naming the problem: a domain part that is not a closed
    convex block (fewer than 4 corners, all in one plane, a corner inside the others' hull), parts that
    overlap, NaN, ``spacing <= 0``, a dip outside [0, 90], an unknown key, ``persistence`` outside (0, 1].

    Example::

        box = [(x, y, z) for x in (0, 12) for y in (0, 12) for z in (0, 12)]
        rock = cutRockMass(box, [dict(dip=90, dipDirection=90, spacing=3), dict(dip=90, dipDirection=0, spacing=4),
                                 dict(dip=0, dipDirection=0, spacing=6)])
        O.bodies.append(rock.ddaBlocks(material=mat))      # 24 blocks
    """
    parts = _parts(domain)
    try:
        entries = list(jointSets)
    except TypeError:
        raise ValueError('jointSets must be a list of dicts, got %r' % (jointSets,)) from None
    joints = [_joint(entry, i) for i, entry in enumerate(entries)]
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise ValueError('seed must be an int, got %r' % (seed,))
    if minVolume is None:
        minVolume = -1.0
    else:
        minVolume = _number(minVolume, 'minVolume')
        if minVolume < 0:
            raise ValueError('minVolume must be >= 0 m^3, got %r' % (minVolume,))
    if not isinstance(checkShapes, bool):
        raise ValueError('checkShapes must be True or False, got %r' % (checkShapes,))
    if not isinstance(concave, bool):
        raise ValueError('concave must be True or False, got %r' % (concave,))
    persistences = [j.get('persistence', 1.0) for j in joints]
    if concave:   # every plane cuts fully; the joins decide where a joint is absent
        joints = [dict(j, persistence=1.0) if 'persistence' in j else j for j in joints]
    # Python's cyclic collector would traverse the millions of new tuples (acyclic) again and again:
    # paused while they are made (0.5 s of 1.7 on 50,000 blocks), and put back as it was.
    collecting = gc.isenabled()
    gc.disable()
    try:
        rock = RockMass(_core.cutRockMass(parts, joints, int(seed) % 2 ** 64, minVolume, checkShapes), int(seed))
    finally:
        if collecting:
            gc.enable()
    if concave:
        rock._join(persistences)
    return rock
