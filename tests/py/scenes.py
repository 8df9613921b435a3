"""Scene geometry and closed forms for the contact physics tests (SI units).

Everything above the "YADE scenes" section is plain Python (math only), so
the closed forms and the geometry can be checked without YADE:

    /usr/bin/python3 -c "import scenes; print(scenes.wedge_factor_of_safety(...))"

Conventions. z is up; gravity is (0, 0, -g). Angles are in radians. A slope
is described by its frame (downhill, across, normal): `downhill` is the unit
line of steepest descent in the slope face, `normal` the outward (upward)
unit normal of the face, `across = normal x downhill`, so
(downhill, across, normal) is right-handed and a positive rotation about
`across` tips a block's top downhill.
"""
import math

G = 9.81              # gravity [m/s^2]
ROCK = dict(young=1e10, poisson=0.25, density=2600.0)   # hard rock [Pa, -, kg/m^3]


# ---------------------------------------------------------------- vectors

def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def combine(origin, *terms):
    """origin + sum(s_k v_k) for terms (s_k, v_k)."""
    x = tuple(float(c) for c in origin)
    for s, v in terms:
        x = add(x, scale(s, v))
    return x


def box(lo, hi):
    """Corners of the axis-aligned box [lo, hi] [m] (same order as helpers.box)."""
    return [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]


def frame_box(origin, axes, lo, hi):
    """Corners of a box given in the orthonormal frame `axes` = (e1, e2, e3) at `origin`.

    Corner i has frame coordinates (hi or lo per bit of i, as in `box`); points
    that share a frame coordinate lie in one plane up to round-off (~1e-16 m).
    """
    return [combine(origin, *zip(p, axes)) for p in box(lo, hi)]


# ---------------------------------------------------------------- block on an incline

def slope_frame(slope, azimuth=0.0):
    """(downhill, across, normal) unit vectors of a plane dipping `slope` [rad]
    towards the horizontal direction (cos azimuth, sin azimuth, 0)."""
    ca, sa, cz, sz = math.cos(slope), math.sin(slope), math.cos(azimuth), math.sin(azimuth)
    downhill = (ca * cz, ca * sz, -sa)
    across = (-sz, cz, 0.0)
    normal = (sa * cz, sa * sz, ca)
    return downhill, across, normal


def incline_slide_distance(slope, phi, t, g=G):
    """Distance [m] a block starting at rest slides down a plane in time t.

    Along the slope the block feels g sin(a) from gravity; the plane pushes
    back with N = m g cos(a) (no motion normal to it), and a sliding contact
    resists with tan(phi) N. So the acceleration is constant,
        s'' = g (sin a - tan(phi) cos a),   s(t) = s'' t^2 / 2,
    when positive; otherwise static friction (up to tan(phi) N > m g sin a)
    holds the block and s = 0.
    """
    acceleration = g * (math.sin(slope) - math.tan(phi) * math.cos(slope))
    return max(acceleration, 0.0) * t * t / 2


def classical_regime(slope, phi, width, height):
    """Classical (Hoek & Bray) modes of a block on an incline: (slides, topples).

    Slides iff tan(a) > tan(phi) (weight component along the slope beats
    friction); topples iff tan(a) > width/height (the weight's line of action
    through the centroid falls outside the downhill base edge), with `width`
    measured along the slope.
    """
    return math.tan(slope) > math.tan(phi), math.tan(slope) > width / height


def toppling_friction_demand(slope, width, height):
    """|F|/N at the downhill edge for a block starting to rotate about it without slip.

    Rigid block (b = width, h = height), pivot P at the downhill lower edge,
    r = c - P = (-b/2, h/2) in (downhill, normal) coordinates. From rest the
    angular acceleration about P is
        alpha = m g (h sin a - b cos a) / 2 / I_P,   I_P = m (b^2 + h^2) / 3,
    the centroid accelerates with alpha x r = alpha (h/2, b/2), and the contact
    force is m (a_c - g): tangential F = m (alpha h/2 - g sin a), normal
    N = m (alpha b/2 + g cos a). Pure toppling needs |F| <= tan(phi) N.
    """
    b, h, a = width, height, slope
    alpha = 3 * G * (h * math.sin(a) - b * math.cos(a)) / (2 * (b * b + h * h))
    return (G * math.sin(a) - alpha * h / 2) / (G * math.cos(a) + alpha * b / 2)


def _solve3(A, r):
    """Solves the 3x3 system A x = r (Cramer's rule; A well conditioned here)."""
    def det(M):
        return (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1])
                - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0])
                + M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]))
    d = det(A)
    out = []
    for k in range(3):
        M = [[r[i] if j == k else A[i][j] for j in range(3)] for i in range(3)]
        out.append(det(M) / d)
    return out


def rigid_block_on_incline(slope, phi, width, height, t_end, steps=20000, g=G):
    """Reference motion of a rigid block released at rest on an incline (plane problem).

    Returns (slip, theta, modes): slip [m] of the downhill lower edge along the
    slope, rotation theta [rad] about that edge (positive = top downhill) at
    t_end, and the sequence of modes. Modes (Sagaseta 1986 refines the
    classical chart this way): 'rest'; 'slide' (both base edges on the plane,
    needs tan(phi) <= b/h so the reaction stays inside the base); 'topple'
    (rotation about the downhill edge, no slip, needs the friction demand
    <= tan(phi)); 'slidetopple' (rotation while the edge slips downhill, with
    friction tan(phi) N). In coordinates q = (s, theta) (s the edge's position),
    the centroid is c = (s - b/2 cos(th) + h/2 sin(th), b/2 sin(th) + h/2 cos(th));
    Newton for the centroid and Euler about it give three linear equations for
    (s'', theta'', N) (slide-topple) or (theta'', N, F) (topple). Integrated by
    semi-implicit Euler; `steps` = 20000 over 0.5 s gives four digits.
    """
    b, h, a = width, height, slope
    mu = math.tan(phi)
    Ic = (b * b + h * h) / 12          # per unit mass, about the centroid
    s = sd = th = thd = 0.0

    def accelerations(mode):
        c, sn = math.cos(th), math.sin(th)
        px, pz = b / 2 * c - h / 2 * sn, -(b / 2 * sn + h / 2 * c)   # P - centroid
        r1 = g * math.sin(a) - (b / 2 * c - h / 2 * sn) * thd ** 2     # c_x'' terms without the unknowns
        r2 = -g * math.cos(a) + (b / 2 * sn + h / 2 * c) * thd ** 2
        # moment about the centroid of a unit force (fx, fz) at P, about `across`: pz fx - px fz
        if mode == 'topple':
            A = [[b / 2 * sn + h / 2 * c, 0.0, -1.0],
                 [b / 2 * c - h / 2 * sn, -1.0, 0.0],
                 [Ic, px, -pz]]
            thdd, N, F = _solve3(A, [r1, r2, 0.0])
            return 0.0, thdd, N, F
        if mode == 'slidetopple':
            A = [[1.0, b / 2 * sn + h / 2 * c, mu],
                 [0.0, b / 2 * c - h / 2 * sn, -1.0],
                 [0.0, Ic, -(pz * -mu - px)]]
            sdd, thdd, N = _solve3(A, [r1, r2, 0.0])
            return sdd, thdd, N, -mu * N
        if mode == 'slide':
            return g * (math.sin(a) - mu * math.cos(a)), 0.0, g * math.cos(a), -mu * g * math.cos(a)
        return 0.0, 0.0, g * math.cos(a), -g * math.sin(a)

    if math.tan(a) <= mu and math.tan(a) <= b / h:
        mode = 'rest'
    elif math.tan(a) > mu and mu <= b / h:
        mode = 'slide'
    else:
        _, thdd, N, F = accelerations('topple')
        mode = 'topple' if thdd > 0 and abs(F) <= mu * N else 'slidetopple'
    modes = [mode]
    dt = t_end / steps
    for _ in range(steps):
        sdd, thdd, N, F = accelerations(mode)
        if mode == 'topple' and abs(F) > mu * N:
            mode = 'slidetopple'
            modes.append(mode)
            sdd, thdd, N, F = accelerations(mode)
        if N < 0:
            raise RuntimeError('block lost contact (N < 0): outside the modes modelled here')
        sd += sdd * dt
        s += sd * dt
        thd += thdd * dt
        th += thd * dt
        if mode == 'slidetopple' and sd < 0:
            mode, sd = 'topple', 0.0
            modes.append(mode)
    return s, th, modes


SLAB = ((-1.0, -1.5, -1.0), (5.0, 1.5, 0.0))   # default slab in slope coordinates [m]


def incline_geometry(slope, size, azimuth=0.0, origin=(0.0, 0.0, 0.0), slab=SLAB):
    """A fixed slab whose top face is the slope and a box resting on it.

    `size` = (b, w, h): the box's extent along the slope, across it and normal
    to it [m]; its base occupies slope coordinates [0, b] x [-w/2, w/2] at
    height 0, the slab the box [slab[0], slab[1]] (its top face at height 0).
    Slope coordinates (x, y, z) map to origin + x downhill + y across + z normal.
    Returns a dict with 'slab' and 'block' (8 corners each, `box` order),
    'slabTop' and 'blockBase' (the 4 corners at height 0 of each), 'frame'
    (downhill, across, normal), 'origin' and 'pivot', the midpoint of the
    block's downhill lower edge.
    """
    frame = slope_frame(slope, azimuth)
    b, w, h = size
    block = frame_box(origin, frame, (0.0, -w / 2, 0.0), (b, w / 2, h))
    slabPoints = frame_box(origin, frame, slab[0], slab[1])
    return dict(slab=slabPoints, block=block, frame=frame, origin=tuple(origin),
                pivot=combine(origin, (b, frame[0])),
                slabTop=[p for i, p in enumerate(slabPoints) if i & 4],
                blockBase=[p for i, p in enumerate(block) if not i & 4])


# ---------------------------------------------------------------- wedge on two planes

def wedge_line(nA, nB):
    """Unit line of intersection of two planes, pointing downhill, and its plunge [rad]."""
    line = unit(cross(nA, nB))
    if line[2] > 0:
        line = scale(-1.0, line)
    return line, math.asin(-line[2])


def wedge_reactions(nA, nB, weight=1.0):
    """Normal reactions R_A, R_B [N] of a wedge of weight W sliding along the intersection line.

    The wedge moves along the line l of intersection, so there is no
    acceleration perpendicular to l; there, with unit normals n_A, n_B of the
    planes (pointing into the wedge; both are perpendicular to l),
        R_A n_A + R_B n_B = W z_perp,   z_perp = z - (z . l) l.
    Dotting with n_A and n_B (and n . l = 0, so n . z_perp = n . z), with c = n_A . n_B:
        R_A + c R_B = W n_A . z,   c R_A + R_B = W n_B . z,
    hence R_A = W (n_A.z - c n_B.z) / (1 - c^2), R_B = W (n_B.z - c n_A.z) / (1 - c^2).
    Both must be >= 0 for the wedge to rest on both planes.
    """
    c = dot(nA, nB)
    za, zb = nA[2], nB[2]
    return weight * (za - c * zb) / (1 - c * c), weight * (zb - c * za) / (1 - c * c)


def wedge_factor_of_safety(nA, nB, phiA, phiB):
    """Factor of safety of a frictional wedge on two planes (no cohesion, no water).

    Limit equilibrium along the line of intersection l: the weight drives
    with W sin(psi_i) (psi_i the plunge of l), friction on each plane resists
    with R tan(phi) (R from `wedge_reactions`), so
        FS = (R_A tan(phi_A) + R_B tan(phi_B)) / (W sin(psi_i)).
    Independent of W. When FS < 1 the wedge accelerates along l with
    g sin(psi_i) (1 - FS).
    """
    RA, RB = wedge_reactions(nA, nB, 1.0)
    _, plunge = wedge_line(nA, nB)
    return (RA * math.tan(phiA) + RB * math.tan(phiB)) / math.sin(plunge)


def wedge_section_angles(nA, nB):
    """The textbook angles of a wedge: (xi, beta, plunge) [rad].

    Measured in the plane perpendicular to the line of intersection l: the
    traces of the two planes leave the keel along t_A = +-(l x n_A) and
    t_B = +-(l x n_B), signed to point into the wedge (t_A . n_B > 0); xi is the
    angle between them (the wedge's included angle), beta the angle between
    their bisector and the horizontal line h = l x z of that plane (so
    sin(beta) = bisector . u with u the upward unit vector of the section).
    """
    line, plunge = wedge_line(nA, nB)
    tA, tB = unit(cross(line, nA)), unit(cross(line, nB))
    if dot(tA, nB) < 0:
        tA = scale(-1.0, tA)
    if dot(tB, nA) < 0:
        tB = scale(-1.0, tB)
    xi = math.acos(max(-1.0, min(1.0, dot(tA, tB))))
    bisector = unit(add(tA, tB))
    horizontal = unit(cross(line, (0.0, 0.0, 1.0)))
    up = unit(sub((0.0, 0.0, 1.0), scale(line[2], line)))
    beta = math.atan2(dot(bisector, up), dot(bisector, horizontal))
    return xi, beta, plunge


def hoek_bray_factor_of_safety(xi, beta, plunge, phi):
    """Textbook wedge FS, equal friction on both planes: FS = sin(beta)/sin(xi/2) tan(phi)/tan(psi_i).

    In the section perpendicular to l, each plane's normal makes 90 deg - xi/2
    with the bisector, so resolving R_A n_A + R_B n_B = W cos(psi_i) u along the
    bisector gives (R_A + R_B) sin(xi/2) = W cos(psi_i) sin(beta); then
    FS = (R_A + R_B) tan(phi) / (W sin(psi_i)).
    """
    return math.sin(beta) / math.sin(xi / 2) * math.tan(phi) / math.tan(plunge)


def dip_and_direction(n):
    """(dip, dip direction) [rad] of a plane with upward unit normal n; dip direction
    is the azimuth clockwise from north = +y (x = east)."""
    return math.acos(n[2]), math.atan2(n[0], n[1]) % (2 * math.pi)


def intersection_from_dips(dipA, dirA, dipB, dirB):
    """(trend, plunge) [rad] of the line where two planes meet, from dips and dip directions.

    A line of trend t in a plane of dip psi and dip direction alpha plunges by
    the apparent dip atan(tan(psi) cos(alpha - t)). On the line of intersection
    both apparent dips agree: tan(psi_A) cos(alpha_A - t) = tan(psi_B) cos(alpha_B - t),
    i.e. tan t = (T_A cos a_A - T_B cos a_B) / (T_B sin a_B - T_A sin a_A) with
    T = tan(psi); of the two trends 180 deg apart the one with positive plunge
    is returned.
    """
    TA, TB = math.tan(dipA), math.tan(dipB)
    trend = math.atan2(TA * math.cos(dirA) - TB * math.cos(dirB), TB * math.sin(dirB) - TA * math.sin(dirA))
    plunge = math.atan(TA * math.cos(dirA - trend))
    if plunge < 0:
        trend, plunge = trend + math.pi, -plunge
    return trend % (2 * math.pi), plunge


def wedge_geometry(plunge, xi, beta, keel=2.0, arms=(1.0, 1.0), at=0.5, azimuth=0.0, origin=(0.0, 0.0, 0.0),
                   overhang=1.0, room=(1.0, 2.5), thickness=1.0):
    """A tetrahedral wedge resting on two fixed slabs (two planes meeting along a keel).

    The keel (line of intersection) runs from `origin` downhill along
    l = (cos psi cos az, cos psi sin az, -sin psi). In the plane perpendicular
    to l, with h = (-sin az, cos az, 0) (horizontal) and u (up), the wedge's
    faces leave the keel along d_A = cos(beta + xi/2) h + sin(beta + xi/2) u and
    d_B = cos(beta - xi/2) h + sin(beta - xi/2) u: the included angle is xi, the
    bisector makes beta with the horizontal. The plane normals pointing into
    the wedge are d_A and d_B turned by 90 deg towards each other:
        n_A = sin(beta + xi/2) h - cos(beta + xi/2) u,
        n_B = -sin(beta - xi/2) h + cos(beta - xi/2) u.
    Wedge corners: P0 = origin, P1 = origin + keel l (the keel edge),
    Q_A = origin + at keel l + arms[0] d_A (on plane A), Q_B likewise on B; so
    faces (P0, P1, Q_A) and (P0, P1, Q_B) lie on the planes exactly.

    Each slab is a box in the orthonormal frame (l, d, -n) of its plane:
    [-room[0], keel + room[1]] along l, [-overhang, arm + 1] along d, thickness
    below. Its top face is the plane; it reaches `overhang` past the keel, so
    the wedge's keel corners lie well inside both top faces, and the two fixed
    slabs overlap below the keel (fixed blocks do not interact). The slab
    edge past the keel is overhang sin(xi) from the other plane.

    Needs xi/2 < beta < 180 deg - xi/2 (the weight's section component lies
    between the normals: both reactions compressive).
    """
    cp, sp, cz, sz = math.cos(plunge), math.sin(plunge), math.cos(azimuth), math.sin(azimuth)
    line = (cp * cz, cp * sz, -sp)
    h = (-sz, cz, 0.0)
    u = (sp * cz, sp * sz, cp)
    dA = combine((0, 0, 0), (math.cos(beta + xi / 2), h), (math.sin(beta + xi / 2), u))
    dB = combine((0, 0, 0), (math.cos(beta - xi / 2), h), (math.sin(beta - xi / 2), u))
    nA = combine((0, 0, 0), (math.sin(beta + xi / 2), h), (-math.cos(beta + xi / 2), u))
    nB = combine((0, 0, 0), (-math.sin(beta - xi / 2), h), (math.cos(beta - xi / 2), u))
    P0 = tuple(float(c) for c in origin)
    P1 = combine(P0, (keel, line))
    QA = combine(P0, (at * keel, line), (arms[0], dA))
    QB = combine(P0, (at * keel, line), (arms[1], dB))
    slabA = frame_box(P0, (line, dA, scale(-1.0, nA)), (-room[0], -overhang, 0.0),
                      (keel + room[1], arms[0] + 1.0, thickness))
    slabB = frame_box(P0, (line, dB, scale(-1.0, nB)), (-room[0], -overhang, 0.0),
                      (keel + room[1], arms[1] + 1.0, thickness))
    return dict(wedge=[P0, P1, QA, QB], onA=(0, 1, 2), onB=(0, 1, 3), slabA=slabA, slabB=slabB,
                slabATop=[p for i, p in enumerate(slabA) if not i & 4],
                slabBTop=[p for i, p in enumerate(slabB) if not i & 4],
                nA=nA, nB=nB, line=line, origin=P0)


def upward_normal(dip, direction):
    """Upward unit normal of a plane of dip `dip` and dip direction `direction` [rad]
    (clockwise from north = +y, x = east): the plane falls towards the horizontal
    direction (sin direction, cos direction, 0), so its upward normal leans that way
    by the dip. Inverse of `dip_and_direction`."""
    return (math.sin(dip) * math.sin(direction), math.sin(dip) * math.cos(direction), math.cos(dip))


def wedge_from_dips(dipA, dirA, dipB, dirB, keel=2.0, arms=(1.0, 1.0), **kw):
    """`wedge_geometry` for a wedge given the way rock engineers give it: the dips and dip
    directions [rad] of its two joint planes (dip direction clockwise from north = +y).

    The wedge lies above both planes, in the valley they make (z above both is
    max(z_A, z_B), a convex V whose floor is the line of intersection), and is held
    by both: its weight pushes it into the keel. The line of intersection has the
    trend and plunge of `intersection_from_dips`; wedge_geometry's keel runs along
    (cos psi cos az, cos psi sin az, -sin psi) with az counter-clockwise from +x,
    so az = 90 deg - trend. In the section perpendicular to the line, xi is the
    angle between the planes' traces (the valley's opening, `wedge_section_angles`)
    and beta the bisector's angle from h = (-sin az, cos az, 0), the horizontal to
    the left looking downhill; wedge_section_angles measures it from l x z = -h,
    so beta = 180 deg - its beta. wedge_geometry's plane A is the one on the
    right flank (its face leaves the keel at beta + xi/2 from h, its upward normal
    leans towards h); when the requested plane A lies on the left the two are
    built swapped and relabelled, so nA (the upward normal of slab A's top face,
    pointing into the wedge) has dip dipA and dip direction dirA. `arms` are the
    wedge's extents from the keel on A and on B [m] (as in wedge_geometry); `kw`
    goes to wedge_geometry (origin, keel position `at`, slab sizes).

    Adds 'trend', 'plunge', 'azimuth', 'xi', 'beta' (wedge_geometry's angles) [rad]
    to the dict. Raises ValueError when one reaction would be tensile (the block
    would slide on one plane and leave the other: not a two-plane wedge).
    """
    nA, nB = upward_normal(dipA, dirA), upward_normal(dipB, dirB)
    RA, RB = wedge_reactions(nA, nB)
    if not (RA > 0 and RB > 0):
        raise ValueError('not a two-plane wedge: reactions %g, %g (per unit weight)' % (RA, RB))
    trend, plunge = intersection_from_dips(dipA, dirA, dipB, dirB)
    azimuth = math.pi / 2 - trend
    xi, betaFromRight, _ = wedge_section_angles(nA, nB)
    beta = math.pi - betaFromRight
    left = (-math.sin(azimuth), math.cos(azimuth), 0.0)
    swap = dot(nA, left) < 0
    geo = wedge_geometry(plunge, xi, beta, keel=keel, arms=tuple(reversed(arms)) if swap else tuple(arms),
                         azimuth=azimuth, **kw)
    if swap:
        for a, b in (('onA', 'onB'), ('slabA', 'slabB'), ('slabATop', 'slabBTop'), ('nA', 'nB')):
            geo[a], geo[b] = geo[b], geo[a]
    geo.update(trend=trend, plunge=plunge, azimuth=azimuth, xi=xi, beta=beta)
    return geo


def tetrahedron_volume_centroid(points):
    """Volume [m^3] and centroid [m] of a tetrahedron."""
    a, b, c, d = points
    volume = abs(dot(sub(b, a), cross(sub(c, a), sub(d, a)))) / 6
    centroid = scale(0.25, add(add(a, b), add(c, d)))
    return volume, centroid


def friction_for_wedge_fs(nA, nB, fs, ratio=1.0):
    """Friction angles (phi_A, phi_B) [rad] giving factor of safety `fs`, with tan(phi_B) = ratio tan(phi_A).

    From FS = tan(phi_A) (R_A + ratio R_B) / (W sin psi_i), linear in tan(phi_A).
    """
    RA, RB = wedge_reactions(nA, nB, 1.0)
    _, plunge = wedge_line(nA, nB)
    tanA = fs * math.sin(plunge) / (RA + ratio * RB)
    return math.atan(tanA), math.atan(ratio * tanA)


# ---------------------------------------------------------------- energy

def kinetic_energy(mass, volume, secondMoment, rates):
    """Kinetic energy [J] of a DDA block from its 12 rates.

    The block's velocity field is linear: v(x) = v_c + L (x - c) with
    L = [w]x + E', E' the strain-rate tensor (engineering shear rates halved).
    Integrating rho |v|^2 / 2 over the block, the cross term vanishes about
    the centroid, leaving
        T = m |v_c|^2 / 2 + rho tr(L J L^T) / 2,   rho = m / V,
    with J = integral of (x - c)(x - c)^T dV (the block's `secondMoment`).
    """
    v = rates[0:3]
    wx, wy, wz = rates[3:6]
    ex, ey, ez, gxy, gyz, gzx = rates[6:12]
    L = [[ex, gxy / 2 - wz, gzx / 2 + wy],
         [gxy / 2 + wz, ey, gyz / 2 - wx],
         [gzx / 2 - wy, gyz / 2 + wx, ez]]
    J = [[secondMoment[i][j] for j in range(3)] for i in range(3)]
    trace = sum(L[i][k] * J[k][l] * L[i][l] for i in range(3) for k in range(3) for l in range(3))
    return mass * dot(v, v) / 2 + mass / volume * trace / 2


# ---------------------------------------------------------------- YADE scenes (import YADE lazily)

def add_block(points, material, **kw):
    """Appends a DDA block to O.bodies; returns its id."""
    from yade_dda import O, ddaBlock
    return O.bodies.append(ddaBlock(points, material=material, **kw))


def rock(frictionDeg=0.0, **overrides):
    """A PolyhedraMat of hard rock (ROCK) with the given friction angle [deg]; returns its id."""
    from yade_dda import O
    from helpers import material
    params = dict(ROCK)
    params.update(overrides)
    return material(O, frictionDeg=frictionDeg, **params)


def build_incline(slope, size, phiBlock, phiSlab=None, azimuth=0.0, origin=(0.0, 0.0, 0.0), slab=None):
    """Fixed slab + block of `incline_geometry` in the current scene; returns (geometry, slab id, block id)."""
    kw = {} if slab is None else dict(slab=slab)
    geo = incline_geometry(slope, size, azimuth=azimuth, origin=origin, **kw)
    slabId = add_block(geo['slab'], rock(phiBlock if phiSlab is None else phiSlab), fixed=True)
    blockId = add_block(geo['block'], rock(phiBlock))
    return geo, slabId, blockId


def build_resting_block(origin=(0.0, 0.0, 0.0), size=1.0, frictionDeg=30.0):
    """A cube of side `size` resting on a fixed floor slab whose top face is z = origin z; (floor, block) ids."""
    x, y, z = origin
    floor = add_block(box((x - 2, y - 2, z - 1), (x + size + 2, y + size + 2, z)), rock(frictionDeg), fixed=True)
    block = add_block(box((x, y, z), (x + size, y + size, z + size)), rock(frictionDeg))
    return floor, block
