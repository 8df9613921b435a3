"""Blocks moving alone inside YADE, checked against closed forms. Free fall under every member of
the time scheme is in solver/test_time_scheme.py."""
import math

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator

from helpers import box, material, rotate

G = 9.81


def run_until(t_end, dt):
    """Runs steps until O.time reaches t_end exactly (the last dt is trimmed)."""
    dda = O.engines[-1]
    while O.time < t_end - 1e-15:
        dda.dt = min(dt, t_end - O.time)
        O.step()
    dda.dt = dt


def test_time_follows_adaptive_step_and_free_fall_stays_exact(scene):
    # a tight displacement bound forces step cuts; O.time must follow the steps actually taken
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), velocity=(20.0, 0, 0)))
    O.engines = [DDAIntegrator(dt=0.01, gravity=(0, 0, -G), maxDisplacement=0.05, label='dda')]
    cuts = 0
    for _ in range(50):
        O.step()
        cuts += yade_dda.stats()['stepCuts']
        assert yade_dda.stats()['maxDisplacement'] <= 0.05
    assert cuts > 0
    t = O.time
    pos = O.bodies[body].state.pos
    assert abs(pos[0] - (0.5 + 20.0 * t)) < 1e-9 * 20 * t
    assert abs(pos[2] - (0.5 - G * t * t / 2)) < 1e-9 * max(1.0, G * t * t)


def test_spinning_block_keeps_volume_and_centroid_for_100_revolutions(scene):
    """One revolution per second about a general axis, 100 s, 100 steps per revolution.

    The spin (6.3 rad/s) stays below the block's lowest elastic frequency
    (about sqrt(E/rho)/L = 26 rad/s): a faster spin would tear a real block of
    this soft rock apart, and DDA, whose strain rates turn with the block,
    shows that as a growing strain.
    """
    pts = rotate(box((-0.5, -1.0, -1.5), (0.5, 1.0, 1.5)), (1, 2, 3), 0.4)
    pts = [(x + 10, y + 20, z + 30) for (x, y, z) in pts]
    omega = 2 * math.pi
    axis = (0.2, -0.7, 0.5)
    n = math.sqrt(sum(a * a for a in axis))
    w = tuple(omega * a / n for a in axis)
    body = O.bodies.append(ddaBlock(pts, material=material(O), angularVelocity=w))
    blk = yade_dda.block(body)
    V0 = blk.volume
    c0 = blk.centroid
    O.engines = [DDAIntegrator(dt=1e-2, maxDisplacement=10.0, label='dda')]
    O.run(10000, True)
    assert abs(O.time - 100.0) < 1e-9
    assert abs(blk.volume - V0) < 1e-9 * V0
    assert (blk.centroid - c0).norm() < 1e-9
    # independent of the core's own volume bookkeeping: volume from the current vertices
    verts, c = blk.vertices, blk.centroid
    V = sum((verts[f[0]] - c).dot((verts[f[k]] - c).cross(verts[f[k + 1]] - c)) / 6
            for f in blk.faces for k in range(1, len(f) - 1))
    assert abs(V - V0) < 1e-9 * V0
    # after exactly 100 revolutions every corner is back where it started
    # (each corner travels about 1.2 km; 1e-8 m is 1e-11 of that)
    assert max(math.dist(tuple(verts[i]), pts[i]) for i in range(len(pts))) < 1e-8


def test_elastic_block_settles_to_constant_strain_closed_form(scene):
    """A block whose base corners are held settles to the uniaxial-strain solution.

    With T(x) constant-strain, holding the four base corners forces ex = ey = 0
    and w(base) = 0, i.e. w0 = (h/2) ez. The potential
        Pi = V/2 (lambda + 2 mu) ez^2 + rho g V w0
    is stationary at ez = -rho g h / (2 (lambda + 2 mu)), with
    lambda + 2 mu = E (1 - nu) / ((1 + nu)(1 - 2 nu)) (the constrained modulus).
    """
    E, nu, rho, h = 4e6, 0.25, 2600.0, 2.0
    mat = material(O, young=E, poisson=nu, density=rho)
    corners = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, h)), material=mat, fixedPoints=corners))
    O.engines = [DDAIntegrator(dt=0.05, gravity=(0, 0, -G), velocityRatio=0.0, label='dda')]
    O.run(200, True)
    constrained = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    expected = -rho * G * h / (2 * constrained)
    ez = yade_dda.block(body).strain[2]
    assert abs(ez - expected) < 0.01 * abs(expected)
    # the stress carried by the block balances its weight on average: szz = constrained * ez
    szz = yade_dda.block(body).stress[2]
    assert abs(szz - (-rho * G * h / 2)) < 0.01 * rho * G * h / 2
    # and the YADE body shows the deformed vertices
    b = O.bodies[body]
    core = yade_dda.block(body).vertices
    for v in b.shape.v:
        shown = b.state.pos + b.state.ori * v
        assert min((shown - x).norm() for x in core) < 1e-12


def test_point_load_at_centroid_accelerates_block(scene):
    force = (0.0, 5200.0, 0.0)
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O, density=2600),
                                    loads=[((0.5, 0.5, 0.5), force)]))
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=1.0, label='dda')]
    O.run(500, True)
    t, m = O.time, 2600.0
    assert abs(O.bodies[body].state.pos[1] - (0.5 + force[1] / m * t * t / 2)) < 1e-9


def test_initial_stress_relaxes_to_free_state(scene):
    """A free block with initial stress sigma0 relaxes (static analysis) to zero
    stress with strain -C sigma0 (C the compliance): sxx = 1 kPa gives
    ex = sxx / E, ey = ez = -nu sxx / E, with the sign of a released compression."""
    E, nu, s = 4e6, 0.25, -1000.0
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O, young=E, poisson=nu),
                                    stress=(s, 0, 0, 0, 0, 0)))
    O.engines = [DDAIntegrator(dt=0.05, velocityRatio=0.0, label='dda')]
    O.run(300, True)
    blk = yade_dda.block(body)
    assert max(abs(x) for x in blk.stress) < 1e-6 * abs(s)
    assert abs(blk.strain[0] - (-s / E)) < 1e-6 * abs(s / E)
    assert abs(blk.strain[1] - (nu * s / E)) < 1e-6 * abs(s / E)


def test_results_do_not_depend_on_thread_count(scene):
    """1100 blocks (above the core's threading threshold of 1024) landing on a
    floor (and bouncing) beside their neighbours: contacts, the solve of 1100
    independent systems and the per-block loops all run threaded, and the
    result is bitwise the same."""
    def run(nthreads):
        O.reset()
        O.bodies.append(ddaBlock(box((-1, -1, -1), (70, 35, 0)), fixed=True))
        for i in range(1100):
            x, y = 1.001 * (i % 68), 2.0 * (i // 68)
            pts = rotate(box((x, y, 0.001), (x + 1, y + 1, 1.001)), (1, 1, 0), 1e-4 * (i % 7), about=(x + 0.5, y + 0.5, 0.5))
            O.bodies.append(ddaBlock(pts, velocity=(0.01 * (i % 3), 0, -0.1)))
        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), threads=nthreads, maxDisplacement=0.01,
                                   label='dda')]
        closed = 0
        for _ in range(30):
            O.run(1, True)
            closed = max(closed, yade_dda.stats()['closedContacts'])
        assert closed > 500 and yade_dda.stats()['components'] >= 1024
        return [tuple(v) for b in O.bodies for v in yade_dda.block(b).vertices]
    assert run(1) == run(2)
