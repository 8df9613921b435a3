"""Blocks made from YADE scripts: exact mass properties (volume, centroid, second moments) and the
YADE body's mass and inertia. Bad block input is tested in yade/test_bad_input.py."""
import math

import yade_dda
from yade_dda import O, ddaBlock

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
