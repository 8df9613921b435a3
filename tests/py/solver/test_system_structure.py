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


def test_the_exported_system_gives_the_step_its_motion(scene):
    """yade_dda.coupledSystem() against the step it was taken from: two cubes
    stacked on a fixed floor, released 0.1 mm apart with no start from rest,
    so the contacts close and the stack compresses. At each step whose last
    solve was taken whole (no line search), the exported K is symmetric and
    positive definite, its rows are the two cubes joined by one link, and
    the dense solution of K D = F moves each cube's centroid by exactly what
    the step moved it (D's translation, to 1e-9 of the motion and the
    centroid's round-off, 1e-15 m)."""
    import numpy
    rock = material(O, young=1e9)
    floor = O.bodies.append(ddaBlock(box((-1, -1, -1), (2, 2, 0)), material=rock, fixed=True))
    lower = O.bodies.append(ddaBlock(box((0, 0, 1e-4), (1, 1, 1 + 1e-4)), material=rock))
    upper = O.bodies.append(ddaBlock(box((0, 0, 1 + 2e-4), (1, 1, 2 + 2e-4)), material=rock))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), startFromRest=False)]
    checked = 0
    for _ in range(30):
        before = {b: numpy.array(yade_dda.block(b).centroid) for b in (lower, upper)}
        O.step()
        s = yade_dda.stats()
        system = yade_dda.coupledSystem()
        if s['closedContacts'] == 0:
            assert len(system['bodies']) == 0
            continue
        if s['lineSearches'] > 0 or s['largestComponent'] != 2:
            continue
        assert sorted(system['bodies']) == [lower, upper] and list(system['sizes']) == [12, 12]
        assert system['links'].tolist() == [[0, 1]] and list(system['components']) == [0, 2]
        K = numpy.zeros((24, 24))
        for k, d in enumerate(system['diagonal']):
            K[12 * k:12 * k + 12, 12 * k:12 * k + 12] = d
        K[0:12, 12:24] = system['offDiagonal'][0]
        K[12:24, 0:12] = system['offDiagonal'][0].T
        assert numpy.array_equal(K, K.T)
        assert numpy.linalg.eigvalsh(K)[0] > 0
        D = numpy.linalg.solve(K, system['force'].ravel()).reshape(2, 12)
        for row, body in enumerate(system['bodies']):
            moved = numpy.array(yade_dda.block(body).centroid) - before[body]
            assert numpy.allclose(system['centroids'][row], before[body], rtol=0, atol=1e-12)
            assert numpy.abs(moved - D[row, :3]).max() <= 1e-9 * numpy.abs(moved).max() + 1e-15, (
                'step %d, body %d: moved %s, the exported system gives %s' % (O.iter, body, moved, D[row, :3]))
        checked += 1
    assert checked >= 10, 'only %d steps were checked' % checked
