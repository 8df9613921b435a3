"""Which blocks the global DDA system couples (SI units).

Only closed contacts carry terms in K D = F, so only they join blocks into one
system; an open contact within the contact distance couples nothing until the
open-close iteration closes it. What could go wrong: every pair within d0
solved as one sparse system (a loose deposit of 50,000 blocks with no closed
contact was solved as one system of 48,000 blocks), or a contact that closes
during the iteration left out of the structure (its terms would have nowhere
to go).
"""
import math

from yade_dda import O, DDAIntegrator, ddaBlock
import yade_dda

from helpers import box, material

G = 9.81


def test_open_contacts_within_d0_couple_nothing(scene):
    """A row of cubes falling side by side, 2 mm apart with d0 = 5 mm: every
    neighbour pair is a contact within d0, none closes, every cube is its own
    system and falls exactly as in free fall."""
    rock = material(O, young=1e9)
    cubes = [O.bodies.append(ddaBlock(box((1.002 * k, 0, 0), (1.002 * k + 1, 1, 1)), material=rock))
             for k in range(6)]
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.002, contactDistance=0.005)]
    for _ in range(20):
        O.step()
        s = yade_dda.stats()
        assert s['contactPairs'] == len(cubes) - 1 and s['closedContacts'] == 0
        assert s['components'] == len(cubes) and s['largestComponent'] == 1
        assert s['systemStructures'] == 1
    t = O.time
    for k, c in enumerate(cubes):
        x = yade_dda.block(c).centroid
        assert abs(x[2] - (0.5 - 0.5 * G * t * t)) < 1e-12
        assert abs(x[0] - (1.002 * k + 0.5)) < 1e-12


def test_a_contact_closing_in_the_iteration_joins_the_system(scene):
    """Two cubes 1 mm apart moving toward each other at 2 m/s each, no
    gravity: the contact opens the step as open, the first solve closes it,
    the structure is rebuilt with the two cubes in one system, and the
    collision conserves momentum exactly (equal and opposite contact
    forces)."""
    rock = material(O, young=1e9)
    a = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock))
    b = O.bodies.append(ddaBlock(box((1.001, 0, 0), (2.001, 1, 1)), material=rock))
    O.bodies[a].state.vel = (2.0, 0, 0)
    O.bodies[b].state.vel = (-2.0, 0, 0)
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=0.004, contactDistance=0.01)]
    rebuilt = joined = False
    for _ in range(40):
        O.step()
        s = yade_dda.stats()
        rebuilt |= s['systemStructures'] >= 2
        joined |= s['closedContacts'] > 0 and s['largestComponent'] == 2 and s['components'] == 1
        va, vb = yade_dda.block(a).velocity, yade_dda.block(b).velocity
        assert abs(va[0] + vb[0]) < 1e-9 and all(math.isfinite(v) for v in va)
    assert rebuilt and joined
    # The cubes bounced: they move apart at the end.
    assert yade_dda.block(a).velocity[0] < 0 < yade_dda.block(b).velocity[0]
