"""A pile: 27 slightly turned cubes dropped into a fixed box. No closed form;
what must hold is that no block sinks into another (every contact found in
time: penetration stays at the penalty's scale), nothing is NaN, nothing gains
energy, and the pile comes to rest inside the box.

A narrow-phase rule that dropped the only sub-contact of a corner-on-edge pair
once let a cube sink 0.4 m into its neighbour here; this test guards that.
"""
import math
import random

from yade_dda import O, DDAIntegrator, ddaBlock
from yade import wrapper
import yade_dda

from helpers import box, rotate

G = 9.81


def test_pile_of_cubes_never_interpenetrates(scene):
    rng = random.Random(7)
    rock = O.materials.append(wrapper.PolyhedraMat(density=2600, young=1e9, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    O.bodies.append(ddaBlock(box((-1, -1, -1), (4.6, 4.6, 0)), material=rock, fixed=True))
    for lo, hi in (((-1, -1, 0), (0, 4.6, 5)), ((3.6, -1, 0), (4.6, 4.6, 5)),
                   ((0, -1, 0), (3.6, 0, 5)), ((0, 3.6, 0), (3.6, 4.6, 5))):
        O.bodies.append(ddaBlock(box(lo, hi), material=rock, fixed=True))
    cubes = []
    for k in range(27):
        i, j, layer = k % 3, (k // 3) % 3, k // 9
        x, y, z = 0.1 + 1.2 * i, 0.1 + 1.2 * j, 0.2 + 1.3 * layer
        pts = rotate(box((x, y, z), (x + 0.9, y + 0.9, z + 0.9)), (rng.random(), rng.random(), rng.random()),
                     rng.uniform(-0.2, 0.2), about=(x + 0.45, y + 0.45, z + 0.45))
        cubes.append(O.bodies.append(ddaBlock(pts, material=rock)))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.005, label='dda')]
    mass = yade_dda  # noqa: F841 (keeps the import explicit)
    deepest = 0.0
    potential0 = None
    while O.time < 1.2:
        O.run(5, True)
        s = yade_dda.stats()
        deepest = max(deepest, s['maxPenetration'])
        energy = 0.0
        for b in cubes:
            blk = yade_dda.block(b)
            v = blk.velocity
            assert all(math.isfinite(x) for x in v)
            energy += blk.mass * G * blk.centroid[2] + 0.5 * blk.mass * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
        if potential0 is None:
            potential0 = energy
        # Kinetic + potential energy of translation never exceeds its start
        # (rotation adds a little more kinetic energy, so this is conservative
        # only up to it; the margin is 1% of the drop energy).
        assert energy < potential0 + 0.01 * potential0
    # Penetration at the penalty's scale: the weight of the whole pile on one
    # contact would sink kn = 40 E size by 27 m g / kn ~ 4e-5 m.
    assert deepest < 1e-3
    # Everything inside the box and at rest-ish on the floor.
    for b in cubes:
        c = yade_dda.block(b).centroid
        assert 0 < c[0] < 3.6 and 0 < c[1] < 3.6 and 0.3 < c[2] < 4
