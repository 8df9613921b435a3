"""Shapes and small utilities shared by the scene tests (SI units)."""
import math

from yade import wrapper


def box(lo, hi):
    """Corners of the axis-aligned box [lo, hi] [m]."""
    return [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]) for i in range(8)]


def material(O, young=4e6, poisson=0.25, density=2600, frictionDeg=0.0):
    return O.materials.append(wrapper.PolyhedraMat(young=young, poisson=poisson, density=density,
                                                   frictionAngle=math.radians(frictionDeg)))


def rotate(points, axis, angle, about=(0, 0, 0)):
    """Rotates points by angle [rad] about an axis through `about` (Rodrigues)."""
    n = math.sqrt(sum(a * a for a in axis))
    k = [a / n for a in axis]
    c, s = math.cos(angle), math.sin(angle)
    out = []
    for p in points:
        v = [p[i] - about[i] for i in range(3)]
        kxv = (k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0])
        kv = sum(k[i] * v[i] for i in range(3))
        out.append(tuple(about[i] + v[i] * c + kxv[i] * s + k[i] * kv * (1 - c) for i in range(3)))
    return out
