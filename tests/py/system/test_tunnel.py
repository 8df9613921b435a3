"""A tunnel in jointed rock whose crown loosens against key-block theory (Goodman & Shi).

The scene is examples/tunnel.py's: a 24 m x 20 m x 24 m box of rock cut by three oblique joint sets
(dip/dip direction 50/055, 58/125, 62/265, spacings 7, 7.5 and 6.5 m, each with a plane through
(12, 10, 15.5)) and a 6 m x 6 m box-shaped tunnel along y, its roof at z = 13 m; E = 1e10 Pa,
density 2600, joints at 30 degrees of friction, no cohesion. Here only the crown is free: the blocks
with a face exposed on the tunnel's roof; every other block is held.

Oracle (key-block theory, from the blocks' geometry alone, examples/tunnel.py's keyBlocks): a free
block translating by d = (0, 0, -1) opens a joint face of outward normal n when n . d < 0, slides
along it when n . d = 0 and is blocked when n . d > 0. A block all of whose joint faces open is a key
block: it touches nothing once it moves, so it falls at g whatever the friction (round 1; round 2 are
those resting only on round-1 blocks). A block whose joint pyramid {d : n . d <= 0 over its faces
against held rock} is the origin alone is locked: no translation frees it; it can only settle on its
contact springs. The joint sets were chosen (their planes through one point 2.5 m above the roof) so
that the crown holds a tetrahedral key block tapering upward, 15.75 m^3, and beside it a block
tapering downward to the roof between held rock, locked.

Checked: each round-1 key block's vertical acceleration equals g within 1 %; each locked block's
centroid moves less than m g / (kn n_z^2), its settlement were one contact spring to carry its whole
weight along the steepest face that looks down (measured: 1.4e-6 m against 4.7e-6 m); the energy account balances (its terms'
change minus what contact detection added, to 1e-6 of the largest change) and contact detection adds
no energy.
"""
import math
import os
import sys

import numpy as np
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock
from yade_dda.rockmass import pole

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'examples'))
import tunnel  # noqa: E402  (examples/tunnel.py: the scene and the key-block oracle)

G = tunnel.G
PENALTY = 40.0          # contactPenaltyFactor's default: a sub-contact's kn = 40 x the smaller E x size [N/m]
DURATION = 0.3          # [s]: the key block falls 0.44 m, well inside the 6 m tunnel


def roofBlocks(rock, contacts):
    """The free blocks of the crown: a face exposed (no neighbour) on the tunnel's roof (outward -z)."""
    return {i for i, faces in enumerate(contacts) if not tunnel.onBoundary(rock, i)
            and any(j is None and kind == 'excavation' and n[2] < -1 + 1e-9 for n, kind, j, _ in faces)}


@pytest.fixture(scope='module')
def crown():
    """(rock, contacts, held, falls, locked, other) with only the crown free."""
    rock = tunnel.cut()
    contacts = tunnel.faceContacts(rock)
    held = set(range(len(rock))) - roofBlocks(rock, contacts)
    falls, locked, other = tunnel.keyBlocks(rock, held, contacts)
    return rock, contacts, held, falls, locked, other


def describe(rock, i):
    c = np.mean(np.array(rock[i].corners), axis=0)
    return 'block %d (%.2f m^3, corners around (%.2f, %.2f, %.2f))' % (i, rock[i].volume, *c)


def test_the_oracle_finds_a_key_block_and_a_locked_one(crown):
    rock, contacts, held, falls, locked, other = crown
    print('geometry: box %s m, joint sets (dip, dip direction, spacing) %s through %s, tunnel section %s; '
          'cutRockMass seed %d: %s' % (tunnel.BOX, tunnel.JOINT_SETS, tunnel.APEX, tunnel.tunnelSection(), rock.seed, rock))
    print('crown: falls %s, locked %s, other %s' % (falls, locked, other))
    keys = [i for i, r in falls.items() if r == 1]
    assert keys and locked
    for i in keys:     # tapering upward: every joint face's outward normal points up
        up = [n[2] for n, kind, j, _ in contacts[i] if j is not None]
        assert len(up) >= 3 and min(up) > 0.3, (describe(rock, i), up)
    for i in locked:   # tapering downward: some joint face looks down onto held rock
        assert any(n[2] < -0.3 and j in held for n, kind, j, _ in contacts[i]), describe(rock, i)


def test_the_oracle_on_known_pyramids():
    """removable() on normals whose answer is known: a cube's six faces lock it, five leave it one way
    out, a tetrahedron tapering upward leaves downwards, one tapering downward is locked by its three
    faces and a lid."""
    cube = [np.array(v, float) for v in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))]
    assert not tunnel.removable(cube)
    assert tunnel.removable(cube[:5]) and tunnel.opensUnder(cube[:5], np.array([0, 0, -1.0]))
    up = [np.array(pole(d, a)) for d, a, _ in tunnel.JOINT_SETS]
    assert tunnel.opensUnder(up, np.array([0, 0, -1.0])) and tunnel.removable(up)
    assert not tunnel.removable([-n for n in up] + [np.array([0, 0, 1.0])])


def test_the_crown_key_block_falls_at_g_and_the_locked_blocks_hold(scene, crown):
    rock, contacts, held, falls, locked, other = crown
    mat = tunnel.material()
    free = set(falls) | set(locked) | set(other)
    ids = [O.bodies.append(ddaBlock(b.corners, material=mat, fixed=i not in free)) for i, b in enumerate(rock)]
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    O.trackEnergy = True
    start = {i: np.array(yade_dda.block(ids[i]).centroid) for i in free}
    O.run(1, True)
    e0 = dict(yade_dda.stats()['energy'])
    total0 = O.energy.total()
    t, z, moved = [], {i: [] for i in falls}, {i: 0.0 for i in locked}
    while O.time < DURATION:
        O.run(1, True)
        t.append(O.time)
        for i in falls:
            z[i].append(yade_dda.block(ids[i]).centroid[2] - start[i][2])
        for i in locked:
            moved[i] = max(moved[i], np.linalg.norm(np.array(yade_dda.block(ids[i]).centroid) - start[i]))
    t = np.array(t)
    for i, rnd in sorted(falls.items()):
        a = -2 * np.polyfit(t, np.array(z[i]), 2)[0]
        print('%s, falls in round %d: acceleration %.5f m/s^2 (g %.2f, ratio %.5f), fell %.4f m in %.3f s'
              % (describe(rock, i), rnd, a, G, a / G, -z[i][-1], t[-1]))
        if rnd == 1:
            assert a == pytest.approx(G, rel=0.01)
    for i in locked:
        # the centroid's settlement on the springs (DDA's strain is uniform about the centroid, so the
        # block's own elastic shortening does not move it): m g over one sub-contact's kn (the smaller
        # E x size of the block and its neighbours, as the core takes it), divided by the smallest n_z^2
        # of its faces that look down (a spring at angle theta to the vertical carries m g / cos theta
        # and gives cos theta of its shortening vertically): as if one spring carried the whole weight
        b = yade_dda.block(ids[i])
        sizes = [rock[j].volume ** (1 / 3) for _, _, j, _ in contacts[i] if j is not None] + [b.volume ** (1 / 3)]
        kn = PENALTY * tunnel.YOUNG * min(sizes)
        nz = min(n[2] ** 2 for n, _, j, _ in contacts[i] if j is not None and n[2] < 0)
        bound = b.mass * G / (kn * nz)
        print('%s, locked: its centroid moved at most %.3g m (bound m g / (kn nz^2) = %.3g m; kn %.3g N/m, nz^2 %.3f)'
              % (describe(rock, i), moved[i], bound, kn, nz))
        assert moved[i] < bound
    e = yade_dda.stats()['energy']
    scale = max(abs(e[k] - e0[k]) for k in e)
    drift = sum(e[k] - e0[k] for k in ('kinetic', 'gravity', 'strain', 'contact', 'friction', 'damping')) \
        - (e['loads'] - e0['loads']) - (e['contactChanges'] - e0['contactChanges'])
    added = e['contactChanges'] - e0['contactChanges']
    print('energy after %.3f s: largest change %.4g J, balance %.3g J (%.2g), contact changes %.3g J, '
          'O.energy.total() %.10g -> %.10g J' % (O.time, scale, drift, drift / scale, added, total0, O.energy.total()))
    assert abs(drift) <= 1e-6 * scale
    assert added <= 1e-6 * scale
    assert O.energy.total() == pytest.approx(total0, abs=1e-6 * scale)
