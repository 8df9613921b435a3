"""ddaBlock(points, hull=True): any point cloud makes a block, the convex hull of the points.

Oracle: the hull's volume computed here, independently of CGAL and of the
core, by brute force on the points themselves: every triple of points whose
plane has all the others on one side is a hull triangle (random clouds have no
four coplanar points), and the divergence theorem sums their signed
tetrahedra. Clouds are random with a printed seed (YADE_DDA_HULL_SEED picks
another), in shapes that stress the hull: uniform in a box, on a sphere (every
point a corner), Gaussian, slender prisms (a random convex polygon extruded,
each corner jittered), and clouds on a cube's faces and edges (points that are
no corner, and corners within round-off of a face).
"""
import itertools
import math
import os
import random

import numpy as np
import pytest

import yade_dda
from yade_dda import O

from helpers import material

SEED = int(os.environ.get('YADE_DDA_HULL_SEED', '20261126'))


def hullVolume(points):
    """Volume of the convex hull of points in general position [m^3], by brute force (numpy)."""
    p = np.asarray(points, dtype=float)
    n = len(p)
    triples = np.array(list(itertools.combinations(range(n), 3)))
    a, b, c = p[triples[:, 0]], p[triples[:, 1]], p[triples[:, 2]]
    normal = np.cross(b - a, c - a)
    side = np.einsum('tk,nk->tn', normal, p) - np.einsum('tk,tk->t', normal, a)[:, None]
    scale = np.abs(side).max()
    tolerance = 1e-12 * scale
    above = (side > tolerance).any(axis=1)
    below = (side < -tolerance).any(axis=1)
    hull = above != below            # all other points on one side: a hull triangle
    centre = p.mean(axis=0)
    volume = 0.0
    for t, a_, b_, c_ in zip(triples[hull], a[hull], b[hull], c[hull]):
        six = np.dot(np.cross(b_ - centre, c_ - centre), a_ - centre)
        volume += abs(six) / 6.0      # the centre is inside: every tetrahedron counts positively
    return volume


def clouds(rng):
    """(name, points) for 100 clouds of 8 to 60 points [m]."""
    for k in range(100):
        n = rng.randint(8, 60)
        kind = k % 4
        if kind == 0:
            yield 'box', [(rng.uniform(0, 2), rng.uniform(0, 1), rng.uniform(0, 3)) for _ in range(n)]
        elif kind == 1:
            points = []
            for _ in range(n):
                v = [rng.gauss(0, 1) for _ in range(3)]
                r = math.sqrt(sum(x * x for x in v))
                points.append(tuple(5 + 0.7 * x / r for x in v))
            yield 'sphere', points
        elif kind == 2:
            yield 'gauss', [(rng.gauss(0, 1), rng.gauss(0, 0.3), rng.gauss(10, 2)) for _ in range(n)]
        else:
            sides = max(3, n // 2)
            angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(sides))
            length = rng.uniform(2, 20)      # slender: up to 20 times its width
            points = []
            for a in angles:
                for z in (0.0, length):
                    points.append((0.5 * math.cos(a) + rng.uniform(-1e-3, 1e-3),
                                   0.5 * math.sin(a) + rng.uniform(-1e-3, 1e-3), z + rng.uniform(-1e-3, 1e-3)))
            yield 'prism', points


def _append(points, **kw):
    body = yade_dda.ddaBlock(points, material=material(O), hull=True, **kw)
    O.bodies.append(body)
    return body, yade_dda.block(body.id)


def test_every_random_cloud_is_a_block_with_the_hulls_volume(scene):
    print('seed', SEED)
    rng = random.Random(SEED)
    worst = 0.0
    for number, (kind, points) in enumerate(clouds(rng)):
        O.reset()
        body, block = _append(points)
        expected = hullVolume(points)
        error = abs(block.volume - expected) / expected
        worst = max(worst, error)
        assert error <= 1e-4, (number, kind, len(points), block.volume, expected)
        assert len(body.shape.v) == len(block.vertices), (number, kind)
        assert {tuple(v) for v in block.vertices} <= set(points), 'the corners are points of the cloud'
    print('worst relative volume error', worst)


def test_points_that_are_no_corner_are_left_out(scene):
    """A unit cube's corners, with points inside, repeated, on its faces and edges, and corners
    1e-13 m off a face: the block is the cube (8 corners, volume 1 to round-off)."""
    rng = random.Random(SEED)
    cube = [(float(x), float(y), float(z)) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    points = list(cube) + list(cube[:3])
    points += [(rng.random(), rng.random(), rng.random()) for _ in range(10)]            # inside
    points += [(rng.random(), rng.random(), 1.0) for _ in range(5)]                      # on the top face
    points += [(rng.random(), 0.0, 0.0) for _ in range(3)]                               # on an edge
    points += [(rng.random(), rng.random(), 1.0 + 1e-13) for _ in range(3)]              # within round-off
    rng.shuffle(points)
    body, block = _append(points)
    assert len(block.vertices) == 8 and len(body.shape.v) == 8
    assert block.volume == pytest.approx(1.0, rel=1e-9)


def test_without_hull_the_same_cloud_is_refused(scene):
    points = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0.1, 0.1, 0.1)]
    with pytest.raises(ValueError, match='strictly inside the hull'):
        yade_dda.ddaBlock(points, material=material(O))
    body, block = _append(points)
    assert len(block.vertices) == 4


@pytest.mark.parametrize('points, message', [
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0)], 'at least 4'),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.5, 0)], 'coplanar'),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, float('nan'))], 'NaN|not finite|finite'),
    ([(0, 0, 0)] * 5, 'at least 4|coplanar'),
])
def test_a_cloud_with_no_hull_is_refused(scene, points, message):
    with pytest.raises(ValueError, match=message):
        yade_dda.ddaBlock(points, material=material(O), hull=True)
    assert len(O.bodies) == 0


def test_hull_must_be_a_bool(scene):
    with pytest.raises(TypeError, match='hull must be True or False'):
        yade_dda.ddaBlock([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], hull=1)


def test_hull_blocks_step(scene):
    """A few hull blocks dropped on a floor run without refusal (they were refused at the first step
    when YADE's shape and the block disagreed)."""
    rng = random.Random(SEED + 1)
    rock = material(O, young=1e8)
    O.bodies.append(yade_dda.ddaBlock([(x, y, z) for x in (-5, 5) for y in (-5, 5) for z in (-1, 0)],
                                      material=rock, fixed=True))
    for k in range(4):
        points = [(2 * k - 3 + rng.uniform(0, 1), rng.uniform(0, 1), 0.5 + rng.uniform(0, 1)) for _ in range(20)]
        O.bodies.append(yade_dda.ddaBlock(points, material=rock, hull=True))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
    O.run(50, True)
    assert yade_dda.stats()['steps'] == 50


def test_corners_yade_merges_are_dropped_near_the_size_limit(scene, monkeypatch):
    """Clouds 9.9e3 m across, just inside ddaBlock's 1e4 m limit, where YADE's Polyhedra (absolute
    tolerances) drops true corners of the hull: the block takes the hull of the corners YADE kept, so
    the two agree, and its volume is at most the hull's. What that costs is stated, not hidden: the
    volume lost (measured 0.5% at worst on these 20 clouds; 0 on the 100 ordinary ones above)."""
    from yade_dda import blocks
    taken = []
    original = blocks._cornersYadeKept
    monkeypatch.setattr(blocks, '_cornersYadeKept', lambda *a: taken.append(1) or original(*a))
    rng = random.Random(SEED + 2)
    worst = 0.0
    for _ in range(20):
        points = [tuple(9.9e3 * rng.random() for _ in range(3)) for _ in range(30)]
        O.reset()
        body, block = _append(points)
        assert len(body.shape.v) == len(block.vertices)
        expected = hullVolume(points)
        assert block.volume <= expected * (1 + 1e-12)
        worst = max(worst, (expected - block.volume) / expected)
    print('YADE merged corners in %d of 20 clouds; worst volume lost %.2e' % (len(taken), worst))
    assert taken, 'no cloud reached the path where YADE merges corners'
    assert worst <= 0.01
