# concave_blocks.py -- concave blocks: an L made of three cubes, the same L given by its
# triangulated surface, and a slope with a bench cut by two joint sets into concave blocks.
#   1. The L falls onto a floor and a cube drops into its inner corner: printed, its volume, centroid
#      and inertia against the closed form, and where the cube rests (on the foot, off the wall).
#   2. The L's closed surface (24 triangles) split by CGAL's convex decomposition: the same block.
#   3. cutRockMass(..., concave=True) on a slope with a bench: blocks joined across the domain's parts
#      and where a non-persistent joint is absent; the slope under gravity with its toe held.
# Run with: yade -n -x examples/concave_blocks.py   (or /usr/bin/python3 examples/concave_blocks.py)
# The tests are tests/py/blocks/test_concave_blocks.py and tests/py/geometry/test_concave_rock_mass.py.
import math
import time

from yade_dda import *
from yade import PolyhedraMat

G = 9.81
start = time.time()
rock = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=math.radians(30)))


box = boxCorners   # the 8 corners of the box from lo to hi [m]


# 1. An L standing on a floor (foot [1,2] x [0,1] x [0,1], wall [0,1] x [0,1] x [0,2]) and a 0.5 m cube
#    dropped 5 cm into its inner corner, 1 mm off the wall.
O.bodies.append(ddaBlock(box((-2, -1.5, -1), (4, 2.5, 0)), material=rock, fixed=True))
L, members = O.bodies.appendClumped(concaveBlock([box((0, 0, 0), (1, 1, 1)), box((1, 0, 0), (2, 1, 1)),
                                                  box((0, 0, 1), (1, 1, 2))], material=rock))
cube = O.bodies.append(ddaBlock(box((1.001, 0.25, 1.05), (1.501, 0.75, 1.55)), material=rock))
O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G))]
O.step()
b = block(L)
print('1. the L: %d parts, volume %.15g m^3 (closed form 3), centroid after its first step (%.5f, %.5f, %.5f) (5/6, 1/2, 5/6)'
      % (b.partCount, b.mass / 2600, *O.bodies[L].state.pos))
O.run(1000, True)
c = O.bodies[cube].state.pos
touching = sorted({i for x in contacts('closed') if cube in (x.id1, x.id2) for i in (x.id1, x.id2)} - {cube})
print('   the cube rests at z = %.6f m (on the foot: 1.25), %.4f m off the wall, touching body %s '
      '(the foot is member %d)' % (c[2], c[0] - 0.25 - 1.0, touching, members[1]))
print('   interactions in O.interactions: %s' % sorted((i.id1, i.id2) for i in O.interactions if i.isReal))

# 2. The same L from its closed surface.
O.reset()
rock = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=math.radians(30)))
polygon = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
n = len(polygon)
points = [(x, y, 0.0) for x, y in polygon] + [(x, y, 1.0) for x, y in polygon] + [(0.5, 0.5, 0.0), (0.5, 0.5, 1.0)]
triangles = []
for k in range(n):
    a, b2 = k, (k + 1) % n
    triangles += [(a, b2, n + b2), (a, n + b2, n + a), (2 * n, b2, a), (2 * n + 1, n + a, n + b2)]
L2, _ = O.bodies.appendClumped(concaveBlock(surface=(points, triangles), material=rock))
O.engines = [DDAIntegrator(dt=1e-3)]
O.step()
b = block(L2)
print('2. the L from %d triangles: %d convex parts, volume %.15g m^3, centroid (%.15g, %.15g, %.15g)'
      % (len(triangles), b.partCount, b.volume, *b.centroid))

# 3. A slope with a bench: two domain parts, a dipping set and a non-persistent vertical set.
O.reset()
rock = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=math.radians(35)))
toe = box((0, 0, 0), (20, 10, 10))
bench = box((0, 0, 10), (10, 10, 20))
mass = cutRockMass([toe, bench], [dict(dip=30, dipDirection=90, spacing=4, origin=(1, 0, 0)),
                                  dict(dip=90, dipDirection=0, spacing=3, persistence=0.5)], seed=2, concave=True)
print('3. %r; joint area %.1f m^2 of the non-persistent set, %.1f joined (%.2f)'
      % (mass, mass.jointArea, mass.absentArea, mass.absentArea / mass.jointArea))
held = lambda blocks: any(min(p[2] for p in blk.corners) < 1e-9 or min(p[0] for p in blk.corners) < 1e-9
                          for blk in blocks)
ids = mass.append(material=rock, fixed=held, rigid=True)
O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1e-3)]
O.trackEnergy = True
O.run(200, True)
moved = max(max(abs(v) for v in block(i).velocity[:3]) for i in ids)
e = stats()['energy']
print('   %d DDA blocks (%d concave); after %.2f s the largest speed is %.3g m/s; energy: gravity %.4g J, '
      'kinetic %.4g J, friction %.4g J' % (len(ids), sum(len(g) > 1 for g in mass.groups), O.time, moved,
                                            e['gravity'], e['kinetic'], e['friction']))
print('done in %.1f s' % (time.time() - start))
