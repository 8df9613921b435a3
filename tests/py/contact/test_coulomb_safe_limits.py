"""A slide along a joint that other joints cross, against the closed form and Coulomb's bound.

The scene (draw_case, seeded, the seed in every message): a box cut by a sliding plane A
(dip theta, dipping east), two horizontal joints and a vertical one, the rock east of a
vertical face excavated so that A daylights. The rock above A slides; the rock below A is
held where it touches the box's west side or base and free elsewhere (free blocks wedged
between the slide and the held rock, on joints of 60 deg friction so that they hold).
Where a horizontal joint meets A, four blocks meet at a line, and the lower one cuts a thin
sliver off the toe of the slide. Its pieces slide together, at

    a = g (sin(theta) - tan(phi) cos(theta))

along A (phi the slide's friction angle, FS = tan(phi) / tan(theta) 0.5 to 0.8).

The friction limits of its contacts do not settle within a step's passes: the normal forces
of the sliver and of the corners at the junctions shift pass after pass. Oracles:

- the slide's mass-weighted displacement along the dip, fitted from 0.1 s to 0.3 s, gives
  the closed-form acceleration within 1 %;
- at every step no closed contact carries more friction than Coulomb's law gives its
  normal force: |shear force| <= (1 + staticFrictionExcess) tan(phi) N, to 1e-3 of its
  force scale, the smaller of its moving blocks' largest Coulomb limits (OpenClose.cpp,
  closePasses: the Coulomb-safe passes, and their tolerance);
- the scene exercises those passes (stats()['limitsLowered'] > 0 in some step), so the
  oracles above test them.
SI units.
"""
import math

import numpy as np
import pytest

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator, cutRockMass
from yade import PolyhedraMat

G = 9.81
DT = 1e-3
SEEDS = (1, 2, 3)


def draw_case(seed):
    """The seeded geometry: dip theta [rad], slide friction phi [rad] (FS 0.5 to 0.8), the
    heights of the two horizontal joints and the x of the vertical one [m]."""
    rng = np.random.default_rng(seed)
    theta = math.radians(rng.uniform(30.0, 40.0))
    fs = rng.uniform(0.5, 0.8)
    phi = math.atan(fs * math.tan(theta))
    return dict(seed=seed, theta=theta, phi=phi, fs=fs, lower=rng.uniform(0.9, 1.1),
                upper=rng.uniform(1.9, 2.1), split=rng.uniform(1.8, 2.2))


def describe(case):
    return 'seed %d: theta %.2f deg, phi %.2f deg (FS %.3f)' % (
        case['seed'], math.degrees(case['theta']), math.degrees(case['phi']), case['fs'])


def build(case):
    """Appends the blocks; returns (slide block ids, the down-dip unit vector)."""
    theta = case['theta']
    box = [(x, y, z) for x in (0, 6) for y in (0, 2) for z in (0, 4)]
    point = (3.0, 1.0, 2.0)
    normal = (math.sin(theta), 0.0, math.cos(theta))
    sets = [dict(plane=(point, normal)),
            dict(plane=((3.0, 1.0, case['upper']), (0, 0, 1.0))),
            dict(plane=((3.0, 1.0, case['lower']), (0, 0, 1.0))),
            dict(plane=((case['split'], 1.0, 2.0), (1.0, 0, 0))),
            # The face where A daylights, just past the lower joint's line on A.
            dict(excavate=((3.0 + (2.0 - case['lower']) / math.tan(theta) + 0.07, 0, 0), (1.0, 0, 0)))]
    rock = cutRockMass(box, sets, seed=case['seed'], minVolume=0)
    slide_mat = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600.0,
                                                frictionAngle=case['phi']))
    base_mat = O.materials.append(PolyhedraMat(young=1e9, poisson=0.25, density=2600.0,
                                               frictionAngle=math.radians(60.0)))
    slide = []
    for b in rock.blocks:
        above = (np.mean(b.corners, axis=0) - point) @ np.array(normal) > 0
        held = not above and any(p[0] <= 1e-9 or p[2] <= 1e-9 for p in b.corners)
        i = O.bodies.append(ddaBlock(b.corners, material=slide_mat if above else base_mat, fixed=held))
        if above:
            slide.append(i)
    return slide, np.array([math.cos(theta), 0.0, -math.sin(theta)])


@pytest.mark.parametrize('seed', SEEDS)
def test_slide_across_joint_junctions_keeps_coulombs_bound_and_rate(scene, seed):
    case = draw_case(seed)
    where = describe(case)
    slide, down = build(case)
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -G), label='dda')]
    O.step()
    start = {i: np.array(yade_dda.block(i).centroid) for i in slide}
    mass = {i: yade_dda.block(i).mass for i in slide}
    total = sum(mass.values())
    excess = O.engines[0].staticFrictionExcess
    moving = {b.id for b in O.bodies if not yade_dda.block(b.id).fixed}
    lowered, worst, track = 0, 0.0, []
    while O.time < 0.3 - 1e-9:
        O.step()
        lowered += yade_dda.stats()['limitsLowered']
        closed = yade_dda.contacts('closed')
        # A moving block's force scale: the largest Coulomb limit among its contacts (fixed
        # blocks have none; a contact's scale is its moving blocks' smaller one).
        bound, scale = {}, {}
        for c in closed:
            mu = math.tan(case['phi'] if (c.id1 in slide or c.id2 in slide) else math.radians(60.0))
            bound[c] = (1 + excess) * mu * max(c.normalForce, 0.0)
            for b in (c.id1, c.id2):
                if b in moving:
                    scale[b] = max(scale.get(b, 0.0), bound[c])
        for c in closed:
            pair = min(scale[b] for b in (c.id1, c.id2) if b in scale)
            over = (np.linalg.norm(c.shearForce) - bound[c]) / pair if pair > 0 else 0.0
            worst = max(worst, over)
            assert over <= 1e-3, (where, 'step', O.iter, 'contact', c.id1, c.id2, c.type, 'shear',
                                  np.linalg.norm(c.shearForce), 'Coulomb', bound[c])
        along = sum(mass[i] * (np.array(yade_dda.block(i).centroid) - start[i]) @ down for i in slide) / total
        track.append((O.time, along))
    t, x = np.array(track).T
    late = t >= 0.1 - 1e-9
    fitted = np.linalg.lstsq(np.c_[np.ones(late.sum()), t[late], 0.5 * t[late] ** 2], x[late], rcond=None)[0][2]
    closed_form = G * (math.sin(case['theta']) - math.tan(case['phi']) * math.cos(case['theta']))
    print('%s: acceleration %.5f, closed form %.5f (%+.2e); limitsLowered %d; worst excess %.2e' % (
        where, fitted, closed_form, fitted / closed_form - 1, lowered, worst))
    assert lowered > 0, (where, 'no step needed Coulomb-safe passes: the scene does not test them')
    assert abs(fitted / closed_form - 1) < 1e-2, (where, 'acceleration', fitted, 'closed form', closed_form)
