# rock_mass.py -- cutRockMass in a scene: a 12 m cube of rock cut by three orthogonal joint sets into
# 3 m x 4 m x 3 m blocks, a 6 m x 3 m tunnel taken out along y, the blocks on the faces x = 0, x = 12
# and z = 0 held, gravity on. The blocks of the tunnel's crown lose their support and fall; nothing else
# moves. Run with: yade -n -x examples/rock_mass.py   (or /usr/bin/python3 examples/rock_mass.py)
# doc/rock-mass.md explains the joint sets, the conventions and the output.
import math

from yade_dda import *
from yade import PolyhedraMat

SIDE = 12.0
rock = cutRockMass(
    [(x, y, z) for x in (0, SIDE) for y in (0, SIDE) for z in (0, SIDE)],
    [dict(dip=90, dipDirection=90, spacing=3),      # vertical, striking north: x = 3, 6, 9
     dict(dip=90, dipDirection=0, spacing=4),       # vertical, striking east: y = 4, 8
     dict(dip=0, dipDirection=0, spacing=3),        # horizontal: z = 3, 6, 9
     dict(excavate=[(x, y, z) for x in (3, 9) for y in (-1, SIDE + 1) for z in (3, 6)])])   # the tunnel
print(rock)

mat = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=math.radians(30)))
held = lambda b: any(c[0] in (0.0, SIDE) or c[2] == 0.0 for c in b.corners)
ids = [O.bodies.append(ddaBlock(b.corners, material=mat, fixed=held(b))) for b in rock]
start = {i: block(i).centroid[2] for i in ids}

O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.01, label='dda')]
O.run(300, True)
drops = sorted(((start[i] - block(i).centroid[2], i) for i in ids), reverse=True)
print('%d blocks, %d held; after %.2f s (free fall: %.3f m) the largest drops [m]:'
      % (len(ids), sum(map(held, rock)), O.time, 9.81 * O.time ** 2 / 2), ', '.join('%.3f' % d for d, _ in drops[:8]))
