# -*- coding: utf-8 -*-
"""Geometry of the three test scenes of Wu, Zhu, Zhuang, Ma & Cai (2014),
*A multi-shell cover algorithm for contact detection in 3D DDA*, Section 5.

Pure Python (math only, no YADE), so the blocks can be built, checked or
handed to another tool (a collider comparison, a plot) without a simulation::

    import paper_scenes as scenes
    blocks, material = scenes.hexahedra_drop(length=40)
    for vertices, fixed in blocks: ...

Every builder returns ``(blocks, material)``: ``blocks`` is a list of
``(vertices, fixed)`` with ``vertices`` a list of (x, y, z) corners [m] and
``fixed`` a bool; ``material`` is a dict ``young`` [Pa], ``poisson`` [-],
``density`` [kg/m^3], ``frictionAngle`` [rad] (0: the paper's scenes are
frictionless). Fixed blocks come first. z is up, gravity is (0, 0, -9.81).

The paper's figures are missing from our copy (OCR text only), so the
arrangements are reconstructions; each builder's docstring lists what the text
gives and what is assumed. Common to all three (Section 5): largest time step
0.001 s and largest vertex displacement per step 0.01 m (``STEP``).
"""
import math

G = 9.81
STEP = dict(dt=1e-3, maxDisplacement=0.01)   # Section 5: max dt [s], allowed step displacement [m]


# ---------------------------------------------------------------- small vector helpers

def _add(*vs):
    return tuple(sum(v[i] for v in vs) for i in range(3))


def _scale(s, v):
    return (s * v[0], s * v[1], s * v[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(v):
    n = math.sqrt(_dot(v, v))
    return (v[0] / n, v[1] / n, v[2] / n)


def box(lo, hi):
    """The 8 corners of the axis-aligned box [lo, hi] [m]."""
    return [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]


def frame_box(origin, axes, lo, hi):
    """Corners of a box given by its frame coordinates [lo, hi] in the
    orthonormal frame ``axes`` = (e1, e2, e3) placed at ``origin``."""
    return [_add(origin, *(_scale(c, e) for c, e in zip(p, axes))) for p in box(lo, hi)]


def material(young, density, poisson=0.25, frictionAngle=0.0):
    return dict(young=float(young), poisson=float(poisson), density=float(density), frictionAngle=float(frictionAngle))


def counts(blocks):
    """(total, fixed, free) block counts."""
    nfixed = sum(1 for _, fixed in blocks if fixed)
    return len(blocks), nfixed, len(blocks) - nfixed


def bounds(blocks):
    """Axis-aligned bounds (lo, hi) of all corners [m]."""
    pts = [p for vertices, _ in blocks for p in vertices]
    return (tuple(min(p[i] for p in pts) for i in range(3)), tuple(max(p[i] for p in pts) for i in range(3)))


# ---------------------------------------------------------------- 5.1 hexahedra drop

def hexahedra_drop(length=20.0, width=1.0, layers=4, perLayer=17, slope=math.radians(25), gap=0.2):
    """Section 5.1, Fig. 10: 70 blocks, 68 free slender hexahedra dropped onto
    two fixed pentahedra; E = 4 MPa, nu = 0.25, rho = 2600 kg/m^3, frictionless.

    From the text: 70 blocks; the two pentahedra (triangular prisms) at the
    bottom are fixed (the paper holds each by four nodes; here they are
    ``fixed`` blocks, which is the same for a rigid support), the hexahedra
    are free; the hexahedra's long axis is 20, 40 or 60 m (``length``, the
    slenderness parameter of the three cases: 1, 2 or 3 shells per block in
    MSC).

    Assumed (Fig. 10 is missing):

    - hexahedra are ``length`` x ``width`` x ``width`` boxes (1 x 1 m section);
    - they lie in ``layers`` = 4 horizontal layers of ``perLayer`` = 17 parallel
      blocks (68), alternate layers crossing: layer 0 (lowest) along x, layer 1
      along y, ...; in a layer the blocks are spread over ``length`` at a pitch
      of length / perLayer (1.18 m for 20 m: 0.18 m gaps), so every layer covers
      the same length x length square and each block crosses all blocks of the
      next layer; layers are ``gap`` = 0.2 m apart;
    - the two pentahedra are right-triangular prisms along y, length + 4 m long,
      whose inclined faces (``slope`` = 25 degrees) form a symmetric V-shaped
      trough, half-width length / 2 + 2 m, meeting at the line x = 0, z = 0;
    - the lowest layer starts ``gap`` above the points where its block ends
      would touch the trough faces, so it lands first, on both faces at once.
    """
    L, a = float(length), float(width)
    half = L / 2 + 2.0                       # trough half-width [m]
    rim = half * math.tan(slope)             # trough rim height [m]
    y0, y1 = -L / 2 - 2.0, L / 2 + 2.0
    blocks = []
    # Fixed pentahedra (6 corners each): triangle (x, z) extruded along y.
    for side in (-1.0, 1.0):
        tri = [(0.0, 0.0), (side * half, 0.0), (side * half, rim)]
        blocks.append(([(x, y, z) for y in (y0, y1) for x, z in tri], True))
    pitch = L / perLayer
    z = (L / 2) * math.tan(slope) + gap      # bottom of layer 0: the blocks' ends are at x = +-L/2
    for layer in range(layers):
        for k in range(perLayer):
            c = -L / 2 + (k + 0.5) * pitch   # centre across the block's long axis
            if layer % 2 == 0:               # along x
                lo, hi = (-L / 2, c - a / 2, z), (L / 2, c + a / 2, z + a)
            else:                            # along y
                lo, hi = (c - a / 2, -L / 2, z), (c + a / 2, L / 2, z + a)
            blocks.append((box(lo, hi), False))
        z += a + gap
    return blocks, material(young=4e6, density=2600)


# ---------------------------------------------------------------- 5.2 blocks slide

# Direction cosines of the blocks' main axis. The OCR'd text gives 50, 135 and
# 120 degrees to +x, +y, +z, but cos^2 50 + cos^2 135 + cos^2 120 = 1.163 != 1.
# 60, 135, 120 degrees give exactly 0.25 + 0.5 + 0.25 = 1: a one-digit misread
# (5 for 6) makes the text consistent, so that is the direction used.
# (Normalising the OCR'd cosines instead would give 53.4, 131.0, 117.6 degrees.)
SLIDE_AXIS_ANGLES = (60.0, 135.0, 120.0)


def slide_frame(crossTilt=math.radians(15)):
    """(s, t, n) frame of the slanted chute: s = the blocks' main axis
    (downhill, 30 degrees below horizontal), t = across the chute, n = the
    bed's upward normal; right-handed. The bed is tilted by ``crossTilt``
    about s, so gravity also presses the sliding blocks towards +t (the wall)."""
    s = tuple(math.cos(math.radians(a)) for a in SLIDE_AXIS_ANGLES)
    v = _unit(_cross((0.0, 0.0, 1.0), s))    # horizontal, across
    w = _cross(s, v)                         # upward normal of an untilted bed
    c, si = math.cos(crossTilt), math.sin(crossTilt)
    t = _add(_scale(c, v), _scale(-si, w))
    n = _add(_scale(si, v), _scale(c, w))
    return s, t, n


def slanted_slide(crossTilt=math.radians(15), gap=0.002):
    """Section 5.2, Fig. 13: 23 blocks, 14 fixed (a bed and a side wall) and
    9 sliding without initial velocity and without friction;
    E = 10 MPa, nu = 0.25, rho = 2600 kg/m^3.

    From the text: 23 blocks; "eleven blocks at the bottom and a side are
    fixed", "the other 9" slide; 11 + 9 = 20 != 23, while 23 is also what the
    MSC shell counts add up to (3 + 8 + 12), and "the sliding nine blocks"
    is repeated later. So 23 total and 9 sliding are kept and 14 are fixed.
    The blocks' main axes make 60, 135, 120 degrees with +x, +y, +z (see
    ``SLIDE_AXIS_ANGLES``: the OCR'd 50 degrees is inconsistent): the main
    axis points 30 degrees below horizontal, so it is the sliding direction.

    Assumed (Fig. 13 is missing), in the chute frame (s, t, n) of
    ``slide_frame`` with the origin at the top inner corner of the bed:

    - bed: 10 fixed blocks, 5 along s (8 m each) x 2 across (3 m each), 1 m
      thick: s in [0, 40], t in [-3, 3], n in [-1, 0];
    - side wall: 4 fixed blocks 10 m x 1 m x 5 m standing on the bed's +t
      side: t in [3, 4], n in [-1, 4];
    - sliding: 9 free 4 x 1 x 1 m blocks (long along s) stacked 3 across x 3
      high against the wall at the top of the chute (s in [1, 5]), ``gap``
      (2 mm) apart and above the bed and wall;
    - the bed is tilted ``crossTilt`` = 15 degrees about s towards the wall,
      so the stack leans on the wall while it slides (bed, wall and
      block-block contacts); every block's main axis is still s.
    """
    s, t, n = slide_frame(crossTilt)
    axes = (s, t, n)
    origin = (0.0, 0.0, 30.0)
    blocks = []
    for i in range(5):
        for j in range(2):
            blocks.append((frame_box(origin, axes, (8.0 * i, -3.0 + 3.0 * j, -1.0), (8.0 * i + 8, 3.0 * j, 0.0)), True))
    for i in range(4):
        blocks.append((frame_box(origin, axes, (10.0 * i, 3.0, -1.0), (10.0 * i + 10, 4.0, 4.0)), True))
    for col in range(3):                     # col 0 against the wall
        t1 = 3.0 - gap - col * (1.0 + gap)
        for layer in range(3):
            n0 = gap + layer * (1.0 + gap)
            blocks.append((frame_box(origin, axes, (1.0, t1 - 1.0, n0), (5.0, t1, n0 + 1.0)), False))
    return blocks, material(young=10e6, density=2600)


# ---------------------------------------------------------------- 5.3 single block slide

def single_block_slide(rows=2, arcBlocks=100, arcDegrees=120.0, start=50.0, gap=0.01,
                       blockSize=(2.0, 1.2, 1.0)):
    """Section 5.3, Fig. 16: 201 blocks, 200 fixed 10 x 1 x 1 m blocks (long
    along x) forming an approximately curved surface, and one free block
    sliding down it; E = 4 MPa, nu = 0.25, rho = 2800 kg/m^3, frictionless.

    From the text: 200 fixed blocks, each 10 m along x with a 1 x 1 m
    section, approximate a curved surface; one block slides down it;
    fixed-fixed pairs are not searched (as in our engine).

    Assumed (Fig. 16 is missing):

    - the surface is a cylindrical trough with its axis along x: ``rows`` = 2
      rows of blocks (x in [-10, 0] and [0, 10]), each of ``arcBlocks`` = 100
      blocks side by side along a circular arc in the y-z plane spanning
      ``arcDegrees`` = 120 degrees (-60 to +60 from the bottom);
    - each fixed block's top face is a 1 m chord of the circle of radius
      R = 1 / (2 sin(pi / 300)) = 47.75 m centred at (y, z) = (0, R), so the
      trough's bottom is at z = 0, its rims at z = R / 2 = 23.9 m, and the
      chords meet at exactly shared edges (a polygonal surface with kinks of
      1.2 degrees); the 1 x 1 m sections fan out below the surface;
    - the free block is a ``blockSize`` = 2 (x) x 1.2 (along the slope) x 1 m
      (normal) box straddling the joint x = 0 between the two rows, on the
      chord nearest ``start`` = 50 degrees up the +y side, its bottom face
      parallel to that chord and ``gap`` = 10 mm above it (the neighbouring
      chords curve up by 2 mm under its overhanging ends), at rest; it
      slides down towards y = 0 and up the other side.
    """
    span = math.radians(arcDegrees)
    step = span / arcBlocks                  # angle per chord
    R = 0.5 / math.sin(step / 2)             # chord length exactly 1 m
    phi = [-span / 2 + k * step for k in range(arcBlocks + 1)]
    P = [(R * math.sin(f), R - R * math.cos(f)) for f in phi]   # (y, z) on the circle
    rowLength = 10.0
    x0 = -rows * rowLength / 2
    blocks = []
    for r in range(rows):
        xa, xb = x0 + r * rowLength, x0 + (r + 1) * rowLength
        for k in range(arcBlocks):
            fm = (phi[k] + phi[k + 1]) / 2
            out = (math.sin(fm), -math.cos(fm))                  # outward (away from the centre)
            section = [P[k], P[k + 1], (P[k + 1][0] + out[0], P[k + 1][1] + out[1]),
                       (P[k][0] + out[0], P[k][1] + out[1])]
            blocks.append(([(x, y, z) for x in (xa, xb) for y, z in section], True))
    # The free block on chord j.
    j = min(range(arcBlocks), key=lambda k: abs((phi[k] + phi[k + 1]) / 2 - math.radians(start)))
    fm = (phi[j] + phi[j + 1]) / 2
    mid = ((P[j][0] + P[j + 1][0]) / 2, (P[j][1] + P[j + 1][1]) / 2)
    tangent = (0.0, math.cos(fm), math.sin(fm))
    inward = (0.0, -math.sin(fm), math.cos(fm))
    bx, bt, bn = blockSize
    origin = (0.0, mid[0], mid[1])
    blocks.append((frame_box(origin, ((1.0, 0.0, 0.0), tangent, inward),
                             (-bx / 2, -bt / 2, gap), (bx / 2, bt / 2, gap + bn)), False))
    return blocks, material(young=4e6, density=2800)


SCENES = {
    'hexahedra_drop': hexahedra_drop,
    'slanted_slide': slanted_slide,
    'single_block_slide': single_block_slide,
}
