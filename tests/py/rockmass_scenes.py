"""Seeded jointed rock masses for tests and benchmarks (SI units: m, s, kg, Pa, rad).

A case is drawn by `draw_case(seed, ...)` from a seeded numpy Generator: a box
domain cut by 2 to 4 joint sets with random dips, dip directions and origins
(optionally one set non-persistent, optionally a cut slope face), every block
touching the box's sides or base held fixed, the rest free under gravity. The
blocks are exactly what `cutRockMass` gives: neighbours share faces bit for bit.

Oracles that need no stored answer (each a closed form of the drawn scene):
- a mass whose joints all dip below the friction angle, confined on its sides
  and base, has a static equilibrium with every contact inside its Coulomb
  cone (the placed geometry with each block carried by the faces below it),
  so it must stay at rest;
- the energy account balances;
- no sub-contact is deeper than the exact overlap of its two blocks
  (`separation` below: numpy's separating-axis value, independent of the
  core's narrow phase), or a free block's corner on a held block than the
  corner lies in the held mass (`FixedMass`);
- every collider gives the all-pairs contact set; 1 and 2 threads give the
  same bits.

`draw_case`, `Convex`, `separation`, `penetration`, `FixedMass` and
`depth_violations` are plain Python plus numpy; `build_scene`, `snapshot`, `exact_penetration` and
`rest_account` need YADE.
"""
import math

import numpy as np

G = 9.81
ROCK = dict(young=1e9, poisson=0.25, density=2600.0)   # [Pa, -, kg/m^3]
FRICTION_DEG = 35.0


# A fixed case: a 5 m cube cut by three oblique sets at 1 m through one point
# off the grid. Its held tetrahedra at the base have all faces covered by held
# neighbours but their bases, and free blocks' corners rest on their apexes.
JUNCTIONS_CASE = dict(seed=0, kind='junctions', side=5.0, spacing=1.0, persistence=None, slope=None,
                      frictionDeg=FRICTION_DEG,
                      jointSets=[dict(dip=85, dipDirection=30, spacing=1.0, origin=(0.31, 0.17, 0.23)),
                                 dict(dip=80, dipDirection=130, spacing=1.0, origin=(0.31, 0.17, 0.23)),
                                 dict(dip=15, dipDirection=250, spacing=1.0, origin=(0.31, 0.17, 0.23))])


def draw_case(seed, kind='oblique', side=5.0, spacing=1.0, sets=3, persistence=None, slope=None,
              friction_deg=FRICTION_DEG, max_dip_below=None):
    """A dict describing a confined jointed rock mass, drawn from `seed`.

    kind: 'oblique' (random dips and dip directions: one gentle set dipping
    0..max_dip_below deg, the others steep, 60..90 deg) or 'orthogonal' (the
    three axis planes, random origins). side [m]: the cube's edge; spacing [m]:
    every set's spacing (each scaled by a random factor 0.9..1.2 for oblique
    masses). persistence: None or a value in (0, 1] for the last steep set.
    slope: None or a dip [deg] of a cut face through the cube's top edge at
    x = side (the rock beyond removed). Joints dipping below the friction
    angle hold: the gentle set dips at most friction_deg - 10 by default.
    """
    rng = np.random.default_rng(seed)
    if max_dip_below is None:
        max_dip_below = friction_deg - 10.0
    joint_sets = []
    if kind == 'orthogonal':
        origin = tuple(float(v) for v in rng.uniform(0.05, 0.95, 3) * spacing)
        joint_sets = [dict(dip=90, dipDirection=90, spacing=spacing, origin=origin),
                      dict(dip=90, dipDirection=0, spacing=spacing, origin=origin),
                      dict(dip=0, dipDirection=0, spacing=spacing, origin=origin)]
    elif kind == 'oblique':
        if not 2 <= sets <= 4:
            raise ValueError('sets must be 2..4, got %r' % (sets,))
        gentle = float(rng.uniform(0.0, max_dip_below))
        dips = [gentle] + [float(rng.uniform(60.0, 90.0)) for _ in range(sets - 1)]
        azimuth0 = float(rng.uniform(0.0, 360.0))
        for k, dip in enumerate(dips):
            # steep sets spread round the compass so that they cut the mass into blocks, not slabs
            direction = (azimuth0 + k * 180.0 / max(sets - 1, 1) + float(rng.uniform(-25, 25))) % 360.0
            origin = tuple(float(v) for v in rng.uniform(0.0, spacing, 3))
            joint_sets.append(dict(dip=round(dip, 3), dipDirection=round(direction, 3),
                                   spacing=round(spacing * float(rng.uniform(0.9, 1.2)), 4), origin=origin))
    else:
        raise ValueError("kind must be 'oblique' or 'orthogonal', got %r" % (kind,))
    if persistence is not None:
        joint_sets[-1]['persistence'] = float(persistence)
    if slope is not None:
        # a face dipping `slope` deg towards +x through the top edge x = side - side/4, z = side
        a = math.radians(slope)
        top = (side * 0.75, 0.0, side)
        joint_sets.append(dict(excavate=(top, (math.sin(a), 0.0, math.cos(a)))))
    return dict(seed=seed, kind=kind, side=side, spacing=spacing, jointSets=joint_sets,
                frictionDeg=friction_deg, slope=slope, persistence=persistence)


def describe(case):
    """One line naming the case, to print with a failure (the seed reproduces it)."""
    sets = ', '.join('%s/%s' % (j['dip'], j['dipDirection']) for j in case['jointSets'] if 'dip' in j)
    return ('rock mass seed %d (%s, %g m cube, sets dip/dir %s, persistence %s, slope %s)'
            % (case['seed'], case['kind'], case['side'], sets, case['persistence'], case['slope']))


def is_held(corners, side, tol=1e-9):
    """True for a block touching the cube's sides (x, y = 0 or side) or its base (z = 0)."""
    for c in corners:
        if c[2] <= tol or c[0] <= tol or c[1] <= tol or c[0] >= side - tol or c[1] >= side - tol:
            return True
    return False


# ---------------------------------------------------------------- YADE scene

def build_scene(case, young=None, **integrator):
    """Cuts the case's mass into O.bodies (O must be empty) and sets O.engines.

    Returns (ids, fixed_ids, free_ids). Keyword arguments go to DDAIntegrator
    (gravity (0, 0, -g) unless given).
    """
    from yade_dda import O, ddaBlock, DDAIntegrator, cutRockMass
    from yade import PolyhedraMat
    side = case['side']
    box = [(x, y, z) for x in (0, side) for y in (0, side) for z in (0, side)]
    rock = cutRockMass(box, case['jointSets'], seed=case['seed'])
    mat = O.materials.append(PolyhedraMat(young=young or ROCK['young'], poisson=ROCK['poisson'],
                                          density=ROCK['density'],
                                          frictionAngle=math.radians(case['frictionDeg'])))
    ids, fixed, free = [], [], []
    for b in rock:
        held = is_held(b.corners, side)
        i = O.bodies.append(ddaBlock(b.corners, material=mat, fixed=held))
        ids.append(i)
        (fixed if held else free).append(i)
    integrator.setdefault('gravity', (0, 0, -G))
    integrator.setdefault('label', 'dda')
    O.engines = [DDAIntegrator(**integrator)]
    return ids, fixed, free


# ---------------------------------------------------------------- exact overlap (numpy, no YADE)

class Convex:
    """A convex block's corners (n, 3) [m] and faces (lists of corner indices),
    with its face polygons padded to one array and its edges, for
    `separation`. Build it once per block and `moved(vertices)` for new corners
    (the faces of a DDA block never change)."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
        self.faces = [tuple(int(k) for k in f) for f in faces]
        width = max(len(f) for f in self.faces)
        # each face's corner k and k+1 (cyclic), padded by the pair (first, first), which adds nothing to
        # Newell's sum (p x p = 0)
        cur = np.array([list(f) + [f[0]] * (width - len(f)) for f in self.faces])
        nxt = np.array([list(f[1:]) + [f[0]] * (width - len(f) + 1) for f in self.faces])
        self._cur, self._nxt = cur, nxt
        edges = {tuple(sorted((f[k], f[(k + 1) % len(f)]))) for f in self.faces for k in range(len(f))}
        self.edges = np.array(sorted(edges))

    def moved(self, vertices):
        other = object.__new__(Convex)
        other.__dict__.update(self.__dict__)
        other.vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
        return other

    def face_normals(self):
        """Unnormalised outward-or-inward face normals by Newell's sum (exact for planar faces;
        the sign does not matter to `separation`, which takes both directions)."""
        v = self.vertices - self.vertices.mean(axis=0)   # about the block's middle: less cancellation
        return np.cross(v[self._cur], v[self._nxt]).sum(axis=1)

    def edge_vectors(self):
        return self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]]


def _unit_rows(a):
    return a / np.sqrt((a * a).sum(axis=1))[:, None]


def separation(A, B, parallel=1e-9):
    """The separating-axis value of convex blocks A and B (`Convex`) [m]: the largest,
    over every face normal of either block and every cross product of an edge of A
    with an edge of B (skipped where |ea x eb| < parallel |ea| |eb|), of the gap
    between the blocks' projections on that axis, max(min B - max A, min A - max B).

    > 0: the blocks are apart (by at least that); <= 0: its negative is the
    blocks' exact penetration depth (the smallest translation that parts them),
    since those axes hold every face normal of the Minkowski difference. Float64,
    vectorised: O((faces + edges^2) x corners)."""
    ea, eb = A.edge_vectors(), B.edge_vectors()
    cross = np.cross(ea[:, None, :], eb[None, :, :]).reshape(-1, 3)
    norm = np.sqrt((cross * cross).sum(axis=1))
    scale = (np.sqrt((ea * ea).sum(axis=1))[:, None] * np.sqrt((eb * eb).sum(axis=1))[None, :]).reshape(-1)
    axes = np.vstack([_unit_rows(A.face_normals()), _unit_rows(B.face_normals()),
                      cross[norm >= parallel * scale] / norm[norm >= parallel * scale][:, None]])
    pa, pb = A.vertices @ axes.T, B.vertices @ axes.T
    gaps = np.maximum(pb.min(axis=0) - pa.max(axis=0), pa.min(axis=0) - pb.max(axis=0))
    return float(gaps.max())


def penetration(A, B):
    """The exact overlap depth of convex blocks A and B (`Convex`) [m]: max(0, -separation)."""
    return max(0.0, -separation(A, B))


def coordinate_scale(A, B):
    """The largest corner coordinate's magnitude of two blocks [m] (what round-off scales with)."""
    return float(max(np.abs(A.vertices).max(), np.abs(B.vertices).max()))


def block_shape(i):
    """The DDA block of body i as a `Convex` (its current corners). Needs YADE."""
    import yade_dda
    b = yade_dda.block(i)
    return Convex([tuple(v) for v in b.vertices], b.faces)


def exact_penetration(i, j, shapes=None):
    """The exact overlap depth [m] of the DDA blocks of bodies i and j: their
    current corners, or those in `shapes` (a dict body id -> `Convex`, e.g. a
    `snapshot()` taken before a step)."""
    if shapes is None:
        return penetration(block_shape(i), block_shape(j))
    return penetration(shapes[i], shapes[j])


def snapshot(ids, shapes=None):
    """{body id: Convex} of the blocks' current corners. `shapes`, a previous snapshot of the
    same blocks, saves re-reading their faces. Needs YADE."""
    import yade_dda
    if shapes is None:
        return {i: block_shape(i) for i in ids}
    return {i: shapes[i].moved([tuple(v) for v in yade_dda.block(i).vertices]) for i in ids}


def depth_violations(contacts, shapes, absolute=1e-9, relative=1e-9, fixed_mass=None):
    """The sub-contacts deeper than their pair's exact overlap.

    contacts: (id1, id2, gap, label) or (id1, id2, gap, label, point) per
    sub-contact, gap [m] measured on the geometry of `shapes` ({body id:
    Convex}), label anything to report (kind, type, state). A sub-contact
    violates when gap < -(penetration of (id1, id2)) - tol, with tol = absolute
    [m] + relative x the pair's largest corner coordinate. With `fixed_mass`
    (a FixedMass of the held blocks, whose ids are its `ids`), a vertex-face
    contact of a free block's corner (id1, the corner nearest `point`) on a
    held block (id2) may be as deep as the corner lies in the held mass: at a
    seam of two held blocks the pair's overlap measures only the way out
    across the joint, into the neighbour. Returns a list of (id1, id2, label,
    gap, penetration, tol), largest excess first."""
    cache, out = {}, []
    for entry in contacts:
        id1, id2, gap, state = entry[:4]
        key = (min(id1, id2), max(id1, id2))
        if key not in cache:
            A, B = shapes[key[0]], shapes[key[1]]
            cache[key] = (penetration(A, B), absolute + relative * coordinate_scale(A, B))
        depth, tol = cache[key]
        if gap < -depth - tol:
            if (fixed_mass is not None and len(entry) > 4 and str(state).startswith('VF') and id2 in fixed_mass.ids
                    and id1 not in fixed_mass.ids):
                corners = shapes[id1].vertices
                corner = corners[np.argmin(((corners - np.asarray(entry[4])) ** 2).sum(axis=1))]
                if fixed_mass.reaches(corner, -gap - tol):
                    continue
            out.append((id1, id2, state, gap, depth, tol))
    out.sort(key=lambda v: v[3] + v[4])
    return out


class FixedMass:
    """The union of the held blocks (`Convex` each) of a cut mass [m]: a corner's depth in it.

    Neighbouring blocks of `cutRockMass` share faces exactly, so a face of a held block
    is either covered whole by an opposed face of another held block (the same corners:
    inside the mass) or exposed; the mass's surface is the union of the exposed faces.
    A point inside some held block lies at least d inside the mass when no exposed face
    polygon comes within d of it."""

    def __init__(self, shapes):
        self.ids = set(shapes)
        self.blocks = list(shapes.values())
        key = lambda pts: tuple(sorted(tuple(np.round(p, 9)) for p in pts))
        count = {}
        faces = []
        for b in self.blocks:
            for f in b.faces:
                pts = b.vertices[list(f)]
                k = key(pts)
                count[k] = count.get(k, 0) + 1
                faces.append((k, pts))
        self.exposed = [pts for k, pts in faces if count[k] == 1]
        self.planes = []   # per block: outward unit normals and offsets (n . x - o > 0 outside)
        for b in self.blocks:
            n = _unit_rows(b.face_normals())
            o = np.array([n[k] @ b.vertices[f[0]] for k, f in enumerate(b.faces)])
            flip = np.where(n @ b.vertices.mean(axis=0) - o > 0, -1.0, 1.0)
            self.planes.append((n * flip[:, None], o * flip))
        self.low = np.array([p.min(axis=0) for p in self.exposed])
        self.high = np.array([p.max(axis=0) for p in self.exposed])

    def inside(self, x, tol=1e-12):
        return any(np.all(n @ x - o <= tol) for n, o in self.planes)

    def reaches(self, x, depth):
        """True when x lies in the mass at least `depth` [m] from its surface."""
        if not self.inside(x):
            return depth <= 0
        near = np.all((self.low <= x + depth) & (self.high >= x - depth), axis=1)
        return all(_polygon_distance(x, self.exposed[k]) >= depth for k in np.nonzero(near)[0])


def _polygon_distance(x, pts):
    """The distance [m] from point x to the planar convex polygon of corners `pts` (in order)."""
    n = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    n = n / np.linalg.norm(n)
    h = n @ (x - pts[0])
    p = x - h * n
    edges = np.roll(pts, -1, axis=0) - pts
    side = np.cross(edges, p - pts) @ n
    if np.all(side >= 0) or np.all(side <= 0):
        return abs(h)
    best = np.inf
    for a, e in zip(pts, edges):
        t = min(1.0, max(0.0, (x - a) @ e / (e @ e)))
        best = min(best, np.linalg.norm(x - (a + t * e)))
    return best


def rest_account(free):
    """stats()['energy'] of the placed scene before its first step (the account then
    reads 0 for gravity): every term 0 but gravity, -m g . c summed over the free
    blocks (bodies `free`) [J] (gravityChange, measured from the blocks' initial
    centroids, is 0). Needs YADE; gravity (0, 0, -G)."""
    import yade_dda
    gravity = math.fsum(yade_dda.block(i).mass * G * yade_dda.block(i).centroid[2] for i in free)
    return dict(kinetic=0.0, gravity=gravity, gravityChange=0.0, strain=0.0, contact=0.0, friction=0.0, damping=0.0,
                loads=0.0, boundaryWork=0.0, contactChanges=0.0)
