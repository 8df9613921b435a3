# wedge.py -- a wedge on a cut slope against the limit-equilibrium (Hoek-Bray) factor of
# safety. A 20 m x 20 m x 10 m prism whose front face dips 65 degrees towards +x is cut by two joints
# (dip 50, dip directions 60 and 120) through a point of the face 2 m above the toe; the tetrahedral
# wedge above both joints is free, the rest fixed. The joints' friction angle is chosen for the factor
# of safety FS (argument, default 0.7); the script prints FS and the wedge's motion along the line of
# intersection against a = g sin(psi) (1 - FS).
# Run with: yade -n -x examples/wedge.py [FS] [--vtk=DIR]   (or /usr/bin/python3 examples/wedge.py [FS])
# tests/py/system/test_wedge.py is the test; doc/rock-mass.md reports the numbers.
import math
import sys

import numpy as np

from yade_dda import *
from yade import PolyhedraMat

G = 9.81
ARGS = [a for a in sys.argv[1:] if not a.startswith('--vtk')]
VTK = next((a.split('=', 1)[1] for a in sys.argv[1:] if a.startswith('--vtk=')), '')
FS = float(ARGS[0]) if ARGS else 0.7
SLOPE, HEIGHT, LENGTH, WIDTH = 65.0, 10.0, 20.0, 20.0


def pole(dip, dipDirection):
    d, a = math.radians(dip), math.radians(dipDirection)
    return np.array([math.sin(d) * math.sin(a), math.sin(d) * math.cos(a), math.cos(d)])


crest = LENGTH - HEIGHT / math.tan(math.radians(SLOPE))
domain = [(x, y, z) for y in (0.0, WIDTH) for x, z in ((0.0, 0.0), (LENGTH, 0.0), (0.0, HEIGHT), (crest, HEIGHT))]
P = np.array([LENGTH - 2.0 / math.tan(math.radians(SLOPE)), WIDTH / 2, 2.0])
normals = [pole(50, 60), pole(50, 120)]          # point into the wedge: the reactions' directions on it
rock = cutRockMass(domain, [dict(plane=(tuple(P), tuple(n))) for n in normals])
print(rock)

# limit equilibrium: N_A nA + N_B nB balances the weight's part perpendicular to s
s = np.cross(*normals)
s = -s / np.linalg.norm(s) if s[2] > 0 else s / np.linalg.norm(s)
psi = math.asin(-s[2])
w = np.array([0.0, 0.0, -1.0])
N = np.linalg.lstsq(np.column_stack(normals), -(w - (w @ s) * s), rcond=None)[0]
phi = math.atan(FS * math.sin(psi) / (N[0] + N[1]))
print('line of intersection: plunge %.2f deg, trend %.1f deg; N/W = %.4f, %.4f; phi = %.2f deg for FS = %.2f'
      % (math.degrees(psi), math.degrees(math.atan2(s[0], s[1])), N[0], N[1], math.degrees(phi), FS))

mat = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600, frictionAngle=phi))
isWedge = [all(n @ (np.mean(np.array(b.corners), axis=0) - P) > 0 for n in normals) for b in rock]
ids = [O.bodies.append(ddaBlock(b.corners, material=mat, fixed=not w)) for b, w in zip(rock, isWedge)]
wedge = ids[isWedge.index(True)]
start = np.array(block(wedge).centroid)
print('wedge: %.2f m^3, %.0f kg' % (block(wedge).volume, block(wedge).mass))

O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
if VTK:   # --vtk=DIR: ParaView output every 0.1 s (doc/wedge.png: tools/render_vtk.py DIR/wedge-)
    import os
    O.engines = O.engines + [DDAVTKRecorder(fileName=os.path.join(VTK, 'wedge-'), virtPeriod=0.1)]
expected = G * math.sin(psi) * (1 - FS) if FS < 1 else 0.0
for _ in range(5):
    O.run(100, True)
    d = np.array(block(wedge).centroid) - start
    along = d @ s
    print('t %.2f s: %.5f m along s (closed form %.5f m), %.2e m across, speed %.4f m/s'
          % (O.time, along, expected * O.time ** 2 / 2, np.linalg.norm(d - along * s), np.linalg.norm(block(wedge).velocity[:3])))
if VTK:
    from yade_dda.recorder import record
    record(os.path.join(VTK, 'wedge-'))     # the final state too
