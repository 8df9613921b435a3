"""cutRockMass(..., concave=True): 3DEC's joined blocks (part lists for concaveBlock).

Oracles: joined blocks lie in one joint cell (the same side of every joint plane, exact from the
corners) and no two groups of one cell touch; volumes add up to the domain's; the fraction of a
non-persistent plane's area left as joint is its persistence within the binomial sampling error; the
same seed gives the same groups; every group is a block concaveBlock accepts; a jointed cube of concave
blocks rests on a fixed floor. SI units.
"""
import math

import numpy
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, cutRockMass, ddaBlock
from yade_dda import _core

from helpers import box, material

BENCH = [[(x, y, z) for x in (0, 20) for y in (0, 10) for z in (0, 10)],     # the slope's toe
         [(x, y, z) for x in (0, 10) for y in (0, 10) for z in (10, 20)]]    # its bench above
BENCH_SETS = [dict(dip=60, dipDirection=90, spacing=4, origin=(1, 0, 0)), dict(dip=90, dipDirection=0, spacing=5)]
CUBE = [(x, y, z) for x in (0, 12) for y in (0, 12) for z in (0, 12)]


def side(rock, block, plane):
    """-1 or +1: the side of plane `plane` that `block` lies on (its corners' mean; no corner is across)."""
    p = rock.planes[plane]
    c = [sum(x[k] for x in rock.blocks[block].corners) / len(rock.blocks[block].corners) for k in range(3)]
    return 1 if sum(p.normal[k] * c[k] for k in range(3)) > p.offset else -1


def cellOf(rock, block, planes):
    return tuple(side(rock, block, p) for p in planes)


def test_blocks_across_the_parts_of_a_domain_are_joined_within_their_joint_cell():
    rock = cutRockMass(BENCH, BENCH_SETS, concave=True)
    print(rock)
    joints = [i for i, p in enumerate(rock.planes) if p.kind == 'set']
    assert sum(len(g) > 1 for g in rock.groups) > 0
    assert sorted(i for g in rock.groups for i in g) == list(range(len(rock.blocks)))
    assert sum(rock.blocks[i].volume for i in range(len(rock.blocks))) == pytest.approx(3000, rel=1e-12)
    for group in rock.groups:
        cells = {cellOf(rock, i, joints) for i in group}
        assert len(cells) == 1, (group, cells)              # one joint cell
        assert len({rock.blocks[i].part for i in group}) == len(group)   # one block per part at most here
    # Groups of the same joint cell do not touch (else they would be one).
    groupOf = {i: k for k, g in enumerate(rock.groups) for i in g}
    for a, f, b, g, area in _core.sharedFaces([(blk.corners, blk.faces) for blk in rock.blocks]):
        if groupOf[a] != groupOf[b]:
            assert rock.planes[rock.blocks[a].planes[f]].kind == 'set', (a, b, area)
    # Without concave=True every block stands alone.
    assert all(len(g) == 1 for g in cutRockMass(BENCH, BENCH_SETS).groups)


def test_a_joint_plane_on_the_boundary_between_parts_keeps_them_apart():
    """A horizontal set whose plane z = 10 lies on the boundary between the slope's toe and its bench: the
    cells on either side are separated by a joint there, so no group spans the two parts; with the set
    offset by 1 m the boundary is intact rock and cells are joined across it."""
    on = cutRockMass(BENCH, [dict(dip=0, dipDirection=0, spacing=5), dict(dip=90, dipDirection=90, spacing=4)],
                     concave=True)
    assert all(len({on.blocks[i].part for i in g}) == 1 for g in on.groups), on.groups
    off = cutRockMass(BENCH, [dict(dip=0, dipDirection=0, spacing=5, origin=(0, 0, 1)),
                              dict(dip=90, dipDirection=90, spacing=4)], concave=True)
    assert any(len({off.blocks[i].part for i in g}) == 2 for g in off.groups), off.groups


@pytest.mark.parametrize('seed', [3, 4])
def test_a_non_persistent_set_leaves_its_persistence_of_joint_area(seed):
    p = 0.5
    rock = cutRockMass(CUBE, [dict(dip=0, dipDirection=0, spacing=1.5, origin=(0, 0, 0.7), persistence=p),
                              dict(dip=80, dipDirection=70, spacing=1.7), dict(dip=85, dipDirection=160, spacing=1.9)],
                       seed=seed, concave=True)
    pairs = len(rock.blocks)   # about one touching pair per block on the horizontal planes
    fraction = 1 - rock.absentArea / rock.jointArea
    sigma = math.sqrt(p * (1 - p) / pairs) * 2   # area-weighted: allow twice the count's standard error
    print(rock, 'joint fraction %.4f (p %.2f, sigma %.4f)' % (fraction, p, sigma))
    assert abs(fraction - p) < 4 * sigma
    assert sum(b.volume for b in rock.blocks) == pytest.approx(12 ** 3, rel=1e-12)
    again = cutRockMass(CUBE, [dict(dip=0, dipDirection=0, spacing=1.5, origin=(0, 0, 0.7), persistence=p),
                               dict(dip=80, dipDirection=70, spacing=1.7), dict(dip=85, dipDirection=160, spacing=1.9)],
                        seed=seed, concave=True)
    assert again.groups == rock.groups
    for group in rock.groups:
        if len(group) > 1:
            _core.checkConcaveBlock([rock.blocks[i].corners for i in group], 2600, 1e10, 0.25)


def test_a_cube_of_concave_blocks_rests_on_a_fixed_floor(scene):
    rho, g, young = 2600.0, 9.81, 1e10
    rock = cutRockMass(CUBE, [dict(dip=90, dipDirection=90, spacing=3), dict(dip=90, dipDirection=0, spacing=4),
                              dict(dip=0, dipDirection=0, spacing=3, persistence=0.5)], seed=1, concave=True)
    assert sum(len(g) > 1 for g in rock.groups) > 0
    mat = material(O, young=young, density=rho, frictionDeg=30)
    O.bodies.append(ddaBlock(box((-2, -2, -1), (14, 14, 0)), material=mat, fixed=True))
    ids = rock.append(material=mat, rigid=True)
    assert len(ids) == len(rock.groups)
    start = {i: tuple(yade_dda.block(i).centroid) for i in ids}
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -g), maxDisplacement=1e-3)]
    O.run(100, True)
    moved = max(math.dist(start[i], tuple(yade_dda.block(i).centroid)) for i in ids)
    print(rock, 'largest displacement %.3g m' % moved)
    assert moved < 1e-5   # the contact springs' settlement (test_rock_mass's rigid bound)
    assert sum(yade_dda.block(i).volume for i in ids) == pytest.approx(12 ** 3, rel=1e-12)


def test_concave_must_be_a_bool():
    with pytest.raises(ValueError, match='concave must be True or False'):
        cutRockMass(CUBE, [], concave=1)


def test_a_tunnel_in_concave_blocks_keeps_its_account_and_its_loose_block_falls_at_g(scene):
    """A 16 m x 8 m x 16 m box around a 4 m x 4 m tunnel, given as four convex parts, cut by two
    conjugate sets dipping 60 degrees and a horizontal set of persistence 0.6, joined into concave blocks
    (seed 4); the boundary blocks held, E = 1e10 Pa, 30 degrees of friction, gravity, 0.3 s. The energy
    account balances (1.5e-4 of the largest change) and what contact detection adds stays within 1e-4 of it; the
    block that falls
    farthest, concave, falls freely: its drop fits g t^2 / 2 (1 %)."""
    parts = [box((0, 0, 0), (16, 8, 6)), box((0, 0, 10), (16, 8, 16)), box((0, 0, 6), (6, 8, 10)),
             box((10, 0, 6), (16, 8, 10))]
    rock = cutRockMass(parts, [dict(dip=60, dipDirection=90, spacing=3.1, origin=(8, 0, 12)),
                               dict(dip=60, dipDirection=270, spacing=3.3, origin=(8, 0, 12)),
                               dict(dip=0, dipDirection=0, spacing=2.5, origin=(0, 0, 11), persistence=0.6)],
                       seed=4, concave=True)
    print(rock)
    mat = material(O, young=1e10, frictionDeg=30)

    def held(blocks):
        return any(min(p[k] for p in b.corners) < 1e-9 or max(p[k] for p in b.corners) > 16 - 1e-9
                   for b in blocks for k in (0, 2))

    ids = rock.append(material=mat, fixed=held)
    free = [i for i in ids if not yade_dda.block(i).fixed]
    assert any(yade_dda.block(i).partCount > 1 for i in free)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.01)]
    O.step()
    e0 = dict(yade_dda.stats()['energy'])
    t0, z0 = O.time, {i: yade_dda.block(i).centroid[2] for i in free}
    track = {i: [] for i in free}
    times = []
    for _ in range(300):
        O.step()
        times.append(O.time - t0)
        for i in free:
            track[i].append(z0[i] - yade_dda.block(i).centroid[2])
    e = yade_dda.stats()['energy']
    account = lambda e: (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping']
                         - e['loads'] - e['contactChanges'])
    scale = max(abs(e[k] - e0[k]) for k in e)
    # The account is exact to round-off but for a residual that depends on the trajectory: 0.05 to 0.6 J
    # lost (never gained) in steps where contacts slide, 9.2e-5 of the largest change over the run. Its
    # source: a pass is accepted when no state changes and the slipping contacts' forces match their
    # model, also when the line search shortened its last Newton step, so the iterate falls short of
    # the minimiser of the pass's energy and the step's equations hold only to the rest of that step.
    # Requiring a full last step makes this scene's account exact (3e-8 J) but leaves contacts sitting
    # at a kink of their energy (a gap at zero, a stretch at its limit) with no pass that converges:
    # jointed masses cut their step to 1e-154 s. With friction limits accepted as they stand when
    # they do not settle (fewer steps with sliding contacts and limit passes) it is 1.8e-5.
    # 1.5e-4 bounds it.
    assert abs(account(e) - account(e0)) < 1.5e-4 * scale, (account(e) - account(e0), scale)
    # What detection gives the springs stays within 1e-4 of the largest change. The bursts it had came from
    # corners given a negative gap against a face whose plane runs on past a ridge of a concave block,
    # the corners outside the whole block: 78 J in one step (refineSolves off; +114 J over the run on an
    # older solver), until ownEntranceContact bounded those gaps by the pair's penetration (OwnEntrance.cpp).
    # Now -74 J of 2.3e5 (energy lost; -37 J with refineSolves off, no step above 1 J).
    changes = e['contactChanges'] - e0['contactChanges']
    print('contact changes %.4g J, largest change %.4g J' % (changes, scale))
    assert changes <= 1e-4 * scale
    fallen = max(free, key=lambda i: track[i][-1])
    # Its first steps it shares with free neighbours that fall too and part from it; from 0.05 s on it
    # touches nothing: its drop is a parabola of curvature g.
    a = 2 * numpy.polyfit(times[50:], track[fallen][50:], 2)[0]
    print('block %d (%d parts) fell %.4f m in %.4f s; acceleration from 0.05 s on %.6f m/s^2' % (
        fallen, yade_dda.block(fallen).partCount, track[fallen][-1], times[-1], a))
    assert yade_dda.block(fallen).partCount > 1
    assert a == pytest.approx(9.81, rel=1e-4)
