"""Random convex prisms on random inclines: the scene generator and its closed forms (SI units).

Plain Python and numpy above the "YADE scene" section, so the geometry can be
checked without YADE. Nothing here is tuned to DDA: every number is drawn from a
seeded numpy Generator, and every bound is a closed form of the drawn scene.

A case is drawn by `draw_case(seed, regime)`:

- the incline: slope theta uniform in 10..35 deg, dip direction (azimuth of the
  line of steepest descent, counter-clockwise from +x) uniform in 0..360 deg,
  the whole scene shifted by a random origin;
- the footprint: a convex polygon of 5 to 9 corners (the convex hull of points
  drawn on a random ellipse with radial jitter, redrawn until every drawn point
  is a corner), its diameter 0.6..1.6 m, spun by a random angle about the
  incline's normal (the angular gaps between drawn points differ by at most
  3:1, so all corner counts are drawn about equally often). Slivers are refused: every edge at least 0.15 of the
  diameter, every corner turning by at least 12 deg (interior angle at most
  168 deg), the polygon's narrowest width at least 0.35 of its diameter;
- the prism: the footprint extruded along the incline's normal by a height h,
  its bottom face ON the slab's top face (the corners' normal coordinate is
  exactly 0, the same plane as the slab's top corners) and its footprint's
  centroid at the slope coordinates' origin. h is drawn in 0.2 m .. h_max, where
  h_max keeps the block from toppling: the vertical line through the centroid
  (gravity's line of action) meets the incline at (h/2) tan(theta) downhill of
  the footprint's centroid, and that point must lie inside the footprint with a
  margin of 0.1 of its narrowest width. When it slides, the contact force
  (N along the normal, tan(phi) N uphill) passes through the centroid (no
  moment: pure translation) and meets the base at (h/2) tan(phi) downhill,
  between the centroid's foot and the vertical's, so inside too (convexity);
- friction: the factor of safety FS = tan(phi)/tan(theta) uniform in 1.25..2.0
  ('hold') or 0.2..0.8 ('slide'); phi goes to the slab or to the prism (drawn),
  the other gets phi plus 5..25 deg: a contact takes the smaller angle.
"""
import math

import numpy as np

G = 9.81
ROCK = dict(young=1e10, poisson=0.25, density=2600.0)   # hard rock [Pa, -, kg/m^3]
PENALTY = 40.0        # contactPenaltyFactor's default: kn = 40 x the smaller E x size (cube root of volume) [N/m]
SHEAR_RATIO = 0.4     # shearStiffnessRatio's default: ks = 0.4 kn
SLOPE_DEG = (10.0, 35.0)
CORNERS = (5, 9)
DIAMETER = (0.6, 1.6)         # footprint diameter [m]
MIN_EDGE = 0.15               # shortest edge / diameter
MIN_TURN_DEG = 12.0           # every corner turns by at least this (interior angle <= 180 - this)
MIN_WIDTH = 0.35              # narrowest width / diameter
TOPPLE_MARGIN = 0.1           # the lines of action meet the base this x the narrowest width inside
MIN_HEIGHT = 0.2              # [m]
MAX_HEIGHT = 1.5              # [m]
FS_RANGE = {'hold': (1.25, 2.0), 'slide': (0.2, 0.8)}
DURATION = 1.0                # [s] of motion the slab must leave room for


def slope_frame(theta, azimuth):
    """(downhill, across, normal) unit vectors (numpy) of a plane of slope theta dipping towards
    the horizontal direction (cos azimuth, sin azimuth, 0); right-handed."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(azimuth), math.sin(azimuth)
    downhill = np.array([ct * ca, ct * sa, -st])
    across = np.array([-sa, ca, 0.0])
    normal = np.array([st * ca, st * sa, ct])
    return downhill, across, normal


def convex_hull_2d(points):
    """Indices of the convex hull of 2D points, counter-clockwise (Andrew's monotone chain);
    collinear points are left out."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    hull = []
    for sweep in (order, order[::-1]):
        chain = []
        for i in sweep:
            while len(chain) >= 2 and turn(points[chain[-2]], points[chain[-1]], points[i]) <= 0:
                chain.pop()
            chain.append(i)
        hull += chain[:-1]
    return hull


def polygon_area_centroid(poly):
    """Area [m^2] and centroid [m] of a counter-clockwise polygon (n x 2 array)."""
    x, y = poly[:, 0], poly[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2
    return area, np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area)


def edge_normals(poly):
    """Outward unit normals (n x 2) of a counter-clockwise polygon's edges (edge i: corner i to i+1)."""
    e = np.roll(poly, -1, axis=0) - poly
    n = np.stack([e[:, 1], -e[:, 0]], axis=1)
    return n / np.linalg.norm(n, axis=1)[:, None]


def inside_distance(poly, p):
    """Smallest distance [m] from the 2D point p to the edges' lines of a convex polygon;
    negative when p is outside."""
    n = edge_normals(poly)
    return float(np.min(np.einsum('ij,ij->i', poly - p, n)))


def polygon_shape(poly):
    """(diameter, shortest edge, smallest turn [rad], narrowest width) of a convex CCW polygon."""
    diameter = max(np.linalg.norm(a - b) for a in poly for b in poly)
    edges = np.roll(poly, -1, axis=0) - poly
    lengths = np.linalg.norm(edges, axis=1)
    turns = [math.atan2(np.cross(edges[i - 1], edges[i]), np.dot(edges[i - 1], edges[i])) for i in range(len(poly))]
    n = edge_normals(poly)
    width = min(float(np.max((poly - poly[i]) @ -n[i])) for i in range(len(poly)))
    return diameter, float(lengths.min()), min(turns), width


def draw_footprint(rng):
    """A convex polygon (k x 2, counter-clockwise) of CORNERS corners that passes the sliver checks,
    its centroid at the origin, spun by a random angle; and the number of draws it took."""
    for attempt in range(1, 10000):
        k = int(rng.integers(CORNERS[0], CORNERS[1] + 1))
        a, b = rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.0)
        gaps = rng.uniform(0.5, 1.5, k)           # angular gaps between corners, at most 3:1
        angles = rng.uniform(0, 2 * math.pi) + 2 * math.pi * np.cumsum(gaps) / gaps.sum()
        radii = rng.uniform(0.8, 1.0, k)
        pts = np.stack([a * radii * np.cos(angles), b * radii * np.sin(angles)], axis=1)
        hull = convex_hull_2d([tuple(p) for p in pts])
        if len(hull) != k:
            continue
        poly = pts[hull]
        diameter, shortest, turn, width = polygon_shape(poly)
        if shortest < MIN_EDGE * diameter or turn < math.radians(MIN_TURN_DEG) or width < MIN_WIDTH * diameter:
            continue
        poly = poly * (rng.uniform(*DIAMETER) / diameter)
        poly = poly - polygon_area_centroid(poly)[1]
        spin = rng.uniform(0, 2 * math.pi)
        c, s = math.cos(spin), math.sin(spin)
        return poly @ np.array([[c, s], [-s, c]]), attempt
    raise RuntimeError('no footprint passed the sliver checks in 10000 draws')


def largest_height(poly, theta):
    """The tallest prism [m] on footprint `poly` (centroid at the origin, x downhill) whose
    gravity line meets the base at least TOPPLE_MARGIN x the narrowest width inside it:
    the point (h/2) tan(theta) downhill moves towards edge i's line at the rate n_i . x."""
    margin = TOPPLE_MARGIN * polygon_shape(poly)[3]
    n = edge_normals(poly)
    room = np.einsum('ij,ij->i', poly, n) - margin      # distance of the origin to each edge line, less the margin
    if room.min() <= 0:
        return 0.0
    rates = n[:, 0]
    shift = min(room[i] / rates[i] for i in range(len(poly)) if rates[i] > 0)
    return 2 * shift / math.tan(theta)


def draw_case(seed, regime):
    """The random scene for `seed` and regime 'hold' or 'slide' (module docstring): a dict with
    theta, azimuth, phi (the contact's angle), phiSlab, phiPrism [rad], fs, footprint (k x 2, slope
    coordinates: x downhill, y across), height, frame, origin, prism (2k corners), slab (8 corners)."""
    rng = np.random.default_rng([seed, 0 if regime == 'hold' else 1])
    while True:
        theta = math.radians(rng.uniform(*SLOPE_DEG))
        poly, _ = draw_footprint(rng)
        hmax = min(largest_height(poly, theta), MAX_HEIGHT)
        if hmax > MIN_HEIGHT:
            break
    height = rng.uniform(MIN_HEIGHT, hmax)
    azimuth = rng.uniform(0, 2 * math.pi)
    fs = rng.uniform(*FS_RANGE[regime])
    phi = math.atan(fs * math.tan(theta))
    other = phi + math.radians(rng.uniform(5, 25))
    slabLower = bool(rng.integers(0, 2))
    origin = rng.uniform(-10, 10, 3)
    frame = slope_frame(theta, azimuth)
    downhill, across, normal = frame

    def at(x, y, z):
        return tuple(float(v) for v in origin + x * downhill + y * across + z * normal)

    prism = [at(x, y, 0.0) for x, y in poly] + [at(x, y, height) for x, y in poly]
    reach = np.abs(poly).max()
    slide = G * math.sin(theta) * DURATION ** 2 / 2      # farther than any slide with friction
    lo, hi = (-reach - 1.0, -reach - 1.0, -1.0), (reach + slide + 1.0, reach + 1.0, 0.0)
    slab = [at(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]
    return dict(seed=seed, regime=regime, theta=theta, azimuth=azimuth, fs=fs, phi=phi,
                phiSlab=phi if slabLower else other, phiPrism=other if slabLower else phi,
                footprint=poly, height=height, hmax=hmax, frame=frame, origin=origin, prism=prism, slab=slab)


def describe(case):
    """One line naming the case's draws (printed with every failure)."""
    return ('seed %d (%s): theta %.2f deg, azimuth %.1f deg, FS %.3f (phi %.2f deg; slab %.1f, prism %.1f), '
            '%d corners, diameter %.3f m, h %.3f m (h_max %.3f m)'
            % (case['seed'], case['regime'], math.degrees(case['theta']), math.degrees(case['azimuth']), case['fs'],
               math.degrees(case['phi']), math.degrees(case['phiSlab']), math.degrees(case['phiPrism']),
               len(case['footprint']), polygon_shape(case['footprint'])[0], case['height'], case['hmax']))


def prism_mass_properties(case):
    """Volume [m^3], mass [kg] and size (cube root of the volume) [m] of the case's prism."""
    area, _ = polygon_area_centroid(case['footprint'])
    volume = area * case['height']
    return volume, ROCK['density'] * volume, volume ** (1 / 3)


def sliding_acceleration(case):
    """a = g (sin theta - tan(phi) cos theta) [m/s^2] along the dip direction (Coulomb, rigid block)."""
    return G * (math.sin(case['theta']) - math.tan(case['phi']) * math.cos(case['theta']))


def settlement_bound(case):
    """An upper bound [m] on how far the held prism's centroid may move while it settles onto its
    contact springs and strains under its own weight, from the drawn geometry alone.

    Springs: with kn = PENALTY E size and ks = SHEAR_RATIO kn (size = the prism's, the smaller
    block), even if one sub-contact carried the whole weight its spring would shorten by
    m g cos(theta) / kn and stretch by m g sin(theta) / ks; that moves the base corners by
    at most u = m g (cos(theta) / kn + sin(theta) / ks). Tilt: the corners sink by different
    amounts, each at most m g cos(theta) / kn, turning the base by at most that over the
    footprint's narrowest width w, which moves the centroid by R / w times as much (R the
    largest distance from the centroid to a base corner).
    Strain: a DDA block's strain is uniform; at rest its stress is the contact forces' first
    moment over the volume, sigma = sym(sum F_k (x_k - c)^T) / V, so |sigma| <= (sum |F_k|) R / V
    <= m g (cos(theta) + sin(theta)) R / V (normal forces sum to m g cos, shear forces, all
    along the dip when it does not turn, to m g sin); the isotropic compliance's largest
    eigenvalue is (1 + nu) / E, so |strain| <= (1 + nu) rho g (cos + sin) R / E and the
    centroid moves relative to a base corner by at most |strain| R.
    With the start from rest (the default) the weight is not applied suddenly, so no
    dynamic factor of 2 is needed.
    """
    volume, mass, size = prism_mass_properties(case)
    theta = case['theta']
    kn = PENALTY * ROCK['young'] * size
    ks = SHEAR_RATIO * kn
    weight = mass * G
    radius = max(math.hypot(math.hypot(x, y), case['height'] / 2) for x, y in case['footprint'])
    width = polygon_shape(case['footprint'])[3]
    springs = weight * (math.cos(theta) / kn + math.sin(theta) / ks)
    tilt = weight * math.cos(theta) / kn * radius / width
    strain = (1 + ROCK['poisson']) * ROCK['density'] * G * (math.cos(theta) + math.sin(theta)) * radius / ROCK['young']
    return springs + tilt + strain * radius


# ---------------------------------------------------------------- YADE scene (imports YADE lazily)

def build(case):
    """The case's fixed slab and free prism in the current scene; returns (slab id, prism id)."""
    from yade_dda import O, ddaBlock
    from yade import wrapper

    def material(phi):
        return O.materials.append(wrapper.PolyhedraMat(frictionAngle=phi, **ROCK))

    slab = O.bodies.append(ddaBlock(case['slab'], material=material(case['phiSlab']), fixed=True))
    prism = O.bodies.append(ddaBlock(case['prism'], material=material(case['phiPrism'])))
    return slab, prism
