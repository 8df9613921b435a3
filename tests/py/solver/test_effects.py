"""Effects on demand, seen from a YADE script: ``stats()['effects']`` says what
the last step simulated; the counters show unused work is not done
(no friction terms without friction, no body force without gravity, no
broad-phase search of a resting pile), and each test checks the results did
not change (against the same scene with the work done, or a closed form). One
sync per ``O.run`` is tested with the YADE link, in
yade/test_yade_integration.py (test_run_syncs_once_at_its_end_and_a_single_step_leaves_bodies_current).
"""
import math

import yade_dda
from yade_dda import O, DDAIntegrator, ddaBlock, stats, contacts

from helpers import box, material, rotate

G = 9.81


def _cube_on_floor(frictionDeg, velocity=(0, 0, 0)):
    floor = material(O, young=1e8, frictionDeg=frictionDeg)
    O.bodies.append(ddaBlock(box((-5, -2, -1), (5, 2, 0)), material=floor, fixed=True))
    return O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=floor, velocity=velocity))


def test_frictionless_scene_assembles_no_friction_terms(scene):
    cube = _cube_on_floor(0.0, velocity=(1, 0, 0))
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), label='dda')]
    frictionTerms = normalTerms = 0
    for _ in range(50):
        O.step()
        s = stats()
        frictionTerms += s['frictionTerms']
        normalTerms += s['normalTerms']
        assert s['effects']['friction'] is False and s['effects']['gravity'] is True
    assert frictionTerms == 0 and normalTerms > 0
    # closed form: nothing resists sliding, the cube keeps 1 m/s
    assert abs(O.bodies[cube].state.vel[0] - 1.0) < 1e-6


def test_friction_is_reported_and_assembled(scene):
    cube = _cube_on_floor(20.0, velocity=(1, 0, 0))
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), label='dda')]
    frictionTerms = 0
    for _ in range(50):
        O.step()
        frictionTerms += stats()['frictionTerms']
    assert stats()['effects']['friction'] is True and frictionTerms > 0
    # sliding friction decelerates by g tan(phi) (closed form, within the first contact steps)
    expected = 1.0 - G * math.tan(math.radians(20)) * O.time
    assert abs(O.bodies[cube].state.vel[0] - expected) < 0.05


def test_no_gravity_no_body_force_and_static_analysis(scene):
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), velocity=(0.5, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-2, maxDisplacement=1, label='dda')]
    O.run(10, True)
    s = stats()
    assert s['bodyForceBlocks'] == 0
    assert s['effects'] == {'friction': False, 'gravity': False, 'static': False, 'bonds': False,
                            'fixedBlocks': 0, 'restingReuse': s['effects']['restingReuse'], 'rigidBlocks':
                            s.get('rigidBlocks', 0), 'baseMotion': False}
    assert abs(O.bodies[body].state.pos[0] - (0.5 + 0.5 * O.time)) < 1e-12   # x = x0 + v t
    # Shi's static analysis is velocityRatio=0: velocities do not carry over,
    # so the unloaded block stays where it is.
    O.engines = [DDAIntegrator(dt=1e-2, maxDisplacement=1, velocityRatio=0, label='dda')]
    before = O.bodies[body].state.pos
    O.run(5, True)
    assert stats()['effects']['static'] is True
    assert O.bodies[body].state.pos == before


def _pile(reuse):
    O.reset()
    rock = material(O, young=1e8, frictionDeg=30)
    O.bodies.append(ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    for k in range(8):
        x, y, z = -1.1 + 1.1 * (k % 2), -1.1 + 1.1 * ((k // 2) % 2), 0.02 + 1.1 * (k // 4)
        pts = rotate(box((x, y, z), (x + 1, y + 1, z + 1)), (0.3, 0.2, 1), 0.02 * (k - 4), about=(x + 0.5, y + 0.5, z))
        O.bodies.append(ddaBlock(pts, material=rock))
    O.engines = [DDAIntegrator(dt=2e-3, gravity=(0, 0, -G), reuseCandidatePairs=reuse, label='dda')]
    record, skipped = [], 0
    for _ in range(120):
        O.step()
        record.append([(c.id1, c.id2, c.kind, c.type, c.state, tuple(c.point), c.gap, c.normalForce)
                       for c in contacts()])
        skipped += stats()['broadPhaseSkipped']
    return record, skipped, stats()['effects']


def test_resting_pile_reuses_pairs_with_the_same_contacts(scene):
    cached, skipped, effects = _pile(True)
    searched, none, _ = _pile(False)
    assert none == 0
    assert skipped > 60               # most steps of a settling pile need no search
    assert effects['restingReuse'] is True and effects['fixedBlocks'] == 1
    for step, (a, b) in enumerate(zip(cached, searched)):
        assert a == b, 'contacts differ at step %d' % step
