"""Bonded joints: cohesion and tensile strength of contacts closed when the scene
starts (ddaBlock's cohesion and tensileStrength, in Pa).

Closed forms: a unit cube (face area A = 1 m^2) of weight W = rho g L^3 hangs
from a fixed block by its top face: the joint holds iff T A > W. On a
frictional slope of angle a, with the slope gravity tilted instead, the joint
holds iff c A > W (sin a - tan(phi) cos a). The blocks start unloaded, so
gravity comes on suddenly and the joint's first peak load is up to twice the
static one: the holding cases use 3 x the static limit, the breaking ones 0.5 x.
Each checks the motion and the state the contacts report.
"""
import math

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock
from yade import wrapper

from helpers import box

G = 9.81
RHO = 2600.0
WEIGHT = RHO * G  # unit cube [N]


def material(frictionDeg):
    return O.materials.append(wrapper.PolyhedraMat(density=RHO, young=1e9, poisson=0.25,
                                                   frictionAngle=math.radians(frictionDeg)))


@pytest.mark.parametrize('ratio, holds', [(3.0, True), (0.5, False)])
def test_hanging_block_holds_iff_tensile_strength_exceeds_weight(scene, ratio, holds):
    rock = material(30)
    strength = ratio * WEIGHT  # [Pa] on the 1 m^2 joint
    # Cohesion too: without it a joint in tension has no shear strength at all
    # (friction needs compression), and the hanging cube's Poisson contraction
    # shears its corners.
    bond = dict(tensileStrength=strength, cohesion=strength)
    O.bodies.append(ddaBlock(box((-1, -1, 1), (1, 1, 2)), material=rock, fixed=True, **bond))
    b = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=rock, **bond))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    O.run(1, True)
    first = yade_dda.contacts()
    assert len(first) == 4 and all(c.type == 'FF' for c in first)
    O.run(499, True)
    drop = 0.5 - yade_dda.block(b).centroid[2]
    if holds:
        assert drop < 1e-4
        closed = yade_dda.contacts('closed')
        assert len(closed) == 4 and all(c.bonded for c in closed)
        # The joint carries the weight in tension: sum of normal forces = -W.
        assert abs(sum(c.normalForce for c in closed) + WEIGHT) < 1e-3 * WEIGHT
    else:
        t = O.time
        assert drop > 0.9 * 0.5 * G * t * t
        assert not any(c.bonded for c in yade_dda.contacts())


@pytest.mark.parametrize('ratio, holds', [(3.0, True), (0.5, False)])
def test_cohesion_holds_a_block_on_a_slope_iff_it_exceeds_the_driving_shear(scene, ratio, holds):
    """A flat 2 x 1 x 0.5 m block (weight W, base area 2 m^2, far from toppling:
    width/height 4 > tan(45 deg)) on a 45 degree slope with 20 degrees of friction."""
    slope, phi, area = math.radians(45), 20, 2.0
    driving = WEIGHT * (math.sin(slope) - math.tan(math.radians(phi)) * math.cos(slope))
    rock = material(phi)
    c = ratio * driving / area  # [Pa]
    O.bodies.append(ddaBlock(box((-10, -5, -1), (10, 5, 0)), material=rock, fixed=True, cohesion=c))
    b = O.bodies.append(ddaBlock(box((-1, -0.5, 0), (1, 0.5, 0.5)), material=rock, cohesion=c))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(G * math.sin(slope), 0, -G * math.cos(slope)),
                               maxDisplacement=0.01, label='dda')]
    O.run(500, True)
    moved = yade_dda.block(b).centroid[0]
    if holds:
        assert abs(moved) < 1e-4
        assert all(c.bonded and c.state == 'locked' for c in yade_dda.contacts())
    else:
        # Once broken, pure friction: close to the frictional sliding distance.
        acc = driving / RHO
        assert moved > 0.9 * 0.5 * acc * O.time ** 2
        assert not any(c.bonded for c in yade_dda.contacts())


def test_contacts_made_after_the_first_step_are_not_bonded(scene):
    rock = material(30)
    strength = 10 * WEIGHT
    O.bodies.append(ddaBlock(box((-2, -2, -1), (2, 2, 0)), material=rock, fixed=True, tensileStrength=strength,
                             cohesion=strength))
    b = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0.01), (0.5, 0.5, 1.01)), material=rock,
                                 tensileStrength=strength, cohesion=strength))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.01, label='dda')]
    O.run(200, True)
    closed = yade_dda.contacts('closed')
    assert len(closed) == 4
    assert not any(c.bonded for c in closed)
    # Thrown upwards, it leaves the floor: an unbonded joint carries no tension.
    yade_dda.setVelocity(b, (0, 0, 2))
    O.run(50, True)
    assert yade_dda.block(b).centroid[2] > 0.5 + 0.05


def test_bond_strengths_are_validated(scene):
    with pytest.raises(ValueError, match='cohesion'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), cohesion=-1)
    with pytest.raises(ValueError, match='tensileStrength'):
        ddaBlock(box((0, 0, 0), (1, 1, 1)), tensileStrength=float('nan'))

