"""Blocks made from YADE scripts: exact mass properties, bodies, and bad input."""
import math

import pytest

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator
from yade import wrapper

from helpers import box, material, rotate


def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def test_box_mass_properties_equal_closed_form(scene):
    mat = material(O, density=2600)
    a, b, c = 1.0, 2.0, 3.0
    body = O.bodies.append(ddaBlock(box((5, -1, 2), (5 + a, -1 + b, 2 + c)), material=mat))
    blk = yade_dda.block(body)
    assert rel(blk.volume, a * b * c) < 1e-12
    centroid = blk.centroid
    for got, want in zip(centroid, (5 + a / 2, -1 + b / 2, 2 + c / 2)):
        assert abs(got - want) < 1e-12 * 10
    J = blk.secondMoment
    for k, side in enumerate((a, b, c)):
        assert rel(J[k, k], a * b * c * side ** 2 / 12) < 1e-12
    assert abs(J[0, 1]) + abs(J[1, 2]) + abs(J[0, 2]) < 1e-12
    # the YADE body carries the same mass and principal moments of inertia
    state = O.bodies[body].state
    assert rel(state.mass, 2600 * a * b * c) < 1e-12
    m = 2600 * a * b * c
    expected = sorted([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])
    for got, want in zip(sorted(state.inertia), expected):
        assert rel(got, want) < 1e-9


def test_tetrahedron_mass_properties_equal_closed_form(scene):
    p = [(0.2, 0.1, 0.0), (2.0, 0.3, 0.1), (0.5, 1.7, 0.2), (0.4, 0.6, 1.9)]
    blk = yade_dda.block(O.bodies.append(ddaBlock(p)))
    d = [[p[k][i] - p[0][i] for i in range(3)] for k in (1, 2, 3)]
    det = (d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
           + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]))
    V = abs(det) / 6
    assert rel(blk.volume, V) < 1e-12
    c = [sum(q[i] for q in p) / 4 for i in range(3)]
    assert max(abs(blk.centroid[i] - c[i]) for i in range(3)) < 1e-13
    # second moments of a tetrahedron about its centroid: V/20 * sum_k q_k q_k^T, q_k = p_k - c
    for i in range(3):
        for j in range(3):
            want = V / 20 * sum((q[i] - c[i]) * (q[j] - c[j]) for q in p)
            assert abs(blk.secondMoment[i, j] - want) < 1e-12 * V


def _ellipsoidPoints(n=14):
    """Points on an ellipsoid (so every one is a hull corner), deterministic."""
    pts = []
    golden = math.pi * (3 - math.sqrt(5))
    for k in range(n):
        z = 1 - 2 * (k + 0.5) / n
        r = math.sqrt(1 - z * z)
        phi = golden * k
        pts.append((1.3 * r * math.cos(phi), 0.8 * r * math.sin(phi), 0.6 * z))
    return pts


def test_irregular_polyhedron_properties_are_invariant_under_rigid_motion(scene):
    pts = _ellipsoidPoints()
    a = yade_dda.block(O.bodies.append(ddaBlock(pts)))
    moved = [(x + 100.0, y - 40.0, z + 7.0) for (x, y, z) in rotate(pts, (0.3, -0.5, 0.8), 1.1)]
    b = yade_dda.block(O.bodies.append(ddaBlock(moved)))
    assert rel(b.volume, a.volume) < 1e-12
    # centroid moves with the points
    ca = rotate([tuple(a.centroid)], (0.3, -0.5, 0.8), 1.1)[0]
    assert max(abs(b.centroid[i] - (ca[i] + (100.0, -40.0, 7.0)[i])) for i in range(3)) < 1e-11
    # second moments rotate: same invariants (trace, sum of principal minors, determinant)
    import numpy
    Ja = numpy.array([[a.secondMoment[i, j] for j in range(3)] for i in range(3)])
    Jb = numpy.array([[b.secondMoment[i, j] for j in range(3)] for i in range(3)])
    assert numpy.allclose(sorted(numpy.linalg.eigvalsh(Ja)), sorted(numpy.linalg.eigvalsh(Jb)), rtol=1e-12, atol=0)
    # and the volume agrees with an independent computation: sum of tetrahedra from the centroid
    faces, verts = a.faces, a.vertices
    V = 0.0
    c = a.centroid
    for f in faces:
        for k in range(1, len(f) - 1):
            p, q, r = (verts[f[0]] - c), (verts[f[k]] - c), (verts[f[k + 1]] - c)
            V += p.dot(q.cross(r)) / 6
    assert rel(V, a.volume) < 1e-12


@pytest.mark.parametrize('points, message', [
    (box((0, 0, 0), (1, 1, 1))[:3], 'at least 4'),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.2, 0)], 'coplanar'),
    (box((0, 0, 0), (1, 1, 1)) + [(1, 1, 1)], 'coincide'),
    (box((0, 0, 0), (1, 1, 1))[:7] + [(float('nan'), 1, 1)], 'non-finite'),
    (box((0, 0, 0), (1, 1, 1))[:7] + [(1, float('inf'), 1)], 'non-finite'),
    (box((0, 0, 0), (1, 1, 1)) + [(0.5, 0.5, 0.5)], 'inside'),
])
def test_bad_geometry_raises_and_leaves_scene_unchanged(scene, points, message):
    before = len(O.bodies)
    with pytest.raises(ValueError, match=message):
        ddaBlock(points)
    assert len(O.bodies) == before
    dda = yade_dda.scene.current(create=False)
    assert dda is None or not dda.pending


@pytest.mark.parametrize('kw, message', [
    (dict(density=0), 'density'),
    (dict(density=-2600), 'density'),
    (dict(poisson=0.5), "Poisson"),
    (dict(poisson=-1.0), "Poisson"),
    (dict(young=0), "Young"),
])
def test_bad_material_raises_and_leaves_scene_unchanged(scene, kw, message):
    params = dict(young=4e6, poisson=0.25, density=2600)
    params.update(kw)
    mat = O.materials.append(wrapper.PolyhedraMat(**params))
    with pytest.raises(ValueError, match=message):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), material=mat)
    assert len(O.bodies) == 0


def test_unknown_material_and_bad_vectors_raise(scene):
    with pytest.raises(IndexError):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), material=5)
    with pytest.raises(KeyError, match='granite'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), material='granite')
    with pytest.raises(ValueError, match='velocity'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), velocity=(float('nan'), 0, 0))
    with pytest.raises(ValueError, match='fixed block'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), fixed=True, velocity=(1, 0, 0))
    with pytest.raises(ValueError, match='3 coordinates'):
        ddaBlock([(0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
    assert len(O.bodies) == 0


@pytest.mark.parametrize('kw, message', [
    (dict(dt=0), 'dt'), (dict(dt=-1e-3), 'dt'), (dict(dt=float('nan')), 'dt'),
    (dict(velocityRatio=1.5), 'velocityRatio'), (dict(gravity=(0, 0)), 'gravity'),
    (dict(maxDisplacementRatio=0), 'maxDisplacementRatio'), (dict(bogus=1), 'bogus'),
])
def test_bad_engine_parameters_raise(scene, kw, message):
    with pytest.raises((ValueError, TypeError), match=message):
        DDAIntegrator(**kw)


def test_engine_parameter_assignment_is_validated_and_kept(scene):
    dda = DDAIntegrator(dt=1e-3, label='dda')
    O.engines = [dda]
    with pytest.raises(ValueError, match='dt'):
        dda.dt = 0
    assert dda.dt == 1e-3
    dda.dt = 2e-3
    # the instance in O.engines is the same subclass instance, and its command carries the value
    assert O.engines[0].dt == 2e-3
    assert "'dt': 0.002" in O.engines[0].command
