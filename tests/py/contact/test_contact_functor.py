"""The narrow phase as a YADE-style functor, usable from scripts on any two DDA
blocks: structural types and gaps on placements with known answers."""
import pytest

import yade_dda
from yade_dda import O, ddaBlock

from helpers import box


def test_pair_functor_reports_types_and_gaps(scene):
    """Ig2_DDABlock_DDABlock_DDAContact on placements with known answers."""
    ig2 = yade_dda.Ig2_DDABlock_DDABlock_DDAContact()
    floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (2, 2, 0)), fixed=True))
    lifted = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0.003), (0.5, 0.5, 1.003))))
    corner = O.bodies.append(ddaBlock(box((0.5, 0.5, 1.003), (1.5, 1.5, 2.003))))  # corner on corner
    far = O.bodies.append(ddaBlock(box((10, 10, 10), (11, 11, 11))))
    face = ig2.go(lifted, floor, 0.01)
    assert face['type'] == 'FF' and len(face['contacts']) == 4
    assert all(c['kind'] == 'VF' and abs(c['gap'] - 0.003) < 1e-12 for c in face['contacts'])
    assert abs(face['separation'] - 0.003) < 1e-12
    assert ig2.go(lifted, floor, 0.002) is None  # farther than the contact distance
    vv = ig2.go(lifted, corner, 0.01)
    assert vv['type'] == 'VV' and len(vv['contacts']) == 1 and abs(vv['contacts'][0]['gap']) < 1e-12
    assert ig2.go(lifted, far, 1.0) is None
    with pytest.raises(ValueError, match='contact distance'):
        ig2.go(lifted, floor, -1)


SEPARATION_SEED = 20261207


def _slab(rng, center, normal, side):
    """A randomly turned slender box (0.05-0.3 x 0.3-3 x 0.05-0.5 m) on the `side` (+1/-1) of the plane
    through `center` with `normal`, its nearest corner on that plane."""
    import numpy
    dims = numpy.array([rng.uniform(0.05, 0.3), rng.uniform(0.3, 3.0), rng.uniform(0.05, 0.5)])
    q, _ = numpy.linalg.qr(numpy.array([[rng.gauss(0, 1) for _ in range(3)] for _ in range(3)]))
    corners = numpy.array([q @ (numpy.array([sx, sy, sz]) * dims / 2)
                           for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    heights = corners @ normal
    shift = center - normal * (heights.min() if side > 0 else heights.max())
    return [tuple(c + shift) for c in corners]


def test_separation_is_positive_for_blocks_apart_and_negative_for_overlapping(scene):
    """Oracle: random slender blocks on either side of a plane, a corner of each on it and the two g
    from 0.2 to 5 mm apart along its normal, are g apart: the functor's separation, a lower bound of
    the distance, must lie in (0, g]
    (the entrance axis's, which prefers faces, is down to -0.05 m for such pairs). A block with a corner
    at the other's centroid overlaps it: separation < 0. Seed printed."""
    import numpy
    import random
    rng = random.Random(SEPARATION_SEED)
    print('seed', SEPARATION_SEED)
    ig2 = yade_dda.Ig2_DDABlock_DDABlock_DDAContact()
    entranceNegative = 0
    for trial in range(150):
        O.reset()
        normal = numpy.array([rng.gauss(0, 1) for _ in range(3)])
        normal /= numpy.linalg.norm(normal)
        gap = rng.uniform(2e-4, 5e-3)
        corners = numpy.array(_slab(rng, numpy.zeros(3), normal, -1))
        other = numpy.array(_slab(rng, gap * normal, normal, +1))
        # B's lowest corner right above A's highest: the blocks are exactly `gap` apart, corner to corner
        other += corners[numpy.argmax(corners @ normal)] + gap * normal - other[numpy.argmin(other @ normal)]
        a = O.bodies.append(ddaBlock([tuple(c) for c in corners]))
        b = O.bodies.append(ddaBlock([tuple(c) for c in other]))
        result = ig2.go(a, b, 0.01)
        assert result is not None, (trial, gap)
        assert 0 < result['separation'] <= gap * (1 + 1e-9), (trial, gap, result['type'], result['separation'])
        entranceNegative += result['entranceSeparation'] < 0
        O.reset()
        corners = _slab(rng, numpy.zeros(3), normal, -1)
        a = O.bodies.append(ddaBlock(corners))
        centroid = numpy.mean(corners, axis=0)
        other = numpy.array(_slab(rng, centroid, normal, +1))
        other += centroid - other[numpy.argmin(other @ normal)]   # its lowest corner at A's centroid
        b = O.bodies.append(ddaBlock([tuple(c) for c in other]))
        result = ig2.go(a, b, 0.01)
        assert result is not None and result['separation'] < 0, (trial, result)
    print('pairs apart whose entrance axis is negative:', entranceNegative)
    assert entranceNegative > 0, 'the sample must hold pairs whose entrance lies deeper than the pair (25 of 150)'
