"""Every block ddaBlock accepts steps.

Random turned triangular prisms and hexahedra (parallelepipeds), 1:1 to
1000:1, at distances from the origin up to 1e6 m, far apart (no contacts):
each must pass the link to its YADE body, step and sync, and then

- its centroid follows free fall, c0 + v0 t + g t^2/2 (the scheme is exact for
  constant acceleration), within the round-off of its coordinates;
- its shape is unchanged (corners about the centroid, turned back by the
  block's rotation) within the same round-off;
- the body's corners (pos + ori * shape.v) are the block's corners, one to
  one, within the round-off of the body's frame;
- the body's mass and principal moments are the block's.

And a cube resting on a fixed floor 1e6 m from the origin settles as the same
cube at the origin (penalty and elastic settlement, a closed-form bound) with
the same contacts, no ghost ones and no NaN.

The seed is YADE_DDA_ACCEPTANCE_SEED (default below) and is printed; the
default run takes 1,200 blocks, `make test-hard` (-m slow) 10,000.
"""
import math
import os
import random

import numpy as np
import pytest

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator
from yade import wrapper

from helpers import box, material

SEED = int(os.environ.get('YADE_DDA_ACCEPTANCE_SEED', '170517'))
G = 9.81
EPS = np.finfo(float).eps
STEPS = 12
MAX_OFFSET = 1e6  # [m]


def _turn(rng):
    """A uniformly random rotation matrix (from a random unit quaternion)."""
    q = np.array([rng.gauss(0, 1) for _ in range(4)])
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _randomShape(rng, kind):
    """Corners [m] of a prism or a parallelepiped about the origin: section a (0.1 to 1 m), length up to 1000 a."""
    a = 10 ** rng.uniform(-1, 0)
    length = a * 10 ** rng.uniform(0, 3)
    if kind == 'prism':
        apex = (a * rng.uniform(-0.5, 1.5), a * rng.uniform(0.1, 1.0))
        section = [(0.0, 0.0), (a, 0.0), apex]
        pts = np.array([(x, y, z) for z in (0.0, length) for x, y in section])
    else:
        e1 = np.array((a, 0.0, 0.0))
        e2 = np.array((a * rng.uniform(-0.5, 0.5), a * rng.uniform(0.3, 1.0), 0.0))
        e3 = np.array((a * rng.uniform(-0.5, 0.5), a * rng.uniform(-0.5, 0.5), length))
        pts = np.array([i * e1 + j * e2 + k * e3 for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    return pts - pts.mean(axis=0)


def _blocks(rng, count):
    """count shapes, turned, far from each other at distances 1 m to MAX_OFFSET from the origin."""
    centres, radii, out = [], [], []
    while len(out) < count:
        kind = ('prism', 'hexa')[len(out) % 2]
        local = _randomShape(rng, kind).dot(_turn(rng).T)
        radius = float(np.linalg.norm(local, axis=1).max())
        direction = np.array([rng.gauss(0, 1) for _ in range(3)])
        centre = direction / np.linalg.norm(direction) * 10 ** rng.uniform(0, math.log10(MAX_OFFSET))
        if centres:
            apart = np.linalg.norm(np.array(centres) - centre, axis=1) - np.array(radii) - radius
            if apart.min() < 1.0:   # keep 1 m between bounding spheres: no contacts
                continue
        centres.append(centre)
        radii.append(radius)
        out.append((kind, [tuple(float(c) for c in p) for p in local + centre]))
    return out


def _quaternionMatrix(q):
    return np.array([[q.toRotationMatrix()[i, j] for j in range(3)] for i in range(3)])


def _bodyCorners(body):
    """The body's corners in the world: pos + ori * v [m]."""
    R = _quaternionMatrix(body.state.ori)
    return np.array([tuple(v) for v in body.shape.v]).dot(R.T) + np.array(tuple(body.state.pos))


def _surfaceArea(corners, faces):
    """Area [m^2] of the polyhedron with these corners and faces (fans of triangles)."""
    area = 0.0
    for face in faces:
        p = corners[list(face)]
        area += 0.5 * np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0))
    return area


def _oneToOne(got, want, tolerance):
    """Largest distance from each of got to its nearest in want; also whether that map is a bijection."""
    d = np.linalg.norm(got[:, None, :] - want[None, :, :], axis=2)
    nearest = d.argmin(axis=1)
    return float(d.min(axis=1).max()), len(set(nearest.tolist())) == len(want)


def _dropFarApart(count, seed):
    """Builds count far-apart random blocks, runs STEPS steps of free fall; returns (accepted, refused, checks)."""
    rng = random.Random(seed)
    mat = material(O, young=1e9, density=2600)
    made, refused = [], 0
    for kind, corners in _blocks(rng, count):
        spin = rng.random() < 0.5
        r = float(np.linalg.norm(np.array(corners) - np.mean(corners, axis=0), axis=1).max())
        velocity = tuple(rng.uniform(-0.5, 0.5) for _ in range(3))
        # Spinning blocks are rigid (a deformable one would stretch); angular speed x radius up to 0.5 m/s.
        axis = np.array([rng.gauss(0, 1) for _ in range(3)])
        angular = tuple(axis / np.linalg.norm(axis) * rng.uniform(0, 0.5) / r) if spin else (0.0, 0.0, 0.0)
        try:
            body = ddaBlock(corners, material=mat, velocity=velocity, angularVelocity=angular, rigid=spin)
        except ValueError as error:
            # A refusal at creation is allowed (with a message); only accepted blocks must step.
            assert 'too small for its distance from the origin' in str(error), str(error)
            refused += 1
            continue
        made.append((O.bodies.append(body), corners, velocity))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    start = {b: (np.array(yade_dda.block(b).vertices), np.array(yade_dda.block(b).centroid)) for b, _, _ in made}
    for bodyId, corners, _ in made:   # the corners reach the core exactly (YADE's shape was made from shifted ones)
        assert sorted(map(tuple, start[bodyId][0].tolist())) == sorted(corners), bodyId
    O.run(STEPS, True)
    t = yade_dda.scene.current().core.time()
    assert t > 0
    worst = {'centroid': 0.0, 'shape': 0.0, 'body': 0.0, 'mass': 0.0, 'inertia': 0.0}
    for bodyId, corners, velocity in made:
        blk = yade_dda.block(bodyId)
        x0, c0 = start[bodyId]
        x, c = np.array(blk.vertices), np.array(blk.centroid)
        assert np.isfinite(x).all() and np.isfinite(c).all(), bodyId
        # Round-off of a coordinate of magnitude |x| per step (the centroid and corners are moved by sums).
        magnitude = float(np.abs(x).max())
        r = float(np.linalg.norm(x0 - c0, axis=1).max())
        roundoff = (STEPS + 4) * EPS * (4 * magnitude + 64 * r)
        expected = c0 + np.array(velocity) * t + np.array((0, 0, -G)) * t * t / 2
        err = float(np.linalg.norm(c - expected))
        worst['centroid'] = max(worst['centroid'], err / roundoff)
        assert err <= roundoff, (bodyId, c.tolist(), expected.tolist(), err, roundoff)
        R = _quaternionMatrix(blk.rotation)
        err = float(np.linalg.norm((x - c).dot(R) - (x0 - c0), axis=1).max())
        worst['shape'] = max(worst['shape'], err / roundoff)
        assert err <= roundoff, ('shape changed', bodyId, err, roundoff)
        body = O.bodies[bodyId]
        err, bijective = _oneToOne(_bodyCorners(body), x, roundoff)
        worst['body'] = max(worst['body'], err / roundoff)
        assert bijective and err <= roundoff, ('body corners are not the block corners', bodyId, err, roundoff)
        # YADE's volume and the core's integrate the same corners; turned corners are rounded to the ulps of
        # their coordinates, so a face is planar only to ~|x| eps and the two fans of a face differ by up to
        # surface area x that height (1e-9 of a 0.1 m section at 1e6 m).
        relative = 1e-12 + _surfaceArea(x0, blk.faces) * 8 * EPS * float(np.abs(x0).max()) / blk.volume
        err = abs(body.state.mass / blk.mass - 1)
        worst['mass'] = max(worst['mass'], err / relative)
        assert err <= relative, (bodyId, body.state.mass, blk.mass, relative)
        J = np.array([[blk.secondMoment[i, j] for j in range(3)] for i in range(3)]) * blk.mass / blk.volume
        principal = np.sort(np.linalg.eigvalsh(np.trace(J) * np.eye(3) - J))
        err = float(np.abs(np.sort(np.array(tuple(body.state.inertia))) - principal).max() / principal[-1])
        worst['inertia'] = max(worst['inertia'], err / (2 * relative))
        assert err <= 2 * relative, (bodyId, tuple(body.state.inertia), principal.tolist(), relative)
    return len(made), refused, worst


def _report(count, seed, accepted, refused, worst):
    print('\nblock acceptance: seed %d (YADE_DDA_ACCEPTANCE_SEED), %d blocks, %d accepted, %d refused at creation; '
          'worst/tolerance: centroid %.2g, shape %.2g, body corners %.2g, mass %.2g, inertia %.2g'
          % (seed, count, accepted, refused, worst['centroid'], worst['shape'], worst['body'], worst['mass'],
             worst['inertia']))


def test_random_prisms_and_hexahedra_far_apart_all_step(scene):
    """1,200 random blocks in one scene: all accepted ones link, step, follow free fall and show right."""
    count = 1200
    accepted, refused, worst = _dropFarApart(count, SEED)
    _report(count, SEED, accepted, refused, worst)
    # Section 0.1 m and up at up to 1e6 m: the core refuses only the smallest far blocks (|x| / size > ~1e6).
    assert accepted >= 0.95 * count


@pytest.mark.slow
def test_ten_thousand_random_blocks_all_step(scene):
    """10,000 random turned prisms and hexahedra, 1:1 to 1000:1, up to 1e6 m from the origin."""
    count = 10000
    accepted, refused, worst = _dropFarApart(count, SEED + 1)
    _report(count, SEED + 1, accepted, refused, worst)
    assert accepted >= 0.95 * count


def test_cube_1e5_m_from_origin_steps(scene):
    """A 1 m cube at x = y = 1e5 m (YADE merged its faces: volume 4/3, centroid 6 cm off)."""
    mat = material(O, young=1e9)
    body = O.bodies.append(ddaBlock(box((1e5, 1e5, 0), (1e5 + 1, 1e5 + 1, 1)), material=mat))
    assert abs(O.bodies[body].state.mass / (2600 * 1.0) - 1) < 1e-12
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    O.run(10, True)
    t = yade_dda.scene.current().core.time()
    c = yade_dda.block(body).centroid
    assert (c[0], c[1]) == (1e5 + 0.5, 1e5 + 0.5)
    assert abs(c[2] - (0.5 - G * t * t / 2)) < 1e-12
    err, bijective = _oneToOne(_bodyCorners(O.bodies[body]), np.array(yade_dda.block(body).vertices), 1)
    assert bijective and err < 16 * EPS * 2e5


def test_a_rock_block_is_accepted_as_its_corners(scene):
    """ddaBlock(rockBlock) was refused ("vertices must be a sequence of points"): a RockBlock of
    cutRockMass is taken as its .corners, by ddaBlock and rigidBlock alike."""
    mass = yade_dda.cutRockMass(box((0, 0, 0), (2, 2, 2)), [dict(dip=0, dipDirection=0, spacing=1, origin=(0, 0, 1))])
    assert len(mass) == 2
    bodies = [O.bodies.append(ddaBlock(mass[0])), O.bodies.append(yade_dda.rigidBlock(mass[1]))]
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    O.step()
    for body, rock in zip(bodies, mass):
        assert sorted(tuple(v) for v in yade_dda.block(body).vertices) == sorted(tuple(p) for p in rock.corners)
        assert abs(yade_dda.block(body).volume - rock.volume) < 1e-12
    assert yade_dda.block(bodies[1]).rigid


def test_far_body_vertices_of_another_shape_are_refused(scene):
    """The link still refuses a body whose corners are not the block's, naming vertex, distance and tolerance."""
    body = ddaBlock(box((1e6, 1e6, 0), (1e6 + 1, 1e6 + 1, 1)))
    v = [tuple(p) for p in body.shape.v]
    v[3] = (v[3][0] + 1e-6, v[3][1], v[3][2])   # 1 um: far above round-off at 1e6 m (~3e-10 m), far below a corner
    body.shape.v = v
    O.bodies.append(body)
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    with pytest.raises(Exception) as error:
        O.step()
    message = str(error.value)
    assert 'vertex 3 of body %d matches no vertex of block 0' % body.id in message, message
    assert 'tolerance' in message and '1e-06 m away' in message, message


def _settle(offset, shape, steps=300):
    """A block (E = 1e9 Pa) set on a fixed floor at `offset` [m]: a 1 m cube, or a turned triangular log 10 m long
    lying on a side. Returns (sink, drift, contacts, bound) [m]."""
    young, density = 1e9, 2600
    mat = material(O, young=young, density=density)
    o = np.array(offset)
    if shape == 'cube':
        corners = box((-0.5, -0.5, 0), (0.5, 0.5, 1))
        height, half = 1.0, 2.0
    else:
        turn = np.array([[math.cos(0.3), -math.sin(0.3), 0], [math.sin(0.3), math.cos(0.3), 0], [0, 0, 1]])
        section = [(-0.5, 0.0), (0.5, 0.0), (0.1, 0.8)]  # (x, z), extruded along y
        corners = [tuple(turn.dot((x, y, z))) for y in (-5.0, 5.0) for x, z in section]
        height, half = 0.8, 7.0
    floor = O.bodies.append(ddaBlock(box(tuple(o + (-half, -half, -0.5)), tuple(o + (half, half, 0))), material=mat,
                                     fixed=True))
    block = O.bodies.append(ddaBlock([tuple(o + p) for p in np.array(corners)], material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1e-3, label='dda')]
    c0 = np.array(yade_dda.block(block).centroid)
    O.run(steps, True)
    blk = yade_dda.block(block)
    c, x = np.array(blk.centroid), np.array(blk.vertices)
    assert np.isfinite(c).all() and np.isfinite(x).all()
    contacts = yade_dda.scene.current().core.contacts()
    for contact in contacts:
        assert {contact[0], contact[1]} == {0, 1}
        assert abs(abs(contact[5][2]) - 1) < 1e-9, ('a contact that is not the floor', contact)
    # The body shows the block: pos, ori and (strained: rewritten) vertices.
    body = O.bodies[block]
    assert body.state.pos == blk.centroid
    r = float(np.linalg.norm(x - c, axis=1).max())
    err, bijective = _oneToOne(_bodyCorners(body), x, 1)
    assert bijective and err <= 16 * EPS * (4 * np.abs(x).max() + 64 * r), err
    assert O.bodies[floor].state.pos == yade_dda.block(floor).centroid
    # Settlement bound: the whole weight on one penalty spring (kn = contactPenaltyFactor x the smaller
    # E x size of the pair, size the cube root of the volume) plus the block's own elastic shortening under
    # its weight (mean strain rho g H / (2E) over H), twice for the overshoot of a suddenly applied load.
    kn = 40 * young * min(blk.volume, yade_dda.block(floor).volume) ** (1 / 3)
    bound = 2 * (blk.mass * G / kn + density * G * height ** 2 / (2 * young))
    return c0[2] - c[2], float(np.hypot(*(c - c0)[:2])), len(contacts), bound


@pytest.mark.parametrize('shape', ['cube', 'log'])
def test_block_resting_on_floor_far_from_origin_settles_as_at_origin(scene, shape):
    """1e6 m from the origin a block on a fixed floor stays put within its penalty settlement, as at the origin."""
    sink0, drift0, contacts0, bound = _settle((0.0, 0.0, 0.0), shape)
    O.reset()
    far = (1e6, -1e6, 1e6)
    sink, drift, contacts, _ = _settle(far, shape)
    roundoff = 300 * 4 * EPS * np.linalg.norm(far)   # per step, a coordinate of 1.7e6 m
    print('\n%s on floor: sink at origin %.3g m, at 1e6 m %.3g m (bound %.3g m), drift %.2g / %.2g m, '
          'contacts %d / %d' % (shape, sink0, sink, bound, drift0, drift, contacts0, contacts))
    assert 0 < sink0 <= bound
    assert 0 < sink <= bound
    assert contacts == contacts0 >= 4
    assert drift0 <= 1e-9 * sink0 and drift <= 1e-3 * sink0 + roundoff
    assert abs(sink - sink0) <= 1e-3 * sink0 + roundoff


def test_box_corners_are_the_eight_corners_of_the_box(scene):
    """boxCorners gives the 8 corners of an axis-aligned box (a block of its volume and centroid) and
    refuses an empty, inverted or non-finite extent by name."""
    import math
    corners = yade_dda.boxCorners((0, 0, 10), (1, 2, 13))
    assert sorted(corners) == sorted((x, y, z) for x in (0.0, 1.0) for y in (0.0, 2.0) for z in (10.0, 13.0))
    body = O.bodies.append(yade_dda.ddaBlock(corners))
    view = yade_dda.block(body)
    assert abs(view.volume - 6.0) < 1e-12 and max(abs(a - b) for a, b in zip(view.centroid, (0.5, 1, 11.5))) < 1e-12
    for lower, upper, message in [((0, 0, 0), (1, 0, 1), 'y from 0.0 to 0.0'), ((0, 0, 0), (1, 1, -1), 'z from'),
                                  ((0, 0, 0), (1, math.nan, 1), 'y from'), ((0, 0), (1, 1), 'two points')]:
        with pytest.raises(ValueError, match=message):
            yade_dda.boxCorners(lower, upper)
