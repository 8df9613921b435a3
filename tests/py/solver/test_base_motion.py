"""Prescribed motion of fixed blocks (baseMotion): a block on a shaken incline against
Newmark's sliding block, a block carried by a moving floor, the energy account with the
boundary's work, determinism, save and load, and refused input.

Newmark's sliding block (Newmark 1965, Geotechnique 15(2)). A rigid block rests on a plane
inclined at alpha, friction angle phi (one coefficient: staticFrictionExcess=0). The base
accelerates horizontally by a(t) towards the uphill side (the scenes' direction (-1, 0, 0):
the slope dips towards +x). In the base's frame the block feels -m a(t) along that
direction, i.e. +m a(t) horizontally downhill. Per unit mass, with s the slip down the
slope relative to the base:
    along the slope:  s'' = g sin(alpha) + a cos(alpha) - T/m
    normal to it:     N/m = g cos(alpha) - a sin(alpha)
While the block slips downhill T = tan(phi) N, so
    s'' = (cos(alpha) + tan(phi) sin(alpha)) (a - a_y) = k (a - a_y),
    a_y = g (tan(phi) cos(alpha) - sin(alpha)) / (cos(alpha) + tan(phi) sin(alpha)) = g tan(phi - alpha),
    k = cos(phi - alpha) / cos(phi).
The block sticks (s' = 0) until a(t) exceeds a_y, slips while s' > 0, and sticks again when
s' returns to 0. Uphill slip needs a base acceleration below -g tan(phi + alpha) and the block
stays down while a < g / tan(alpha); the scenes' peaks stay far inside both.

References: (1) for a(t) = A sin(w t) (A > a_y), each cycle slips from t1 = asin(a_y/A)/w to
the t2 where s' = 0 again, the root of (A/w)(cos w t1 - cos w t2) = a_y (t2 - t1), by
    s_cycle = k [(A/w) cos(w t1) (t2 - t1) - (A/w^2)(sin w t2 - sin w t1) - a_y (t2 - t1)^2 / 2]
(s' integrated twice; t2 by bisection: the closed form up to one scalar root), the same each
cycle when t2 < T + t1. (2) For any record, Newmark's equation integrated numerically
(trapezoidal rule at 1e-5 s on the record's piecewise linear acceleration, the same history
the base follows). The two agree on the sinusoid to 1e-4 (tested).
"""
import math
import random

import pytest

import yade_dda
from yade_dda import O, DDAIntegrator, rigidBlock, ddaBlock, baseMotion, baseMotionState, stats

import scenes as S
from helpers import box, material

G = 9.81
ALPHA = math.radians(20.0)
UPHILL = (-1.0, 0.0, 0.0)   # horizontal, towards the uphill side of a slope dipping towards +x
SEED = 20261208


def newmark_constants(phi, alpha=ALPHA):
    """(a_y [m/s^2], k [-]) of the module's derivation."""
    return G * math.tan(phi - alpha), math.cos(phi - alpha) / math.cos(phi)


def newmark_sine_slip(A, w, ay, k, cycles):
    """Slip [m] of `cycles` whole cycles of A sin(w t), from the closed form (module docstring)."""
    t1 = math.asin(ay / A) / w
    rest = lambda t: (A / w) * (math.cos(w * t1) - math.cos(w * t)) - ay * (t - t1)   # s'/k
    lo, hi = t1 + 1e-9, t1 + 2 * math.pi / w
    assert rest(lo) > 0 and rest(hi) < 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rest(mid) > 0 else (lo, mid)
    t2, d = 0.5 * (lo + hi), 0.5 * (lo + hi) - t1
    per = k * ((A / w) * math.cos(w * t1) * d - (A / w ** 2) * (math.sin(w * t2) - math.sin(w * t1)) - ay * d * d / 2)
    return cycles * per, t2


def newmark_numeric(accel, t_end, ay, k, h=1e-5):
    """Slip [m] by Newmark's equation, s'' = k (a - a_y) while slipping or a > a_y, s' >= 0
    (trapezoidal rule at step h [s])."""
    v = s = 0.0
    n = int(round(t_end / h))
    a0 = accel(0.0)
    for i in range(n):
        a1 = accel((i + 1) * h)
        if v > 0 or a0 > ay or a1 > ay:
            v1 = max(0.0, v + 0.5 * h * k * ((a0 - ay) + (a1 - ay)))
            s += 0.5 * h * (v + v1)
            v = v1
        a0 = a1
    return s


def linear(times, values):
    """The piecewise linear function through the rows (0 outside them), as the base follows it."""
    def f(t):
        if t < times[0] or t > times[-1]:
            return 0.0
        k = min(max(0, int((t - times[0]) / (times[1] - times[0]))), len(times) - 2)
        while times[k + 1] < t:
            k += 1
        while times[k] > t:
            k -= 1
        u = (t - times[k]) / (times[k + 1] - times[k])
        return values[k] + u * (values[k + 1] - values[k])
    return f


def shaken_incline(phiDeg, size=(1.0, 1.0, 0.4), rigid=True):
    """A fixed slab whose top is a plane dipping ALPHA towards +x, a block on it (rigid unless told);
    (slab, block, downhill)."""
    geo = S.incline_geometry(ALPHA, size, slab=((-3.0, -1.5, -1.0), (4.0, 1.5, 0.0)))
    rock = S.rock(phiDeg)
    slab = O.bodies.append(ddaBlock(geo['slab'], material=rock, fixed=True))
    block = O.bodies.append(ddaBlock(geo['block'], material=rock, rigid=rigid))
    return slab, block, geo['frame'][0]


def integrator(**kw):
    params = dict(dt=1e-3, gravity=(0, 0, -G), staticFrictionExcess=0.0, label='dda')
    params.update(kw)
    return DDAIntegrator(**params)


def run_to(t_end):
    """Runs until O.time reaches t_end [s] (O.run in batches of the steps left at the current dt:
    a single O.step costs a YADE round trip each)."""
    while O.time < t_end - 1e-12:
        dt = stats()['dt'] if O.iter else 1e-3
        O.run(max(1, int((t_end - O.time) / dt * 0.999)), True)


def slip_until(slab, block, downhill, t_end):
    """Runs to t_end [s]; returns the block's slip down the slope relative to the slab [m]
    (checking that the slab moved exactly as its motion says)."""
    b0, s0 = yade_dda.block(block).centroid, yade_dda.block(slab).centroid
    run_to(t_end)
    base = yade_dda.block(slab).centroid - s0
    assert (base - baseMotionState()['displacement']).norm() <= 1e-12 * max(1.0, base.norm())
    relative = yade_dda.block(block).centroid - b0 - base
    return sum(relative[i] * downhill[i] for i in range(3))


@pytest.mark.parametrize('rigid', [True, False], ids=['rigid', 'deformable'])
def test_sinusoid_slip_is_newmarks_closed_form(scene, rigid):
    """2 cycles of 0.5 g at 2 Hz, alpha 20 deg, phi 30 deg (a_y = 0.176 g): DDA's slip within
    2 % of the closed form, for a rigid block and a deformable one (E 1e10 Pa: its strain under
    the shaking is 1e-6); the numerical reference agrees with the closed form to 1e-4."""
    phi, A, w, cycles = math.radians(30.0), 0.5 * G, 4 * math.pi, 2
    ay, k = newmark_constants(phi)
    expected, t2 = newmark_sine_slip(A, w, ay, k, cycles)
    numeric = newmark_numeric(lambda t: A * math.sin(w * t), cycles * 2 * math.pi / w, ay, k)
    assert abs(numeric - expected) < 1e-4 * expected, (numeric, expected)
    slab, block, downhill = shaken_incline(30.0, rigid=rigid)
    baseMotion(slab, acceleration=lambda t: A * math.sin(w * t), direction=UPHILL, sampling=1e-3,
               duration=cycles * 2 * math.pi / w)
    O.engines = [integrator()]
    slip = slip_until(slab, block, downhill, cycles * 2 * math.pi / w)
    error = (slip - expected) / expected
    print('sinusoid (%s): slip %.6f m, Newmark %.6f m (t2 %.4f s), error %+.3f %%'
          % ('rigid' if rigid else 'deformable', slip, expected, t2, 100 * error))
    assert abs(error) < 0.02
    assert stats()['effects']['baseMotion'] is True and stats()['shakenBlocks'] == 1


def synthetic_record(path, seed, peak=0.5 * G, duration=2.0, interval=0.01):
    """A recorded-like accelerogram [m/s^2] every `interval` s: five sinusoids of 1 to 6 Hz
    with random phases under a sin(pi t / duration) envelope, scaled to `peak`, written as two
    columns (time [s], acceleration [m/s^2]) with a comment line; returns (times, values)."""
    rng = random.Random(seed)
    waves = [(rng.uniform(1.0, 6.0), rng.uniform(0, 2 * math.pi), rng.uniform(0.3, 1.0)) for _ in range(5)]
    times = [k * interval for k in range(int(round(duration / interval)) + 1)]
    raw = [math.sin(math.pi * t / duration) * sum(c * math.sin(2 * math.pi * f * t + p) for f, p, c in waves)
           for t in times]
    scale = peak / max(abs(a) for a in raw)
    values = [scale * a for a in raw]
    with open(path, 'w') as out:
        out.write('# synthetic accelerogram, seed %d: time [s], acceleration [m/s^2]\n' % seed)
        for t, a in zip(times, values):
            out.write('%.6f %.9e\n' % (t, a))
    return times, values


def test_recorded_accelerogram_slip_is_newmarks_integration(scene, tmp_path):
    """A seeded synthetic record (file, 0.5 g peak, 2 s): DDA's slip within 2 % of Newmark's
    equation integrated numerically on the same piecewise linear record."""
    print('seed', SEED)
    path = str(tmp_path / 'record.txt')
    times, values = synthetic_record(path, SEED)
    phi = math.radians(30.0)
    ay, k = newmark_constants(phi)
    assert max(values) > 2 * ay and -min(values) < G * math.tan(phi + ALPHA) / 2
    end = times[-1] + 0.3
    expected = newmark_numeric(linear(times, values), end, ay, k)
    slab, block, downhill = shaken_incline(30.0)
    baseMotion(slab, acceleration=tmp_path / 'record.txt', direction=UPHILL)   # a str or a path
    O.engines = [integrator()]
    slip = slip_until(slab, block, downhill, end)
    error = (slip - expected) / expected
    print('record: slip %.6f m, Newmark %.6f m, error %+.3f %%' % (slip, expected, 100 * error))
    assert expected > 0.01 and abs(error) < 0.02


def test_yield_acceleration_above_the_peak_no_slip(scene):
    """phi 40 deg (a_y = g tan 20 deg = 0.36 g) under 0.3 g at 2 Hz: the block rides the base.
    Tolerance 1e-6 m: the contact springs' elastic give under the peak inertial force, m A /
    (4 ks) = 1e-8 m for these stiffnesses (E 1e10 Pa, 0.4 m block), is a hundredth of it, and a
    slip of the order of the closed form at a_y just below the peak would be 1e-4 m and more."""
    A, w = 0.3 * G, 4 * math.pi
    assert A < newmark_constants(math.radians(40.0))[0]
    slab, block, downhill = shaken_incline(40.0)
    baseMotion(slab, acceleration=lambda t: A * math.sin(w * t), direction=UPHILL, sampling=1e-3, duration=1.0)
    O.engines = [integrator()]
    slip = slip_until(slab, block, downhill, 1.0)
    print('no slip: %.3e m' % slip)
    assert abs(slip) < 1e-6
    assert baseMotionState()['displacement'].norm() > 0.1   # the base moved


def test_block_on_a_floor_moved_at_constant_velocity(scene):
    """A floor set moving at 0.5 m/s at t = 0 (velocity table of one row) under a cube, phi 30 deg:
    friction accelerates the cube at g tan(phi) until it moves with the floor (t* = v / (g tan
    phi) = 0.088 s), after a slip of v^2 / (2 g tan phi) = 22.1 mm; then it rides the floor. The
    floor's displacement is v t to round-off (exact kinematics), its body follows."""
    v, phi = 0.5, math.radians(30.0)
    floor, cube = S.build_resting_block(frictionDeg=30.0)
    baseMotion(floor, velocity=[(0.0, v)])
    O.engines = [integrator(dt=2e-3)]
    c0, f0 = yade_dda.block(cube).centroid, yade_dda.block(floor).centroid
    run_to(0.5)
    moved = yade_dda.block(floor).centroid - f0
    assert abs(moved[0] - v * O.time) < 1e-12 and moved[1] == 0 and moved[2] == 0
    assert abs(O.bodies[floor].state.pos[0] - f0[0] - v * O.time) < 1e-9
    assert O.bodies[floor].state.vel[0] == v
    cubeMoved = yade_dda.block(cube).centroid - c0
    slip = moved[0] - cubeMoved[0]
    expected = v * v / (2 * G * math.tan(phi))
    print('carried: slip %.6f m, closed form %.6f m' % (slip, expected))
    assert abs(slip - expected) < 0.02 * expected
    assert abs(yade_dda.block(cube).velocity[0] - v) < 1e-3


def test_a_gentle_velocity_ramp_carries_the_block_without_slip(scene):
    """A floor ramped from rest to 0.5 m/s in 0.5 s (1 m/s^2, below g tan(phi) = 5.7 m/s^2):
    the cube moves with it, its displacement the floor's to the springs' give (1e-6 m)."""
    floor, cube = S.build_resting_block(frictionDeg=30.0)
    baseMotion(floor, velocity=[(0.0, 0.0), (0.5, 0.5)])
    O.engines = [integrator(dt=2e-3)]
    c0, f0 = yade_dda.block(cube).centroid, yade_dda.block(floor).centroid
    run_to(0.8)
    moved = yade_dda.block(floor).centroid - f0
    expected = 0.5 * 0.5 * 0.5 + 0.5 * (O.time - 0.5)     # v t^2 / (2 t_ramp), then v
    assert abs(moved[0] - expected) < 1e-12
    assert ((yade_dda.block(cube).centroid - c0) - moved).norm() < 1e-6


def energy_sum(e):
    return (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']
            - e['boundaryWork'] - e['contactChanges'])


@pytest.mark.parametrize('gamma', [1.0, 0.5], ids=['shi', 'average-acceleration'])
def test_energy_account_balances_with_the_boundary_work(scene, gamma):
    """One cycle of the sinusoid (the block slips, friction dissipates): kinetic + gravity +
    strain + contact + friction + damping - loads - boundaryWork - contactChanges stays
    constant to 1e-8 of the largest term's change, and the base did work."""
    A, w = 0.5 * G, 4 * math.pi
    slab, block, downhill = shaken_incline(30.0)
    baseMotion(slab, acceleration=lambda t: A * math.sin(w * t), direction=UPHILL, sampling=1e-3, duration=1.0)
    O.engines = [integrator(newmarkGamma=gamma, newmarkBeta=gamma / 2)]
    O.step()
    e0 = dict(stats()['energy'])
    worst, scale = 0.0, 0.0
    while O.time < 0.5:
        O.run(10, True)
        e = stats()['energy']
        scale = max(scale, max(abs(e[k] - e0[k]) for k in e))
        worst = max(worst, abs(energy_sum(e) - energy_sum(e0)))
    e = stats()['energy']
    print('gamma %g: residual %.3e J of %.3e J, boundary work %.3f J, friction %.3f J'
          % (gamma, worst, scale, e['boundaryWork'] - e0['boundaryWork'], e['friction'] - e0['friction']))
    assert e['friction'] - e0['friction'] > 1.0 and abs(e['boundaryWork'] - e0['boundaryWork']) > 1.0
    assert worst <= 1e-8 * scale


def shaken_cubes(threads):
    """256 rigid cubes on a shaken floor (enough pairs to thread the narrow phase), 40 steps; the
    cubes' centroids and velocities."""
    O.reset()
    rock = material(O, young=1e9, frictionDeg=25.0)
    floor = O.bodies.append(ddaBlock(box((-1, -1, -1), (17, 17, 0)), material=rock, fixed=True))
    cubes = [O.bodies.append(rigidBlock(box((i + 0.2, j + 0.2, 0), (i + 0.8, j + 0.8, 0.6)), material=rock))
             for i in range(16) for j in range(16)]
    baseMotion(floor, acceleration=[(0.0, (0.0, 0.0, 0.0)), (0.02, (4.0, 2.0, 0.5)), (0.2, (-4.0, 1.0, 0.0))])
    O.engines = [integrator(dt=2e-3, threads=threads)]
    O.run(40, True)
    return [(tuple(yade_dda.block(c).centroid), tuple(yade_dda.block(c).velocity)) for c in cubes]


def test_shaken_scene_is_bitwise_the_same_on_one_and_two_threads(scene):
    one, two = shaken_cubes(1), shaken_cubes(2)
    assert stats()['candidatePairs'] >= 256
    assert one == two


def test_save_and_load_keep_the_motion_bitwise(scene):
    """A shaken incline saved mid-run and loaded continues bitwise, the motion and its work kept."""
    A, w = 0.5 * G, 4 * math.pi
    slab, block, downhill = shaken_incline(30.0)
    baseMotion(slab, acceleration=lambda t: A * math.sin(w * t), direction=UPHILL, sampling=1e-3, duration=1.0)
    O.engines = [integrator()]
    O.run(100, True)
    O.saveTmp('shaken')
    O.run(100, True)
    first = (tuple(yade_dda.block(block).centroid), tuple(yade_dda.block(slab).centroid),
             stats()['energy']['boundaryWork'])
    O.loadTmp('shaken')
    O.run(100, True)
    second = (tuple(yade_dda.block(block).centroid), tuple(yade_dda.block(slab).centroid),
              stats()['energy']['boundaryWork'])
    assert first == second
    assert yade_dda.baseMotionRecord()['baseUx'] == baseMotionState()['displacement'][0]


def test_bad_input_is_refused_with_its_reason(scene, tmp_path):
    floor, cube = S.build_resting_block()
    bad = tmp_path / 'bad.txt'
    bad.write_text('0 1\n0.1 two\n')
    cases = [
        (dict(bodies=99, acceleration=[(0, 1), (1, 1)]), ValueError, 'body 99 is not a DDA block'),
        (dict(bodies=cube, acceleration=[(0, 1), (1, 1)]), ValueError, 'body %d is not fixed' % cube),
        (dict(bodies=floor), ValueError, 'exactly one of acceleration= or velocity='),
        (dict(bodies=floor, acceleration=[(0, 1)], velocity=[(0, 1)]), ValueError, 'exactly one'),
        (dict(bodies=floor, acceleration=[]), ValueError, 'table is empty'),
        (dict(bodies=floor, acceleration=[(0, 1), (1, float('nan'))]), ValueError, 'row 1 .* not finite'),
        (dict(bodies=floor, acceleration=[(0, 1), (1, 1), (1, 2)]), ValueError, 'increase strictly: row 2'),
        (dict(bodies=floor, acceleration=[(0, 1)]), ValueError, 'at least two rows'),
        (dict(bodies=floor, velocity=[(-1, 1)]), ValueError, 'first time must be >= 0'),
        (dict(bodies=floor, acceleration=str(tmp_path / 'missing.txt')), ValueError, 'cannot read the base motion'),
        (dict(bodies=floor, acceleration=str(bad)), ValueError, 'line 2: not numbers'),
        (dict(bodies=floor, acceleration=lambda t: t), ValueError, 'sampling= and duration='),
        (dict(bodies=floor, velocity=[(0, 1)], direction=(0, 0, 0)), ValueError, 'non-zero 3-vector'),
        (dict(bodies=floor, velocity=[(0, 'x')]), TypeError, 'must be a number or a 3-vector'),
        (dict(bodies=floor, velocity=[(0, 1)], start=float('inf')), ValueError, 'start must be finite'),
    ]
    for kw, error, message in cases:
        with pytest.raises(error, match=message):
            baseMotion(**kw)
    assert baseMotion(floor, velocity=[(0, 1.0)]) == 0
    with pytest.raises(ValueError, match='has a prescribed motion already'):
        baseMotion(floor, velocity=[(0, 1.0)])
    with pytest.raises(ValueError, match='no base motion 3'):
        baseMotionState(3)


@pytest.mark.parametrize('collider', ['MSCCollider', 'NBSCollider', 'AllPairsCollider'])
def test_every_collider_follows_the_moving_base(scene, collider):
    """Colliders only propose pairs: a cycle of the shaken incline ends bitwise where DESS's does
    (MSC rebuilds a shaken block's shells every step, not once as a fixed block's)."""
    def run(engine):
        O.reset()
        slab, block, downhill = shaken_incline(30.0)
        baseMotion(slab, acceleration=lambda t: 0.5 * G * math.sin(4 * math.pi * t), direction=UPHILL,
                   sampling=1e-3, duration=0.5)
        O.engines = ([getattr(yade_dda, engine)(label='collider')] if engine else []) + [integrator()]
        run_to(0.5)
        assert stats()['collider'] == (engine or 'DESSCollider').replace('Collider', '')
        return tuple(yade_dda.block(block).centroid), tuple(yade_dda.block(slab).centroid)
    assert run(collider) == run(None)


def test_a_shaken_slab_beside_a_still_flush_one(scene):
    """Two fixed slabs flush along x = 0, the right one moved along the seam at 0.2 m/s: its cube
    is carried (its speed 0.2 m/s after 0.5 s), the other cube stays put (1e-6 m), and the seam's
    faces, no longer flush, are found again without a hitch."""
    rock = S.rock(30.0)
    left = O.bodies.append(ddaBlock(box((-4, -2, -1), (0, 2, 0)), material=rock, fixed=True))
    right = O.bodies.append(ddaBlock(box((0, -2, -1), (4, 2, 0)), material=rock, fixed=True))
    still = O.bodies.append(ddaBlock(box((-3, -0.5, 0), (-2, 0.5, 1)), material=rock))
    carried = O.bodies.append(ddaBlock(box((2, -0.5, 0), (3, 0.5, 1)), material=rock))
    baseMotion(right, velocity=[(0.0, 0.0), (0.1, 0.2)], direction=(0, 1, 0))
    O.engines = [integrator(dt=2e-3)]
    s0, c0 = yade_dda.block(still).centroid, yade_dda.block(carried).centroid
    run_to(0.5)
    assert (yade_dda.block(still).centroid - s0).norm() < 1e-6
    assert abs(yade_dda.block(carried).velocity[1] - 0.2) < 1e-3
    assert yade_dda.block(carried).centroid[1] - c0[1] > 0.07
    assert stats()['shakenBlocks'] == 1 and yade_dda.block(left).centroid[1] == 0


def test_a_concave_base_moves_whole(scene):
    """A fixed L-shaped base (two parts) moved by a velocity ramp: both parts and the clump move
    by the same exact displacement, and a cube on it rides along."""
    rock = S.rock(30.0)
    parts = [box((-2, -2, -1), (2, 2, 0)), box((2, -2, -1), (3, 2, 1))]
    clump, members = O.bodies.appendClumped(yade_dda.concaveBlock(parts, material=rock, fixed=True))
    cube = O.bodies.append(ddaBlock(box((-1, -0.5, 0), (0, 0.5, 1)), material=rock))
    baseMotion(clump, velocity=[(0.0, 0.0), (0.5, 0.5)])
    O.engines = [integrator(dt=2e-3)]
    p0 = [yade_dda.block(m).centroid for m in members]
    c0 = yade_dda.block(cube).centroid
    run_to(0.6)
    expected = 0.5 * 0.5 * 0.5 + 0.5 * (O.time - 0.5)
    for m, p in zip(members, p0):
        assert abs((yade_dda.block(m).centroid - p)[0] - expected) < 1e-12
    assert stats()['shakenBlocks'] == 2
    assert abs((yade_dda.block(cube).centroid - c0)[0] - expected) < 1e-6


def test_a_shaken_blocks_corners_push_a_free_block(scene):
    """A fixed 0.5 m cube touching the face of a free 1 m cube (frictionless, no gravity): the shaken
    block's own corners carry the contact (it owns the vertices). Ramped to 0.5 m/s over 0.2 s, it
    pushes the cube along, the cube's displacement the pusher's to the springs' give (1e-5 m); at
    the ramp's end the springs let go and the cube runs ahead at the pusher's speed (to 0.1 %).
    The work the pusher did is the cube's kinetic energy plus what the scheme damped and the
    springs hold, to 1e-10."""
    rock = S.rock(0.0)
    pusher = O.bodies.append(ddaBlock(box((-0.5, -0.25, 0.25), (0, 0.25, 0.75)), material=rock, fixed=True))
    cube = O.bodies.append(ddaBlock(box((0, -0.5, 0), (1, 0.5, 1)), material=rock))
    baseMotion(pusher, velocity=[(0.0, 0.0), (0.2, 0.5)])
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    c0 = yade_dda.block(cube).centroid
    run_to(0.15)
    closed = [c for c in yade_dda.contacts() if c.state != 'open']
    assert len(closed) == 4 and all(c.id1 == pusher for c in closed)
    expected = 0.5 * 0.5 * O.time ** 2 / 0.2
    assert abs((yade_dda.block(cube).centroid - c0)[0] - expected) < 1e-5
    run_to(0.4)
    assert abs(yade_dda.block(cube).velocity[0] - 0.5) < 5e-4
    e = stats()['energy']
    print('pusher: work %.6f J, kinetic %.6f J, damping %.3e J' % (e['boundaryWork'], e['kinetic'], e['damping']))
    assert abs(e['boundaryWork'] - (e['kinetic'] + e['contact'] + e['damping'] - e['contactChanges'])) \
        < 1e-10 * e['boundaryWork']


# (slope alpha [deg], phi [deg], peak [g], frequency [Hz], cycles, direction: 'horizontal' or 'along')
SWEEP = [(10.0, 35.0, 0.5, 1.0, 1, 'horizontal'), (25.0, 35.0, 0.35, 3.0, 3, 'horizontal'),
         (15.0, 25.0, 0.6, 2.0, 2, 'along'), (30.0, 38.0, 0.25, 1.5, 2, 'along')]


@pytest.mark.parametrize('alphaDeg, phiDeg, peak, hz, cycles, direction', SWEEP,
                         ids=['%g-%g-%gg-%ghz-%s' % (a, p, g, f, d) for a, p, g, f, c, d in SWEEP])
def test_newmark_over_slopes_frequencies_and_directions(scene, alphaDeg, phiDeg, peak, hz, cycles, direction):
    """Newmark's closed form for the sinusoid over other slopes, friction angles, peaks and
    frequencies, horizontal and along-slope shaking, within 2 %. Along the slope (the base
    accelerating uphill along it by a(t)) the normal force is g cos(alpha) whatever a(t), so
    a_y = g (tan(phi) cos(alpha) - sin(alpha)) and k = 1 (the module's derivation with the
    direction's normal component 0)."""
    alpha, phi = math.radians(alphaDeg), math.radians(phiDeg)
    A, w = peak * G, 2 * math.pi * hz
    if direction == 'horizontal':
        (ay, k), along = newmark_constants(phi, alpha), UPHILL
    else:
        ay, k = G * (math.tan(phi) * math.cos(alpha) - math.sin(alpha)), 1.0
        along = (-math.cos(alpha), 0.0, math.sin(alpha))
    expected, _ = newmark_sine_slip(A, w, ay, k, cycles)
    geo = S.incline_geometry(alpha, (1.0, 1.0, 0.4), slab=((-3.0, -1.5, -1.0), (4.0, 1.5, 0.0)))
    rock = S.rock(phiDeg)
    slab = O.bodies.append(ddaBlock(geo['slab'], material=rock, fixed=True))
    block = O.bodies.append(rigidBlock(geo['block'], material=rock))
    baseMotion(slab, acceleration=lambda t: A * math.sin(w * t), direction=along, sampling=1e-3,
               duration=cycles / hz)
    O.engines = [integrator()]
    slip = slip_until(slab, block, geo['frame'][0], cycles / hz)
    error = (slip - expected) / expected
    print('alpha %g phi %g %g g %g Hz %s: slip %.6f m, Newmark %.6f m, error %+.3f %%'
          % (alphaDeg, phiDeg, peak, hz, direction, slip, expected, 100 * error))
    assert abs(error) < 0.02


@pytest.mark.slow
def test_a_shaken_rock_mass_keeps_its_account(scene):
    """A jointed 5 m cube (tests/py/rockmass_scenes.py, junctions, 247 blocks, 187 held) whose held
    blocks all shake at 0.3 g and 3 Hz: 60 steps, the account balanced to 1e-6 of its largest term
    (the rock-mass oracles' bound) and to 1e-5 of the largest change of a term (1.3e-7 measured),
    the work of the motion booked."""
    import rockmass_scenes as R
    ids, fixed, free = R.build_scene(R.JUNCTIONS_CASE, dt=1e-3)
    baseMotion(fixed, acceleration=lambda t: 0.3 * G * math.sin(6 * math.pi * t), direction=(1, 0.3, 0),
               sampling=1e-3, duration=1.0)
    O.run(1, True)
    e0 = dict(stats()['energy'])
    O.run(60, True)
    e = stats()['energy']
    magnitude = max(abs(v) for v in list(e.values()) + list(e0.values()))
    drift = energy_sum(e) - energy_sum(e0)
    print('rock mass: drift %.3e J, magnitude %.3e J, boundary work %.3f J' % (drift, magnitude, e['boundaryWork']))
    change = max(abs(e[k] - e0[k]) for k in e)
    assert e['boundaryWork'] > 1.0 and abs(drift) < 1e-6 * magnitude and abs(drift) < 1e-5 * change
