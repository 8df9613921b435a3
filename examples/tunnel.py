# tunnel.py -- a tunnel in jointed rock whose crown loosens, against key-block theory.
# A 24 m x 20 m x 24 m box of rock (E = 1e10 Pa, density 2600, joints frictional at 30 degrees, no
# cohesion) is cut by three oblique joint sets through one point above the crown (cutRockMass), and a
# box-shaped tunnel (6 m x 6 m, its roof at z = 13 m) is taken out along y.
# The blocks on the box's faces are held, the rest free, gravity on. Before the run the script sorts
# every free block by key-block theory (Goodman & Shi) from its geometry alone: the blocks that fall
# free because every joint face of theirs opens under a translation d = (0, 0, -1) (outward normal
# n with n . d < 0), then those that fall once those are gone, then the locked ones (no translation
# at all opens them against the blocks that stay) and the rest (friction decides). It runs the scene
# and prints which blocks fell, how far, how many stayed, the energy account and the run time.
# Run with: yade -n -x examples/tunnel.py [--time 1.2] [--vtk DIR]
#           (or /usr/bin/python3 examples/tunnel.py ...)
# tests/py/system/test_tunnel.py is the test; doc/rock-mass.md reports the numbers; doc/tunnel.png is
# the picture (--vtk DIR, then tools/render_vtk.py DIR/tunnel- --colour displacement).
import argparse
import math
import os
import sys
import time

import numpy as np

G = 9.81
BOX = (24.0, 20.0, 24.0)                       # the rock mass [m]: x (east), y (north, the tunnel's axis), z (up)
AXIS_X, HALF_WIDTH, FLOOR, ROOF = 12.0, 3.0, 7.0, 13.0   # tunnel: centre line x, walls at x -+ 3, floor and roof z [m]
APEX = (12.0, 10.0, 15.5)                      # every joint set has a plane through this point [m]
JOINT_SETS = [(50.0, 55.0, 7.0), (58.0, 125.0, 7.5), (62.0, 265.0, 6.5)]   # (dip, dip direction [deg], spacing [m])
FRICTION_DEG, YOUNG, DENSITY = 30.0, 1e10, 2600.0
EPS = 1e-9                                     # tolerance on unit normals' components


def tunnelSection():
    """The tunnel's (x, z) corners [m]: a box, 6 m x 6 m (why not an arch: doc/rock-mass.md)."""
    return [(AXIS_X - HALF_WIDTH, FLOOR), (AXIS_X + HALF_WIDTH, FLOOR), (AXIS_X + HALF_WIDTH, ROOF),
            (AXIS_X - HALF_WIDTH, ROOF)]


def cut(jointSets=JOINT_SETS, apex=APEX):
    """The rock mass cut by the joint sets and the tunnel (a RockMass; every block kept, see the doc)."""
    from yade_dda import cutRockMass
    lx, ly, lz = BOX
    sets = [dict(dip=d, dipDirection=a, spacing=s, origin=apex) for d, a, s in jointSets]
    tunnel = [(x, y, z) for x, z in tunnelSection() for y in (-1.0, ly + 1.0)]
    return cutRockMass([(x, y, z) for x in (0, lx) for y in (0, ly) for z in (0, lz)], sets + [dict(excavate=tunnel)])


# --- key-block theory (Goodman & Shi 1985), from the blocks' corners and face planes only ---------------

def outwardNormal(corners, face):
    """Unit outward normal of a face (corner indices counter-clockwise seen from outside; Newell)."""
    c = np.array([corners[k] for k in face])
    n = np.cross(c, np.roll(c, -1, axis=0)).sum(axis=0)
    return n / np.linalg.norm(n)


def _polygonArea2d(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _clip(subject, clipper):
    """Sutherland-Hodgman: the convex polygon subject (2d, any orientation) clipped by the convex clipper."""
    if _polygonArea2d(clipper) == 0:
        return subject[:0]
    sign = 1.0 if np.cross(clipper[1] - clipper[0], clipper[2] - clipper[0]) > 0 else -1.0
    out = list(subject)
    for a, b in zip(clipper, np.roll(clipper, -1, axis=0)):
        pts, out = out, []
        side = [sign * np.cross(b - a, p - a) for p in pts]
        for k in range(len(pts)):
            p, q, sp, sq = pts[k], pts[(k + 1) % len(pts)], side[k], side[(k + 1) % len(pts)]
            if sp >= 0:
                out.append(p)
            if (sp >= 0) != (sq >= 0):
                out.append(p + (q - p) * (sp / (sp - sq)))
        if len(out) < 3:
            return subject[:0]
    return np.array(out)


def faceContacts(rock):
    """For each block, a list of (unit outward normal, plane kind, neighbour index or None, shared area
    [m^2]) per face and neighbour: two blocks touch across a face when their faces lie on the same
    plane of the cut, with opposite normals, and overlap with positive area (several neighbours
    when a merged sliver made a T-junction)."""
    onPlane = {}
    normals = []
    for i, b in enumerate(rock):
        normals.append([outwardNormal(b.corners, f) for f in b.faces])
        for k, p in enumerate(b.planes):
            onPlane.setdefault(p, []).append((i, k))
    out = [[] for _ in rock]
    for i, b in enumerate(rock):
        for k, p in enumerate(b.planes):
            n = normals[i][k]
            kind = rock.planes[p].kind
            u = np.cross(n, (1.0, 0, 0) if abs(n[0]) < 0.9 else (0, 1.0, 0))
            u /= np.linalg.norm(u)
            v = np.cross(n, u)
            mine = np.array([[c @ u, c @ v] for c in (np.array(b.corners[j]) for j in b.faces[k])])
            found = False
            for j, m in onPlane[p]:
                if j == i or normals[j][m] @ n > -0.5:
                    continue
                other = np.array([[c @ u, c @ v] for c in (np.array(rock[j].corners[q]) for q in rock[j].faces[m])])
                area = _polygonArea2d(_clip(mine, other)) if len(mine) else 0.0
                if area > 1e-9 * _polygonArea2d(mine):
                    out[i].append((n, kind, j, area))
                    found = True
            if not found:
                out[i].append((n, kind, None, _polygonArea2d(mine)))
    return out


def opensUnder(normals, d):
    """True when the translation d opens or slides every face (n . d <= EPS for each outward normal n)."""
    return all(n @ d <= EPS for n in normals)


def removable(normals):
    """Whether some translation d != 0 opens or slides every face of these outward normals: the joint
    pyramid {d : n . d <= 0} is more than the origin (Goodman & Shi). Its extreme rays lie on two of
    the planes n . d = 0 (d = -+ n_i x n_j), or, when all normals are parallel, any d normal to them."""
    normals = [np.asarray(n) for n in normals]
    if not normals:
        return True
    candidates = [-normals[0], np.cross(normals[0], (1.0, 0, 0) if abs(normals[0][0]) < 0.9 else (0, 1.0, 0))]
    for a in range(len(normals)):
        for b in range(a + 1, len(normals)):
            c = np.cross(normals[a], normals[b])
            if np.linalg.norm(c) > 1e-6:
                candidates += [c, -c]
    return any(opensUnder(normals, c / np.linalg.norm(c)) for c in candidates)


def keyBlocks(rock, held, contacts=None):
    """Key-block analysis under gravity of the free blocks (those not in `held`), by rounds: round 1 are
    the blocks every joint face of which opens under d = (0, 0, -1) (outward n_z > 0: they fall free,
    at g, whatever the friction); round k those that do so once rounds 1..k-1 are gone. Of the blocks
    left, 'locked' have an empty joint pyramid against the blocks that stay (no translation at all
    frees them: they can only settle on their springs), 'other' have a non-empty one (some translation
    frees them; friction decides whether gravity drives it). Returns ({block: round}, locked, other)."""
    contacts = contacts or faceContacts(rock)
    down = np.array([0.0, 0.0, -1.0])
    stays = set(range(len(rock)))
    falls = {}
    free = [i for i in range(len(rock)) if i not in held]
    for rnd in range(1, len(rock) + 1):
        now = [i for i in free if i in stays
               and opensUnder([n for n, kind, j, _ in contacts[i] if j is not None and j in stays], down)]
        if not now:
            break
        for i in now:
            falls[i] = rnd
            stays.discard(i)
    # locked: proven one by one against the held blocks and those already proven (a least fixed point:
    # blocks that lock each other only together could still leave as a group, so they are not called locked)
    sure, locked = set(held), []
    while True:
        now = [i for i in free if i in stays and i not in sure
               and not removable([n for n, kind, j, _ in contacts[i] if j is not None and j in sure])]
        if not now:
            break
        sure.update(now)
        locked += now
    other = [i for i in free if i in stays and i not in sure]
    return falls, sorted(locked), other


def onBoundary(rock, i):
    return any(rock.planes[p].kind == 'domain' for p in rock[i].planes)


def material(young=YOUNG, frictionDeg=FRICTION_DEG):
    from yade_dda import O
    from yade import PolyhedraMat
    return O.materials.append(PolyhedraMat(young=young, poisson=0.25, density=DENSITY,
                                           frictionAngle=math.radians(frictionDeg)))


def main(argv):
    parser = argparse.ArgumentParser(description='a tunnel in jointed rock whose crown loosens')
    parser.add_argument('--time', type=float, default=1.2, help='simulated time [s]')
    parser.add_argument('--vtk', default='', help='write DDAVTKRecorder output to this directory')
    args = parser.parse_args(argv)
    from yade_dda import O, DDAIntegrator, DDAVTKRecorder, ddaBlock, block, stats

    t0 = time.time()
    rock = cut()
    print(rock, '(cut in %.2f s)' % (time.time() - t0))
    print('joint sets (dip/dip direction, spacing): %s, all through %s; friction %g deg, E %.0e Pa'
          % (', '.join('%g/%03g %g m' % s for s in JOINT_SETS), APEX, FRICTION_DEG, YOUNG))
    held = {i for i in range(len(rock)) if onBoundary(rock, i)}
    falls, locked, other = keyBlocks(rock, held)
    print('key-block theory: %d held, %d free; %d fall free in round 1 (key blocks), %d in later rounds, '
          '%d locked, %d others (friction decides)' % (len(held), len(rock) - len(held),
          sum(r == 1 for r in falls.values()), sum(r > 1 for r in falls.values()), len(locked), len(other)))

    O.reset()
    mat = material()
    ids = [O.bodies.append(ddaBlock(b.corners, material=mat, fixed=i in held)) for i, b in enumerate(rock)]
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), maxDisplacement=0.02, label='dda')]
    if args.vtk:
        O.engines = O.engines + [DDAVTKRecorder(fileName=os.path.join(args.vtk, 'tunnel-'), virtPeriod=0.1)]
    O.trackEnergy = True
    start = {i: np.array(block(ids[i]).centroid) for i in range(len(rock))}
    t0 = time.time()
    O.run(1, True)
    e0 = dict(stats()['energy'])
    while O.time < args.time - 1e-9:
        O.run(10, True)
    wall = time.time() - t0
    if args.vtk:
        from yade_dda.recorder import record
        record(os.path.join(args.vtk, 'tunnel-'))     # the final state too
    e = stats()['energy']
    drop = {i: start[i][2] - block(ids[i]).centroid[2] for i in range(len(rock)) if i not in held}
    fell = sorted((i for i in drop if drop[i] > 0.05), key=lambda i: -drop[i])
    print('after %.2f s (%d steps, %.1f s of wall time; free fall would be %.2f m):'
          % (O.time, O.iter, wall, G * O.time ** 2 / 2))
    for i in fell:
        c = start[i]
        print('  block %3d (%.2f m^3, from (%.1f, %.1f, %.1f)) fell %.3f m   theory: %s'
              % (i, rock[i].volume, c[0], c[1], c[2], drop[i],
                 'falls, round %d' % falls[i] if i in falls else 'locked' if i in locked else 'friction decides'))
    stayed = [i for i in drop if drop[i] <= 0.05]
    most = max(stayed, key=lambda i: drop[i]) if stayed else None
    print('  %d free blocks stayed (the largest drop %.2e m, block %s: %s); theory said %d fall, DDA %d fell'
          % (len(stayed), drop.get(most, 0.0), most, 'locked' if most in locked else 'friction decides',
             len(falls), len(fell)))
    names = ('kinetic', 'gravity', 'strain', 'contact', 'friction', 'damping', 'loads', 'contactChanges')
    change = {k: e[k] - e0[k] for k in names}
    balance = sum(change[k] for k in names[:6]) - change['loads'] - change['contactChanges']
    print('energy account since the first step [J]: ' + ', '.join('%s %+.4g' % (k, change[k]) for k in names))
    print('  balance %.3g J (%.2g of the gravity change); O.energy.total() %.6g J' %
          (balance, balance / abs(change['gravity']) if change['gravity'] else 0.0, O.energy.total()))


# Under `yade -x script.py args`, sys.argv is [script.py, args...]; imported (by the test), nothing runs.
if __name__ == '__main__':
    main(sys.argv[1:] if sys.argv and sys.argv[0].endswith('.py') else [])
