"""Hard cases: placements and motions where contact DDA is known to
break, each checked for what could go wrong.

Every case runs under the common guards of `hardguards.Guard`, after every
step: finite state; no two blocks overlapping by more than the penetration
tolerance (doc/testing.md, "Penetration tolerance"), both as the core reports its
contacts and as the true overlap of the blocks' current shapes; no energy
gain beyond round-off (kinetic + gravity + strain + contact springs); the
open-close iteration never accepted unconverged and its dt cuts bounded; and
the run is deterministic (the same scene again, with 2 threads instead of 1,
is bitwise the same). Each case adds what is specific to it (a stack that
must stand, a block that must come back up, a wedge that must slide or
stay).

Quick cases run in the default `pytest tests/py`; the long ones (marked
`slow`) run with `make test-hard`.

All blocks are rock (E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3) unless a case
says otherwise; contact stiffness kn = 40 E size (4e11 N/m for a 1 m cube).
"""
import math

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator

import scenes as S
from scenes import G
from helpers import rotate
from hardguards import Guard, fingerprint

GRAVITY = (0.0, 0.0, -G)
deg = math.radians


# ---------------------------------------------------------------- scene building

def rock(frictionDeg=0.0, young=S.ROCK['young']):
    return S.rock(frictionDeg, young=young)


def floor(top=0.0, size=(-4.0, -4.0, 8.0, 8.0), thickness=1.0, frictionDeg=0.0, young=S.ROCK['young']):
    x0, y0, x1, y1 = size
    return S.add_block(S.box((x0, y0, top - thickness), (x1, y1, top)), rock(frictionDeg, young), fixed=True)


def shifted(points, offset):
    return [S.add(p, offset) for p in points]


def corner_down_cube(apex, side=1.0, turn=0.0):
    """A cube standing on a corner: its body diagonal vertical, the lowest corner at `apex`."""
    pts = S.box((0, 0, 0), (side, side, side))
    # turn the diagonal (1, 1, 1) onto +z: about (1, -1, 0) by acos(1/sqrt 3)
    pts = rotate(pts, (1, -1, 0), math.acos(1 / math.sqrt(3)))
    if turn:
        pts = rotate(pts, (0, 0, 1), turn)
    low = min(pts, key=lambda p: p[2])
    return shifted(pts, S.sub(apex, low))


def corner_up_cube(apex, side=1.0, turn=0.0):
    """A cube on a corner upside down: its highest corner at `apex`."""
    pts = corner_down_cube((0, 0, 0), side, turn)
    high = max(pts, key=lambda p: p[2])
    return shifted(pts, S.sub(apex, high))


def edge_bar(length, width, direction, edgeAt, up=True):
    """A square bar (length x width x width) along the horizontal unit `direction`,
    turned 45 deg about its axis so one edge is straight up (up=True) or down;
    that edge's midpoint at `edgeAt`."""
    pts = S.box((-length / 2, -width / 2, -width / 2), (length / 2, width / 2, width / 2))
    pts = rotate(pts, (1, 0, 0), deg(45))
    angle = math.atan2(direction[1], direction[0])
    pts = rotate(pts, (0, 0, 1), angle)
    reach = width / math.sqrt(2)
    return shifted(pts, S.sub(edgeAt, (0.0, 0.0, reach if up else -reach)))


def integrator(threads=1, **kw):
    params = dict(dt=1e-3, gravity=GRAVITY, maxDisplacement=0.01, threads=threads)
    params.update(kw)
    return DDAIntegrator(label='dda', **params)


def bodies():
    """Body ids of the scene's DDA blocks (moving and fixed), in block order."""
    ddaScene = yade_dda.scene.current(create=False)
    ddaScene.resolvePending()
    return list(ddaScene.bodyOfBlock)


def run_case(build, steps, guardOptions=None, every=None, gravity=GRAVITY, **integratorOptions):
    """Runs a hard case under every guard; returns (guard, what `build` returned).

    `every(built)`, if given, is called after each guarded step (to record
    the motion on the way).
    First the scene is built and run `steps` steps with 2 threads, unguarded,
    and fingerprinted; then built again and run with 1 thread, checking every
    guard after every step, and its fingerprint must be bitwise that of the
    first run (determinism: the same scene twice, with 1 and 2 threads; the
    core uses threads only from 1024 items, so for the small scenes this is
    the rerun, and test_threads_do_not_change_a_hard_field engages them).
    """
    fingerprints = []
    for threads in (2, 1):
        O.reset()
        built = build()
        O.engines = [integrator(threads=threads, gravity=gravity, **integratorOptions)]
        if threads == 2:
            for _ in range(steps):
                O.step()
        else:
            guard = Guard(bodies(), gravity, **(guardOptions or {}))
            guard.run(steps, None if every is None else lambda step: every(built))
        fingerprints.append(fingerprint())
    assert fingerprints[0] == fingerprints[1], 'the run with 2 threads differs from the run with 1'
    return guard, built


def centroid(body):
    return tuple(yade_dda.block(body).centroid)


def velocity(body):
    return tuple(yade_dda.block(body).velocity)


def horizontal(v):
    return math.hypot(v[0], v[1])


# ================================================================ the checker itself (no DDA)

def test_overlap_depth_matches_closed_forms():
    """The guards' own overlap measure (hardguards.overlap_depth) on placements with a known answer:
    boxes overlapping by 0.1 m along x, apart by 0.2 m, touching; a cube on its corner sunk
    1e-3 m into a box (a face axis); two crossing bars turned 45 deg on their axes, edge sunk
    1e-3 m into edge (an edge-edge axis: no face axis sees it); the same bars 1e-8 rad from
    parallel, where the shortest way out is along a face normal at 45 deg: (1e-3 + 1.5e-8) / sqrt(2)
    (the twist moves the bars' ends 1.5e-8 m apart sideways)."""
    import numpy
    from hardguards import Topology, overlap_depth

    cube = S.box((0, 0, 0), (1, 1, 1))
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    edges = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)]
    topo = Topology(faces, edges)

    def depth(a, b):
        return overlap_depth(numpy.array(a, float), topo, numpy.array(b, float), topo)

    assert abs(depth(cube, shifted(cube, (0.9, 0.2, 0.1))) - 0.1) < 1e-12
    assert depth(cube, shifted(cube, (1.2, 0, 0))) <= -0.2 + 1e-12
    assert abs(depth(cube, shifted(cube, (1.0, 0.3, 0)))) < 1e-12
    slab = S.box((-2, -2, -1), (2, 2, 0))
    apex = corner_down_cube((0.1, 0.2, -1e-3))
    assert abs(depth(slab, apex) - 1e-3) < 1e-12
    for theta, expected in ((math.pi / 2, 1e-3), (1e-8, (1e-3 + 1.5e-8) / math.sqrt(2))):
        low = edge_bar(3.0, 0.5, (1, 0, 0), (0, 0, 0), up=True)
        high = edge_bar(3.0, 0.5, (math.cos(theta), math.sin(theta), 0), (0, 0, -1e-3), up=False)
        assert abs(depth(low, high) - expected) < 1e-12, theta


# ================================================================ degenerate geometry

CORNER_DROPS = ['aligned', 'apex', 'apex-turned']


@pytest.mark.parametrize('placement', CORNER_DROPS)
def test_corner_dropped_exactly_on_corner(scene, placement):
    """A cube dropped 2 cm so that a corner lands exactly on a corner of a fixed cube.

    What could go wrong: the vertex-vertex contact has no defined normal
    (NaN from normalising a zero vector, or the normal flipping between the
    candidate faces every step and the open-close iteration cycling); the
    two coincident corners give two opposed contacts at one point; the
    contact is missed and the corner sinks in; the corners slide past each
    other and their edges cross unseen. Placements: 'aligned' (axis-aligned
    cubes, corner (1, 1, 1) onto corner (1, 1, 1), the upper cube then tips
    off onto the floor), 'apex' (both cubes on a corner, body diagonals
    vertical and in line: an unstable balance), 'apex-turned' (the same, the
    upper cube turned 0.3 rad about the vertical, so its edges at the apex
    lie between the lower cube's). 0.4 s.
    """
    def build():
        if placement == 'aligned':
            floor(0.0, frictionDeg=30)
            S.add_block(S.box((0, 0, 0), (1, 1, 1)), rock(30), fixed=True)
            return S.add_block(S.box((1, 1, 1.02), (2, 2, 2.02)), rock(30))
        floor(-3.0, frictionDeg=30)
        S.add_block(corner_up_cube((0, 0, 0)), rock(30), fixed=True)
        return S.add_block(corner_down_cube((0, 0, 0.02), turn=0.3 if placement == 'apex-turned' else 0.0), rock(30))

    guard, cube = run_case(build, 400)
    assert guard.worstPenetration > 0   # the corners did meet


EDGE_CROSSINGS = {'90deg': math.pi / 2, '30deg': math.radians(30)}
NEAR_PARALLEL = [pytest.param(t, id='%g' % t) for t in (1e-2, 1e-4, 1e-6, 1e-8, 0.0)]


def edge_on_edge(theta, gap=0.02):
    """A fixed square bar with an edge straight up and a moving one above it with an edge straight
    down, turned by theta about the vertical, the edges' midpoints one above the other `gap` apart
    (3 m x 0.5 m x 0.5 m bars, friction 30 deg, a floor 2 m below)."""
    def build():
        floor(-2.0, frictionDeg=30)
        S.add_block(edge_bar(3.0, 0.5, (1, 0, 0), (0, 0, 0), up=True), rock(30), fixed=True)
        return S.add_block(edge_bar(3.0, 0.5, (math.cos(theta), math.sin(theta), 0), (0, 0, gap), up=False),
                           rock(30))
    return build


@pytest.mark.parametrize('angle', list(EDGE_CROSSINGS))
def test_crossing_edges_meet_edge_on_edge(scene, angle):
    """A bar dropped edge-down across a fixed bar's upward edge (at 90 and 30 deg): the blocks meet at
    one point, where two edges cross.

    What could go wrong: no face of either block is the entrance (every face
    normal is 45 deg off the contact normal), so a narrow phase that only
    looks at faces either misses the contact (the bars sink into each other)
    or pushes along a face normal (sideways kick, energy gain); the crossing
    point of the edges is found but the normal (their cross product) is
    oriented the wrong way. The upper bar must rest on the crossing: it ends
    above the lower edge by no more than its own edge height and has not
    fallen through.
    """
    guard, bar = run_case(edge_on_edge(EDGE_CROSSINGS[angle]), 400)
    assert guard.worstPenetration > 0
    lowest = min(v[2] for v in yade_dda.block(bar).vertices)
    assert lowest > -guard.penetration()


@pytest.mark.parametrize('theta', NEAR_PARALLEL)
def test_near_parallel_edges(scene, theta):
    """The same two bars with their edges theta from parallel, theta = 1e-2 down to 1e-8 rad and 0.

    What could go wrong: the crossing point of nearly parallel lines lies
    far away (up to L / theta) or is NaN; their cross product, the edge-edge
    normal, is round-off and points anywhere; the iteration flips between a
    crossing contact and the end-point contacts. The upper bar balances on a
    line and soon rolls off one side; it must do so without blowing up,
    sinking in or gaining energy.
    """
    guard, bar = run_case(edge_on_edge(theta), 400)
    assert guard.worstPenetration > 0


STACKS = ['aligned', 'offset', 'turned45', 'turned1e-9']


@pytest.mark.parametrize('kind', STACKS)
def test_coplanar_face_on_face_stack(scene, kind):
    """Three 1 m cubes stacked face on face on a floor, touching exactly (gap 0), friction 30 deg, 0.5 s.

    Kinds: 'aligned' (every edge of a joint coincides with one of the other
    block: collinear edges, coincident corners), 'offset' (the middle cube
    shifted (0.3, 0.2) m: corners on the other's faces, edges crossing
    edges in the plane of the joint), 'turned45' (the middle cube turned 45
    deg about the vertical: eight in-plane edge crossings per joint),
    'turned1e-9' (turned 1e-9 rad: edges parallel to round-off).
    What could go wrong: coplanar faces give gap-0 contacts with no
    preferred entrance face, edges in the joint plane cross with a normal
    that is round-off, duplicated contacts at coincident corners push twice,
    and the stack creeps or tilts. It must stand: every cube's centroid moves
    less than 1e-5 m sideways and 5e-5 m down (elastic settling ~1e-5 m), and
    turns less than 1e-5 rad.
    """
    def build():
        floor(0.0, frictionDeg=30)
        cubes = []
        for k in range(3):
            pts = S.box((0, 0, k), (1, 1, k + 1))
            if k == 1:
                if kind == 'offset':
                    pts = shifted(pts, (0.3, 0.2, 0))
                elif kind == 'turned45':
                    pts = rotate(pts, (0, 0, 1), math.pi / 4, about=(0.5, 0.5, 0))
                elif kind == 'turned1e-9':
                    pts = rotate(pts, (0, 0, 1), 1e-9, about=(0.5, 0.5, 0))
            cubes.append((S.add_block(pts, rock(30)), tuple(sum(p[i] for p in pts) / 8 for i in range(3))))
        return cubes

    guard, cubes = run_case(build, 500)
    for cube, c0 in cubes:
        d = S.sub(centroid(cube), c0)
        assert horizontal(d) < 1e-5 and -5e-5 < d[2] < 1e-7, (cube, d)
        assert yade_dda.block(cube).rotation.toRotationVector().norm() < 1e-5


# ================================================================ slender blocks, stiffness contrast

SLENDER = ['lengthwise', 'crosswise', 'crosswise-friction30', 'incline']


@pytest.mark.parametrize('motion', SLENDER)
def test_slender_block_sliding(scene, motion):
    """A 60:1 block (6 m x 0.1 m x 0.1 m) sliding: along its length and across it at 2 m/s on a
    frictionless floor, across it at 2 m/s on a floor with 30 deg of friction, and down a 30 deg
    incline with 20 deg of friction, 0.5 s.

    What could go wrong: the block's contact edges are 60 times its size
    (size = cube root of volume, what the penalty and tolerances scale
    with), so a tolerance in units of the size misses contacts along the
    length; the small inertia about the long axis turns a one-sided
    contact force into a fast roll (launched across a frictional floor, its
    new corner contacts must slide from the first step: held locked for a
    step, they tip the block over its long edge); a linearised gap over a
    6 m lever penetrates. On the frictionless floor the block must keep its
    velocity (to 1e-6 m/s horizontally and 1e-6 rad/s: nothing resists); on the
    frictional one it must stop after v^2 / (2 g tan(phi)) within 1% (it
    stops at 0.35 s); on the incline it must follow
    g (sin a - tan(phi) cos a) t^2 / 2 within 1%; it must stay flat (turned
    by less than 1e-4 rad; friction at the base pitches a block on an
    incline by the spring compliance only, 5e-8 rad here).
    """
    speed = 2.0
    friction = 30.0 if motion == 'crosswise-friction30' else 0.0

    def build():
        if motion == 'incline':
            geo, slab, block = S.build_incline(math.radians(30), (6.0, 0.1, 0.1), 20.0,
                                               slab=((-1.0, -1.5, -1.0), (12.0, 1.5, 0.0)))
            return block, geo
        floor(0.0, size=(-2, -2, 20, 20), frictionDeg=friction)
        block = S.add_block(S.box((0, 1, 0), (6, 1.1, 0.1)), rock(friction))
        O.bodies[block].state.vel = (speed, 0, 0) if motion == 'lengthwise' else (0, speed, 0)
        return block, None

    guard, (block, geo) = run_case(build, 500)
    v = velocity(block)
    if motion == 'incline':
        c0 = tuple(sum(p[i] for p in geo['block']) / 8 for i in range(3))
        slid = S.dot(S.sub(centroid(block), c0), geo['frame'][0])
        expected = S.incline_slide_distance(math.radians(30), math.radians(20), O.time)
        assert abs(slid - expected) < 0.01 * expected
    elif friction:
        slid = centroid(block)[1] - 1.05
        expected = speed ** 2 / (2 * G * math.tan(math.radians(friction)))
        assert speed / (G * math.tan(math.radians(friction))) < O.time   # the run outlasts the slide
        assert abs(slid - expected) < 0.01 * expected, (slid, expected)
    else:
        expected = (speed, 0, 0) if motion == 'lengthwise' else (0, speed, 0)
        assert math.hypot(v[0] - expected[0], v[1] - expected[1]) < 1e-6
        # Vertically the block, launched as placed (not settled), still rings on its
        # contact springs as its weight loads them: 4e-7 m/s at 0.5 s without strain
        # viscosity, 1.3e-6 m/s with it (the thin directions' overdamped strain slows
        # the decay).
        assert abs(v[2]) < 1e-5
        assert S.norm(v[3:6]) < 1e-6
    assert yade_dda.block(block).rotation.toRotationVector().norm() < 1e-4


CONTRASTS = ['hard-on-soft', 'soft-on-hard']


@pytest.mark.parametrize('order', CONTRASTS)
def test_stiffness_contrast_of_1e3(scene, order):
    """A 0.8 x 0.6 x 0.6 m block on a 1 m cube on a hard floor, E = 1e10 Pa for one block and 1e7 Pa
    for the other (contrast 1e3), 0.5 s.

    What could go wrong: the contact between them takes the soft block's
    stiffness (kn = 40 min(E size)) while the hard block's elastic and
    inertia terms are 1e3 times stiffer, so the coupled system is badly
    conditioned; the soft block rings (its lowest frequency ~60 rad/s) and
    the contacts open and close with it; the soft contact lets the hard
    block sink 1e3 times deeper than between hard blocks. The pair must stay
    centred (no sideways drift above 1e-6 m), upright and untwisted (turned
    by less than 2e-5 rad: while the soft cube rings, the upper block's
    corner contacts slide on it and twist it by 7e-6 rad about the vertical,
    then lock) and settle by no more than 5 mm (the soft cube's elastic
    shortening under both weights: ~1e-3 m).
    """
    soft, hard = 1e7, 1e10
    lower, upper = (soft, hard) if order == 'hard-on-soft' else (hard, soft)

    def build():
        floor(0.0, frictionDeg=30)
        a = S.add_block(S.box((0, 0, 0), (1, 1, 1)), rock(30, young=lower))
        b = S.add_block(S.box((0.1, 0.2, 1), (0.9, 0.8, 1.6)), rock(30, young=upper))
        return [(a, (0.5, 0.5, 0.5)), (b, (0.5, 0.5, 1.3))]

    guard, blocks = run_case(build, 500)
    for body, c0 in blocks:
        d = S.sub(centroid(body), c0)
        assert horizontal(d) < 1e-6 and -5e-3 < d[2] < 1e-6, (body, d)
        assert yade_dda.block(body).rotation.toRotationVector().norm() < 2e-5


# ================================================================ impact

IMPACTS = {'face': None, 'edge': ((1, 0, 0), math.pi / 4), 'corner': 'corner'}
IMPACT_STEPS = {'dt1ms': dict(dt=1e-3, maxDisplacement=0.02), 'dt10ms': dict(dt=1e-2, maxDisplacement=0.25)}


@pytest.mark.parametrize('steps', list(IMPACT_STEPS))
@pytest.mark.parametrize('orientation', list(IMPACTS))
def test_block_hits_floor_at_20_m_per_s(scene, orientation, steps):
    """A 1 m cube hits a 5 cm thick fixed floor at 20 m/s, face, edge or corner first, with dt = 1 ms
    (0.02 m per step) and 10 ms (0.2 m per step, the allowed displacement 0.25 m), for 0.2 s.

    What could go wrong: the block moves farther in one step than the floor
    is thick, so a contact found only once the blocks overlap comes too
    late and the block tunnels through (or is pushed out the wrong side);
    the penalty spring stops 5e5 J in a few steps and throws the block back
    faster than it came (energy gain); the corner or edge impact tips it
    into a spin. It must end above the floor, moving up, slower than 20 m/s.
    """
    options = IMPACT_STEPS[steps]
    duration = 0.2

    def build():
        floor(0.0, thickness=0.05, frictionDeg=30)
        pts = S.box((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))
        if orientation == 'edge':
            pts = rotate(pts, (1, 0, 0), math.pi / 4)
        elif orientation == 'corner':
            pts = corner_down_cube((0, 0, 0))
        low = min(p[2] for p in pts)
        pts = shifted(pts, (0, 0, 0.05 - low))
        block = S.add_block(pts, rock(30))
        O.bodies[block].state.vel = (0, 0, -20)
        return block

    guard, block = run_case(build, int(round(duration / options['dt'])), **options)
    assert guard.worstPenetration > 0   # it did hit
    assert min(v[2] for v in yade_dda.block(block).vertices) > 0
    v = velocity(block)
    assert 0 < v[2] < 20


# ================================================================ sliding across an edge, spinning

RIDGES = {'1deg': (1.0, 0.0), '5deg': (5.0, 0.0), '2deg-oblique': (2.0, 0.5)}


@pytest.mark.parametrize('ridge', list(RIDGES))
def test_vertex_slides_across_boundary_between_faces(scene, ridge):
    """A 1 x 1 x 0.5 m block slides frictionless at 2 m/s over a ridge: a fixed block whose top is
    two faces sloping down by 1, 5 or 2 deg either side of the edge x = 0 (the last crossed at 0.5
    rad to the ridge's normal), 1 s. Each bottom corner of the block slides from one face onto the
    other, across the edge between them.

    What could go wrong: as a corner reaches the edge its contact must move
    from the first face to the second (contact history keyed by face:
    state and shear spring lost or duplicated); with the corner on the edge
    both faces are equally good entrances and the normal can flip every
    step (iteration cycling); the edge itself acts as an obstacle ("ghost"
    edge, the block stops); the switch of normal gives the block a kick
    (energy gain). Every corner must end past the ridge and the block must
    keep moving forward at >= 60% of its start speed (a block landing on
    the far slope after tipping over the ridge loses some energy in that
    impact: 2.5% to 16% of its kinetic energy here).
    """
    slopeDeg, azimuth = RIDGES[ridge]
    speed = 2.0

    def build():
        t = math.tan(math.radians(slopeDeg))
        L = 6.0
        ridgeBlock = [(-L, -4, -1), (L, -4, -1), (-L, 4, -1), (L, 4, -1),
                      (-L, -4, -L * t), (L, -4, -L * t), (-L, 4, -L * t), (L, 4, -L * t), (0, -4, 0), (0, 4, 0)]
        S.add_block(ridgeBlock, rock(0), fixed=True)
        pts = rotate(S.box((-1.5, -0.5, 0), (-0.5, 0.5, 0.5)), (0, 1, 0), -math.radians(slopeDeg), about=(0, 0, 0))
        block = S.add_block(pts, rock(0))
        c = math.cos(math.radians(slopeDeg))
        O.bodies[block].state.vel = (speed * c * math.cos(azimuth), speed * math.sin(azimuth),
                                     speed * math.sin(math.radians(slopeDeg)) * math.cos(azimuth))
        return block

    guard, block = run_case(build, 1000)
    blk = yade_dda.block(block)
    assert min(v[0] for v in blk.vertices) > 0
    assert blk.velocity[0] > 0.6 * speed * math.cos(azimuth)


SPINS = {'frictionless': (0.0, (1.0, 1.0, 1.0)), 'cube-friction30': (30.0, (1.0, 1.0, 1.0)),
         'slab-friction30': (30.0, (2.0, 0.5, 0.3))}


@pytest.mark.parametrize('spin', list(SPINS))
def test_block_spinning_on_floor(scene, spin):
    """A block resting on a floor, spun at 5 rad/s about the vertical, 1 s.

    What could go wrong: each corner contact slides along a circle, so its
    sliding direction turns every step: friction from a stale direction
    pushes sideways (the block drifts) or along the motion (energy gain);
    the fast tangential motion of the corners over the floor face breaks the
    contact history. Frictionless, no force has a moment about the vertical:
    the angular momentum I_zz w_z must stay its start value (to 1e-6; the
    deformable block's I_zz grows by about 1e-6 as its weight and the spin
    widen it, so w_z itself drops by about 1.6e-6 rad/s);
    with friction 30 deg the four corner contacts, each carrying a quarter
    of the weight at r (half the base diagonal) from the axis, slow it by
    alpha = tan(phi) m g r / I (24.0 and 16.5 rad/s^2; within 2% at
    t = 0.1 s) until it stops (0.21 s, 0.30 s) and stays: turned by less
    than 1e-6 rad over the last 0.5 s. The centroid must not move (1e-6 m).
    """
    friction, (a, b, c) = SPINS[spin]
    omega = 5.0

    def build():
        floor(0.0, frictionDeg=friction)
        block = S.add_block(S.box((-a / 2, -b / 2, 0), (a / 2, b / 2, c)), rock(friction))
        O.bodies[block].state.angVel = (0, 0, omega)
        return block

    spinAt, turnAt, momentum = [], [], []

    def angularMomentum(block):
        blk = yade_dda.block(block)
        J = blk.secondMoment
        return blk.mass / blk.volume * (J[0][0] + J[1][1]) * velocity(block)[5]

    def record(block):
        momentum.append(angularMomentum(block))
        if not spinAt and O.time >= 0.1 - 1e-12:
            spinAt.append((O.time, velocity(block)[5]))
        if not turnAt and O.time >= 0.5 - 1e-12:
            turnAt.append(yade_dda.block(block).rotation)

    guard, block = run_case(build, 1000, every=record)
    w = velocity(block)[3:6]
    d = S.sub(centroid(block), (0, 0, c / 2))
    assert horizontal(d) < 1e-6
    if friction == 0:
        start = (a * a + b * b) / 12 * S.ROCK['density'] * a * b * c * omega
        assert max(abs(h - start) for h in momentum) < 1e-6 * start
        assert abs(w[2] - omega) < 1e-5 and horizontal(w) < 1e-9
    else:
        alpha = math.tan(math.radians(friction)) * G * math.hypot(a, b) / 2 / ((a * a + b * b) / 12)
        t, w01 = spinAt[0]
        assert abs((omega - w01) / t - alpha) < 0.02 * alpha
        turned = yade_dda.block(block).rotation * turnAt[0].conjugate()
        assert turned.toRotationVector().norm() < 1e-6


# ================================================================ wedge at FS = 1

WEDGE_FS = [0.98, 1.02]


@pytest.mark.parametrize('fs', WEDGE_FS)
def test_wedge_at_factor_of_safety_one(scene, fs):
    """A tetrahedral wedge on two fixed planes (plunge of their line 35 deg, right-angled, symmetric),
    friction set for FS = 0.98 and 1.02 (scenes.friction_for_wedge_fs), 2 s (dt 2 ms).

    What could go wrong: at FS 1 +/- 0.02 only 2% of the friction capacity
    separates sliding from standing, so a friction force off by 2% (wrong
    normal force, the wrong friction angle, friction lagging the normal
    force) flips the outcome; contacts on the friction limit switch
    between locked and sliding every iteration. FS 0.98: the wedge slides
    along the line of intersection at g sin(psi) (1 - FS) (0.22 m in 2 s),
    within 3% (0.06% of friction). FS 1.02: it slips during the first
    steps while its contacts load up from zero (< 1e-4 m), then stands:
    no creep (< 1e-9 m over the last 1.5 s).
    """
    def build():
        geo = S.wedge_geometry(math.radians(35), math.radians(90), math.radians(90), azimuth=0.3,
                               origin=(3.0, -2.0, 10.0))
        phiA, phiB = S.friction_for_wedge_fs(geo['nA'], geo['nB'], fs)
        S.add_block(geo['slabA'], rock(math.degrees(phiA)), fixed=True)
        S.add_block(geo['slabB'], rock(math.degrees(phiB)), fixed=True)
        return S.add_block(geo['wedge'], rock(60.0)), geo

    atHalfSecond = []

    def record(built):
        if not atHalfSecond and O.time >= 0.5 - 1e-12:
            atHalfSecond.append(centroid(built[0]))

    guard, (wedge, geo) = run_case(build, 1000, every=record, dt=2e-3, maxDisplacement=0.02)
    c0 = S.tetrahedron_volume_centroid(geo['wedge'])[1]
    d = S.sub(centroid(wedge), c0)
    _, plunge = S.wedge_line(geo['nA'], geo['nB'])
    if fs < 1:
        expected = G * math.sin(plunge) * (1 - fs) * O.time ** 2 / 2
        assert abs(S.dot(d, geo['line']) - expected) < 0.03 * expected
        assert S.norm(d) - abs(S.dot(d, geo['line'])) < 1e-4
    else:
        assert S.norm(d) < 1e-4
        assert S.norm(S.sub(centroid(wedge), atHalfSecond[0])) < 1e-9


# ================================================================ long run, threads

STACK_TILTS = [0.0, 10.0]


@pytest.mark.slow
@pytest.mark.parametrize('tiltDeg', STACK_TILTS, ids=['level', 'tilted10deg'])
def test_resting_stack_for_20000_steps(scene, tiltDeg):
    """A tower of four 1 m cubes with exactly coincident corners on a fixed floor (friction 30 deg),
    20,000 steps of 1 ms; level, and with gravity tilted by 10 deg (the tower on a 10 deg slope: its
    joints carry shear, tan 10 deg = 0.18 of their normal force against 0.58 available, and the
    tower's weight passes 0.15 m inside its downhill edge).

    What could go wrong over a long run: round-off in the contact
    linearisation or the stress update accumulates (the tower creeps,
    tilts or sinks); shear springs that lose their stretch when they
    re-lock ratchet the tilted tower downhill; energy leaks in one step in
    10,000 and the tower ends up moving; the iteration starts cycling once
    the contacts' forces are settled to round-off. The tower must stand: no
    cube moves more than 1e-4 m (elastic settling and shear ~1e-5 m) or
    turns more than 1e-4 rad; over the second half the centroids move less
    than 1e-8 m (no creep), and the kinetic energy at the end is below 1e-9
    of m g L.
    """
    steps = 20000
    tilt = math.radians(tiltDeg)
    gravity = (G * math.sin(tilt), 0.0, -G * math.cos(tilt))

    def build():
        floor(0.0, frictionDeg=30)
        return [(S.add_block(S.box((0, 0, k), (1, 1, k + 1)), rock(30)), (0.5, 0.5, k + 0.5)) for k in range(4)]

    halfway = []

    def record(cubes):
        if O.iter == steps // 2:
            halfway.extend(centroid(cube) for cube, _ in cubes)

    guard, cubes = run_case(build, steps, every=record, gravity=gravity)
    for (cube, c0), cHalf in zip(cubes, halfway):
        assert S.norm(S.sub(centroid(cube), c0)) < 1e-4, cube
        assert yade_dda.block(cube).rotation.toRotationVector().norm() < 1e-4
        assert S.norm(S.sub(centroid(cube), cHalf)) < 1e-8
    kinetic = guard.energy(parts=True)[1]['kinetic']
    assert kinetic < 1e-9 * guard.mass * G * 1.0


def cubes(offsets, size=1.0):
    """Corner lists of cubes of side `size` at the grid offsets (in units of `size`), centred on the origin."""
    h = size / 2
    return [S.box((o[0] * size - h, o[1] * size - h, o[2] * size - h), (o[0] * size + h, o[1] * size + h, o[2] * size + h))
            for o in offsets]


def moved(parts, axis, angle, by):
    return [shifted(rotate(part, axis, angle), by) for part in parts]


@pytest.mark.parametrize('drop', ['corner', 'seam'])
def test_concave_blocks_dropped_into_a_concave_corner(scene, drop):
    """Concave blocks in hard contact: a fixed L of three 1 m cubes (a step: foot and wall) on a floor,
    a T of four cubes dropped turned into the L's inner corner, a rigid L dropped corner first onto the
    T, friction 30 deg; 'seam': the T dropped flat across the fixed L's seams instead. 0.5 s.

    What could go wrong: a corner or edge meets the seam between two parts of a block (the faces they
    share) and finds a contact on a face inside the block; two parts of one block contact each other;
    the parts of a moving block move apart; the union's mass properties and the energy of several
    parts are counted twice. The guards check the true overlap of every part of one block with every
    part of the others (not of its own), and the energy of each block once.
    """
    def build():
        floor(0.0, frictionDeg=30)
        ids = []
        clump, members = O.bodies.appendClumped(yade_dda.concaveBlock(
            cubes([(0, 0, 0), (1, 0, 0), (0, 0, 1)]), material=rock(30), fixed=True))
        t = [(0, 0, 0), (1, 0, 0), (-1, 0, 0), (0, 1, 0)]
        if drop == 'corner':
            T = moved(cubes(t, 0.5), (1, 1, 0), 0.4, (1.4, 0.1, 1.9))
        else:
            T = moved(cubes(t, 0.5), (0, 0, 1), 0.3, (0.6, 0.2, 2.3))
        ids.append(O.bodies.appendClumped(yade_dda.concaveBlock(T, material=rock(30)))[0])
        L = moved(cubes([(0, 0, 0), (1, 0, 0), (0, 1, 0)], 0.4), (1, -1, 0.5), 0.9, (1.2, 0.3, 3.2))
        ids.append(O.bodies.appendClumped(yade_dda.concaveBlock(L, material=rock(30), rigid=True))[0])
        return ids

    guard, blocks = run_case(build, 500)
    assert guard.worstPenetration > 0   # they did land
    for b in blocks:
        assert yade_dda.block(b).partCount > 1


@pytest.mark.slow
def test_threads_do_not_change_a_hard_field(scene):
    """Determinism with threads engaged: 1100 hard placements side by side on one floor, 1375 moving
    blocks in 1100 independent systems (above the core's threading threshold of 1024 blocks, pairs and
    components), 20 steps with 2 threads and with 1, bitwise the same, every guard on (1 thread).

    In each 2 m cell, by turn: a stack of two cubes face on face (gap 0), a
    cube on its corner exactly on the floor, a cube on an edge exactly on
    the floor, a cube face down spinning at 3 rad/s. What could go wrong:
    a reduction whose order depends on the thread count, a contact list
    filled in thread order, a shared scratch buffer.
    """
    def build():
        floor(0.0, size=(-1.0, -1.0, 67.0, 67.0), frictionDeg=30)
        stacks = []
        for k in range(1100):
            x, y = 2.0 * (k % 33) + 0.5, 2.0 * (k // 33) + 0.5
            kind = k % 4
            if kind == 0:
                a = S.add_block(S.box((x - 0.4, y - 0.4, 0), (x + 0.4, y + 0.4, 0.8)), rock(30))
                b = S.add_block(S.box((x - 0.4, y - 0.4, 0.8), (x + 0.4, y + 0.4, 1.6)), rock(30))
                stacks.append((a, b))
            elif kind == 1:
                S.add_block(corner_down_cube((x, y, 0.0), side=0.8, turn=0.1 * (k % 7)), rock(30))
            elif kind == 2:
                pts = rotate(S.box((-0.4, -0.4, -0.4), (0.4, 0.4, 0.4)), (1, 0, 0), math.pi / 4)
                S.add_block(shifted(pts, (x, y, 0.4 * math.sqrt(2))), rock(30))
            else:
                c = S.add_block(S.box((x - 0.4, y - 0.4, 0), (x + 0.4, y + 0.4, 0.8)), rock(30))
                O.bodies[c].state.angVel = (0, 0, 3.0)
        return stacks

    fingerprints = []
    for threads in (2, 1):
        O.reset()
        stacks = build()
        O.engines = [integrator(threads=threads)]
        if threads == 2:
            for _ in range(20):
                O.step()
        else:
            ids = bodies()
            guard = Guard(ids, GRAVITY, pairs=[(ids[0], b) for b in ids[1:]] + stacks)
            assert len(guard.moving) >= 1024
            guard.run(20)
        s = yade_dda.stats()
        assert s['contactPairs'] >= 1024 and s['components'] >= 1024 and s['movingBlocks'] >= 1024
        fingerprints.append(fingerprint())
    assert fingerprints[0] == fingerprints[1]
