"""DDA blocks among YADE's own bodies, engines and tools."""
import math

import pytest

import yade_dda
from yade_dda import O, ddaBlock, DDAIntegrator
from yade import wrapper, utils

from helpers import box, material

G = 9.81


def test_sphere_left_to_yade_and_block_to_dda(scene):
    """Newton moves the sphere (mask 1), DDA the block (mask 2); neither touches the other."""
    sphere = O.bodies.append(utils.sphere((0, 0, 100), 0.5))
    block = O.bodies.append(ddaBlock(box((10, 0, 100), (11, 1, 101)), material=material(O), mask=2))
    O.engines = [
        wrapper.ForceResetter(),
        wrapper.InsertionSortCollider([wrapper.Bo1_Sphere_Aabb(), wrapper.Bo1_Polyhedra_Aabb()]),
        wrapper.InteractionLoop([], [], []),
        wrapper.NewtonIntegrator(gravity=(0, 0, -G), damping=0, mask=1),
        DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1.0, label='dda'),
    ]
    O.run(500, True)
    t = O.time
    # DDA's block: exact free fall
    assert abs(O.bodies[block].state.pos[2] - (100.5 - G * t * t / 2)) < 1e-9 * 100
    # YADE's sphere: its own leapfrog free fall, first order: within g t dt of the parabola
    dt = t / O.iter
    assert abs(O.bodies[sphere].state.pos[2] - (100 - G * t * t / 2)) <= G * t * dt
    assert O.bodies[sphere].state.pos[0] == 0 and abs(O.bodies[block].state.pos[0] - 10.5) < 1e-12


def test_newton_that_would_move_dda_blocks_is_refused(scene):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1))))
    O.engines = [wrapper.NewtonIntegrator(gravity=(0, 0, -G)), DDAIntegrator(dt=1e-3, label='dda')]
    with pytest.raises(RuntimeError) as error:
        O.step()
    assert 'NewtonIntegrator would also move DDA block body 0' in str(error.value)


def test_recorder_sees_core_state_when_it_runs(scene):
    """A PyRunner recorder reads O.bodies; automatic sync must have written the state by then."""
    body = O.bodies.append(ddaBlock(box((0, 0, 10), (1, 1, 11)), velocity=(0, 0, 3)))
    seen = []

    def record():
        seen.append((O.iter, O.bodies[body].state.pos[2], yade_dda.block(body).centroid[2]))
    import builtins
    builtins._ddaRecord = record
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1, label='dda'),
                 wrapper.PyRunner(command='_ddaRecord()', iterPeriod=7)]
    O.run(50, True)
    assert len(seen) >= 7
    for _, shown, core in seen:
        assert shown == core
    # between recorder calls the bodies are not rewritten: sync is not every step
    assert yade_dda.stats()['syncs'] < 50
    del builtins._ddaRecord


def test_run_syncs_once_at_its_end_and_a_single_step_leaves_bodies_current(scene):
    """O.run syncs the bodies once, when it ends (nothing read them before: an effect on
    demand), and leaves them current; so does a single O.step."""
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), velocity=(1, 2, 3)))
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=1, label='dda')]
    O.run(37, True)
    assert yade_dda.stats()['syncs'] == 1
    assert O.bodies[body].state.pos == yade_dda.block(body).centroid
    O.step()
    assert O.bodies[body].state.pos == yade_dda.block(body).centroid
    assert abs(O.bodies[body].state.pos[2] - (0.5 + 3 * O.time)) < 1e-12


def test_sync_period_writes_every_n_steps(scene):
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), velocity=(1, 0, 0)))
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=1, syncPeriod=1, label='dda')]
    O.run(20, True)
    assert yade_dda.stats()['syncs'] == 20


def test_state_set_on_the_body_before_the_first_step_is_used(scene):
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1))))
    O.bodies[body].state.vel = (2, 0, 0)
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=1, label='dda')]
    O.run(100, True)
    assert abs(O.bodies[body].state.pos[0] - (0.5 + 2 * O.time)) < 1e-12


def test_reset_starts_a_fresh_dda_scene(scene):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1))))
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    O.run(3, True)
    assert yade_dda.stats()['blocks'] == 1
    O.reset()
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1))))
    O.bodies.append(ddaBlock(box((2, 0, 0), (3, 1, 1))))
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    O.run(3, True)
    assert yade_dda.stats()['blocks'] == 2


def test_fixed_block_never_moves_and_costs_no_unknowns(scene):
    fixed = O.bodies.append(ddaBlock(box((0, 0, -1), (10, 10, 0)), fixed=True))
    free = O.bodies.append(ddaBlock(box((0, 0, 5), (1, 1, 6))))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1, label='dda')]
    O.run(100, True)
    s = yade_dda.stats()
    assert s['movingBlocks'] == 1 and s['unknowns'] == 12
    assert O.bodies[fixed].state.pos == yade_dda.block(fixed).centroid
    assert (O.bodies[fixed].state.pos - yade_dda._yade.yade.Vector3(5.0, 5.0, -0.5)).norm() < 1e-12 * 10
    assert O.bodies[free].state.pos[2] < 5.5


def test_stats_report_phases_and_sizes(scene):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1))))
    O.engines = [DDAIntegrator(dt=1e-3, label='dda')]
    O.run(2, True)
    s = yade_dda.stats()
    for key in ('dt', 'stepCuts', 'maxDisplacement', 'allowedDisplacement', 'blocks', 'unknowns', 'time'):
        assert key in s
    for phase in ('assembly', 'solve', 'update', 'core', 'sync'):
        assert s['time'][phase] >= 0
    assert s['dt'] == O.dt
    # the allowed displacement is ratio x half the scene size (0.01 x 0.5 m)
    assert abs(s['allowedDisplacement'] - 0.005) < 1e-15


def test_newton_added_or_changed_mid_run_is_checked_again(scene):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), mask=2))
    newton = wrapper.NewtonIntegrator(gravity=(0, 0, -G), mask=1)
    O.engines = [newton, DDAIntegrator(dt=1e-3, label='dda')]
    O.step()
    newton.mask = 3
    with pytest.raises(RuntimeError) as error:
        O.step()
    assert 'NewtonIntegrator would also move' in str(error.value)


def test_script_helpers_change_a_running_block(scene):
    body = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O, density=1000)))
    sphere = O.bodies.append(utils.sphere((5, 5, 5), 0.5))
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=1, label='dda')]
    O.run(10, True)
    assert yade_dda.blockOf(body) == 0 and yade_dda.blockOf(sphere) is None
    with pytest.raises(KeyError, match='not a DDA block'):
        yade_dda.block(sphere)
    yade_dda.setVelocity(body, (0, 0, 2))
    t0 = O.time
    O.run(100, True)
    assert abs(O.bodies[body].state.pos[2] - (0.5 + 2 * (O.time - t0))) < 1e-12
    # a 1 kN load at the centroid of the 1000 kg block: 1 m/s^2 from now on
    yade_dda.setVelocity(body, (0, 0, 0))
    z0, t0 = O.bodies[body].state.pos[2], O.time
    yade_dda.addPointLoad(body, O.bodies[body].state.pos, (0, 0, 1000))
    O.run(200, True)
    assert abs(O.bodies[body].state.pos[2] - (z0 + 0.5 * (O.time - t0) ** 2)) < 1e-12
    with pytest.raises(ValueError, match='finite'):
        yade_dda.addPointLoad(body, (0, 0, float('nan')), (0, 0, 1))
