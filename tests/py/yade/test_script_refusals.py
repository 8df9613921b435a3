"""What a YADE script can get wrong around the DDA engines, refused by name.

Each refusal is checked twice: the exception names the problem, and nothing
changed (the engine's parameters and command, the scene's bodies, iteration
and DDA state are as before). The oracle for "nothing changed" in a scene is
its continuation: a scene that met a refused call goes on exactly, bitwise,
as the same scene that never met it.
"""
import hashlib
import os
import random

import pytest

import yade_dda
from yade import wrapper
from yade_dda import O
from yade_dda import params as _params
from yade_dda.hooks import USER_DT_TAG

from helpers import box, material


def _scene(steps=0):
    """Two blocks resting on a fixed floor, run `steps` steps."""
    rock = material(O, young=1e8, frictionDeg=30)
    O.bodies.append(yade_dda.ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0.001), (1, 1, 1.001)), material=rock))
    O.bodies.append(yade_dda.ddaBlock(box((-1.5, 0, 0.001), (-0.5, 1, 0.8)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
    if steps:
        O.run(steps, True)


def _fingerprint():
    """sha256 of O.iter, O.time and every block's corners and 12 rates (exact floats)."""
    digest = hashlib.sha256(('%d %s' % (O.iter, float(O.time).hex())).encode())
    for body in O.bodies:
        if yade_dda.blockOf(body.id) is None:
            continue
        block = yade_dda.block(body.id)
        for value in [c for v in block.vertices for c in v] + list(block.velocity):
            digest.update(float(value).hex().encode())
    return digest.hexdigest()


# ---- engine attributes

@pytest.mark.parametrize('make', [
    lambda: yade_dda.DDAIntegrator(dt=1e-3),
    lambda: yade_dda.DESSCollider(),
    lambda: yade_dda.MSCCollider(segments=4),
    lambda: yade_dda.Checkpoint(period=5),
], ids=['DDAIntegrator', 'DESSCollider', 'MSCCollider', 'Checkpoint'])
def test_a_misspelt_attribute_is_refused_after_construction(scene, make):
    engine = make()
    command = engine.command
    name = {'DDAIntegrator': 'gravty', 'MSCCollider': 'segmnts', 'Checkpoint': 'perod'}.get(type(engine).__name__,
                                                                                          'labl')
    with pytest.raises(AttributeError, match=r"has no parameter or attribute '%s'; did you mean" % name):
        setattr(engine, name, 1)
    assert engine.command == command and not hasattr(engine, name)
    engine.label = 'fine'     # YADE's own attributes stay settable
    assert engine.label == 'fine'


def test_a_parameter_set_after_construction_reaches_the_command(scene):
    dda = yade_dda.DDAIntegrator()
    dda.gravity = (0, 0, -1)
    assert "'gravity': (0.0, 0.0, -1.0)" in dda.command


@pytest.mark.parametrize('make', [lambda: yade_dda.DDAIntegrator(), lambda: yade_dda.DESSCollider()],
                         ids=['DDAIntegrator', 'DESSCollider'])
@pytest.mark.parametrize('name, value', [('iterPeriod', 2), ('iterPeriod', 0), ('virtPeriod', 1e-3),
                                         ('realPeriod', 1.0), ('nDo', 10)])
def test_an_engine_that_must_run_every_iteration_refuses_a_period(scene, make, name, value):
    engine = make()
    before = (engine.iterPeriod, engine.virtPeriod, engine.realPeriod, engine.nDo)
    with pytest.raises(ValueError, match='runs at every iteration: %s = ' % name):
        setattr(engine, name, value)
    assert (engine.iterPeriod, engine.virtPeriod, engine.realPeriod, engine.nDo) == before == (1, 0, 0, -1)


@pytest.mark.parametrize('name, value', [('iterPeriod', 2), ('iterPeriod', 0), ('virtPeriod', 1e-3),
                                         ('realPeriod', 1.0), ('nDo', 10)])
def test_a_period_given_to_the_integrator_says_it_runs_every_iteration(scene, name, value):
    """DDAIntegrator(iterPeriod=2) answered "did you mean syncPeriod?": a period given to the constructor
    gets the same refusal as one assigned later, with what to use instead."""
    with pytest.raises(ValueError, match='DDAIntegrator runs at every iteration: %s = ' % name) as error:
        yade_dda.DDAIntegrator(dt=1e-3, **{name: value})
    message = str(error.value)
    assert 'iterPeriod is fixed at 1' in message and 'syncPeriod' in message and 'dead = True' in message
    assert 'did you mean' not in message
    with pytest.raises(ValueError, match='DESSCollider runs at every iteration: iterPeriod = 2'):
        yade_dda.DESSCollider(iterPeriod=2)
    assert yade_dda.DDAIntegrator(iterPeriod=1).iterPeriod == 1   # what it is anyway


@pytest.mark.parametrize('make, match', [
    (lambda: yade_dda.DDAIntegrator(1e-3), r'DDAIntegrator takes keyword arguments only, as YADE\'s engines do: '
                                           r'got the positional argument 0.001; write DDAIntegrator\(dt=0.001, \.\.\.\)'),
    (lambda: yade_dda.DDAIntegrator(1e-3, (0, 0, -9.81)), r'got the positional arguments 0.001, \(0, 0, -9.81\); '
                                                          r'write DDAIntegrator\(dt=0.001, \.\.\.\)'),
    (lambda: yade_dda.DDAIntegrator('dda'), r"write DDAIntegrator\(label='dda', \.\.\.\)"),
    (lambda: yade_dda.MSCCollider(2.0), r'MSCCollider takes keyword arguments only.*MSCCollider\(criticalLength=2.0'),
    (lambda: yade_dda.DESSCollider(3), r'DESSCollider takes keyword arguments only.*its parameters: none but label'),
    (lambda: yade_dda.Checkpoint(100), r'Checkpoint takes keyword arguments only.*Checkpoint\(period=100'),
], ids=['dt', 'dt and gravity', 'label', 'MSCCollider', 'DESSCollider', 'Checkpoint'])
def test_a_positional_argument_is_refused_naming_the_keyword(scene, make, match):
    """DDAIntegrator(1e-3) said "label must be a string". YADE engines take keyword arguments only
    (PyRunner's positional ones are iterPeriod and command), so a positional one is a TypeError that
    says which keyword to write."""
    with pytest.raises(TypeError, match=match) as error:
        make()
    assert 'label must be a string' not in str(error.value)


def test_iteration_period_2_would_have_let_time_run_ahead(scene):
    """Why the period is refused: with YADE's own attribute forced to 2 past our check, O.time
    advances by O.dt at every iteration while the block moves at every other one (a free fall
    then lags the closed form of O.time). With period 1 it follows the closed form."""
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    dda = yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -10))
    O.engines = [dda]
    wrapper.PyRunner.__setattr__(dda, 'iterPeriod', 2)  # what the check stops a script from doing
    O.run(100, True)
    fall = 0.5 - O.bodies[0].state.pos[2]
    assert abs(fall - 5 * O.time ** 2) > 0.2 * 5 * O.time ** 2


def test_checkpoint_periods(scene):
    c = yade_dda.Checkpoint(period=7)
    with pytest.raises(ValueError, match='set period'):
        c.iterPeriod = 3
    assert c.iterPeriod == 7
    c.period = 9
    assert c.iterPeriod == 9
    c.realPeriod = 3600      # a checkpoint every hour of wall time too: YADE's own
    assert c.realPeriod == 3600


@pytest.mark.parametrize('params, error, message', [
    (dict(period=1.5), TypeError, 'period must be an integer, got 1.5'),
    (dict(period=float('inf')), TypeError, 'period must be an integer, got inf'),
    (dict(period=float('nan')), TypeError, 'period must be an integer, got nan'),
    (dict(keep=2.5), TypeError, 'keep must be an integer, got 2.5'),
    (dict(period=0), ValueError, r'period must be an integer in \[1, '),
])
def test_checkpoint_periods_are_whole_iterations(scene, params, error, message):
    with pytest.raises(error, match=message):
        yade_dda.Checkpoint(**params)


def test_threads_beyond_the_machine_are_refused(scene):
    dda = yade_dda.DDAIntegrator(threads=_params.PROCESSORS)
    command = dda.command
    with pytest.raises(ValueError, match=r'threads must be at most the %d processors of this machine \(0 = all\), '
                                         r'got %d' % (_params.PROCESSORS, _params.PROCESSORS + 1)):
        dda.threads = _params.PROCESSORS + 1
    with pytest.raises(ValueError, match='threads must be at most'):
        yade_dda.DDAIntegrator(threads=10 ** 6)
    assert dda.threads == _params.PROCESSORS and dda.command == command


# ---- Python's random

def test_ddablock_leaves_pythons_random_alone(scene):
    random.seed(1234)
    expected = [random.random() for _ in range(3)]
    random.seed(1234)
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    O.bodies.append(yade_dda.rigidBlock(box((2, 0, 0), (3, 1, 1)), material=material(O)))
    assert [random.random() for _ in range(3)] == expected


# ---- checkpoints and loads that find nothing

def test_latest_checkpoint_of_nothing_saved(scene, tmp_path):
    with pytest.raises(FileNotFoundError, match=r"no checkpoint checkpoint-<iteration><format> in .*\(nothing saved there yet\)"):
        yade_dda.latestCheckpoint(str(tmp_path))
    with pytest.raises(FileNotFoundError, match='the directory does not exist'):
        yade_dda.latestCheckpoint(str(tmp_path / 'missing'))
    assert yade_dda.latestCheckpoint(str(tmp_path), missingOk=True) is None


@pytest.mark.parametrize('argument, error, message', [
    (None, TypeError, 'O.load needs a file name, got None'),
    ('', TypeError, "O.load needs a file name, got ''"),
    ('/no/such/scene.yade.gz', FileNotFoundError, 'no such file; the running scene is unchanged'),
])
def test_a_load_of_no_file_changes_nothing(scene, argument, error, message):
    _scene(steps=20)
    before = _fingerprint()
    with pytest.raises(error, match=message):
        O.load(argument)
    assert _fingerprint() == before and len(O.bodies) == 3


def test_a_failed_load_puts_the_running_scene_back(scene, tmp_path):
    """A file YADE cannot read (YADE empties the scene when its load fails half-way): the scene
    is put back, and goes on bitwise as the same scene that never tried the load."""
    _scene(steps=30)
    O.run(20, True)
    expected = _fingerprint()

    O.reset()
    _scene(steps=30)
    junk = tmp_path / 'junk.yade'
    junk.write_bytes(b'not a YADE file')
    with pytest.raises(RuntimeError, match='the running scene was put back as it was'):
        O.load(str(junk))
    assert len(O.bodies) == 3 and O.iter == 30
    O.run(20, True)
    assert _fingerprint() == expected


@pytest.mark.parametrize('where, error, message', [
    ('missing-directory/scene.yade', FileNotFoundError, 'does not exist; nothing was saved'),
    ('readonly/scene.yade', PermissionError, 'not writable; nothing was saved'),
])
def test_a_save_that_cannot_be_written_raises(scene, tmp_path, where, error, message):
    if where.startswith('readonly') and os.geteuid() == 0:
        # root writes through a read-only mode bit: make the path a directory instead, which no one
        # can write as a file
        (tmp_path / 'readonly' / 'scene.yade').mkdir(parents=True)
        error, message = IsADirectoryError, 'is a directory; nothing was saved'
    else:
        (tmp_path / 'readonly').mkdir()
        os.chmod(tmp_path / 'readonly', 0o500)
    _scene(steps=5)
    before = _fingerprint()
    with pytest.raises(error, match=message):
        O.save(str(tmp_path / where))
    assert _fingerprint() == before
    assert not os.path.isfile(tmp_path / where)


# ---- O.dt

def test_o_dt_set_by_the_script_is_the_largest_step(scene):
    """O.dt = 1e-5 before O.run: the steps are 1e-5 (not the engine's 1e-3), and the engine's dt
    says so; a time step that is no time step is refused and changes nothing."""
    _scene()
    O.dt = 1e-5
    O.run(10, True)
    assert O.time == pytest.approx(1e-4, rel=1e-12)
    assert O.engines[0].dt == 1e-5 and "'dt': 1e-05" in O.engines[0].command
    for bad in (0, -1e-3, float('nan'), float('inf')):
        with pytest.raises(ValueError, match=r'O.dt must be finite and in \(0, inf\)'):
            O.dt = bad
    assert O.dt == 1e-5 and O.tags[USER_DT_TAG] == ''


def test_o_dt_reaches_an_engine_back_from_a_file(scene, tmp_path):
    """After O.load the engine is YADE's plain PyRunner carrying our command: O.dt reaches it too."""
    _scene(steps=3)
    path = str(tmp_path / 's.yade.gz')
    O.save(path)
    O.load(path)
    O.dt = 2e-4
    O.run(5, True)
    assert "'dt': 0.0002" in O.engines[0].command
    assert O.dt <= 2e-4


# ---- progress of a long run

def _progressLines(capsys, steps, **params):
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), **params)]
    capsys.readouterr()
    O.run(steps, True)
    return [line for line in capsys.readouterr().out.splitlines() if line.startswith('yade_dda: iter')]


def test_progress_lines_report_rate_time_and_eta(scene, capsys):
    lines = _progressLines(capsys, 40, progressPeriod=1e-9)
    assert len(lines) >= 30, lines
    iterations = [int(line.split()[2].rstrip(',')) for line in lines]
    assert iterations == sorted(iterations) and iterations[-1] <= 40
    assert all('steps/s' in line and 'dt 0.001 s' in line and 'closed contacts' in line for line in lines)
    assert all('(O.stopAtIter 40)' in line for line in lines[:-1]), lines


def test_progress_is_off_in_batch_runs_and_when_asked(scene, capsys):
    """Under pytest stdout is no terminal, as in yade-batch: the default (-1) prints nothing; 0 is off."""
    assert _progressLines(capsys, 20) == []
    O.reset()
    assert _progressLines(capsys, 20, progressPeriod=0) == []


@pytest.mark.parametrize('how', ['run', 'step'])
def test_newton_without_dda_integrator_is_refused(how):
    """A NewtonIntegrator with no DDAIntegrator would move DDA blocks as plain polyhedra (the block fell
    under YADE's gravity): refused before YADE runs, nothing moved; with a mask bit the blocks do not
    have, YADE's own bodies run as before."""
    O.reset()
    rock = material(O)
    block = O.bodies.append(yade_dda.ddaBlock(box((0, 0, 1), (1, 1, 2)), material=rock, mask=2))
    O.engines = [wrapper.ForceResetter(), wrapper.InsertionSortCollider([wrapper.Bo1_Polyhedra_Aabb()]),
                 wrapper.NewtonIntegrator(gravity=(0, 0, -9.81))]
    O.dt = 1e-3
    with pytest.raises(RuntimeError, match='NewtonIntegrator would move DDA block body %d as a plain polyhedron'
                       % block):
        O.run(10, True) if how == 'run' else O.step()
    assert O.iter == 0 and O.bodies[block].state.pos[2] == 1.5
    O.engines[-1].mask = 1   # YADE's bodies only
    O.run(10, True) if how == 'run' else O.step()
    assert O.iter > 0 and O.bodies[block].state.pos[2] == 1.5
    O.reset()


OVERLAPPING_SCRIPT = '''
from yade_dda import *
O.bodies.append(ddaBlock([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]))
O.bodies.append(ddaBlock([(x, y, z) for x in (0.5, 1.5) for y in (0, 1) for z in (0, 1)]))
O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
O.run(3, True)
'''


@pytest.mark.parametrize('how', ['run', 'step', 'background'])
def test_a_steps_error_is_raised_as_itself(how):
    """A DDA step that raises (blocks entering 0.5 m deep into each other): O.run, O.step and O.wait
    raise that ValueError, not YADE's RuntimeError('PyRunner error ...') that quotes it, so a script
    catches it by its type; the scene is unchanged and runs on once the cause is gone."""
    O.reset()
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1))))
    extra = O.bodies.append(yade_dda.ddaBlock(box((0.5, 0, 0), (1.5, 1, 1))))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3)]
    with pytest.raises(ValueError, match=r'DDA blocks body 0 and body 1 overlap by 0.5 m'):
        if how == 'run':
            O.run(3, True)
        elif how == 'step':
            O.step()
        else:
            O.run(3)
            O.wait()
    assert O.iter == 0
    O.bodies.erase(extra)
    O.run(3, True)
    assert O.iter == 3
    O.reset()


def test_a_steps_error_in_a_script_ends_with_the_error(tmp_path):
    """Run by yade -x: the report ends with the step's own ValueError (YADE's report of the failed
    engine stays before it); it was 76 lines with the message six times, quoted inside 'PyRunner error'."""
    import subprocess
    script = tmp_path / 'overlap.py'
    script.write_text(OVERLAPPING_SCRIPT)
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(yade_dda.__file__)) + os.pathsep
               + os.environ.get('PYTHONPATH', ''))
    result = subprocess.run(['yade', '-n', '-x', str(script)], capture_output=True, text=True, timeout=120,
                            env=env, stdin=subprocess.DEVNULL)
    lines = [l for l in (result.stdout + result.stderr).splitlines() if l.strip()]
    assert result.returncode != 0
    assert lines[-1].startswith('ValueError: DDA blocks body 0 and body 1 overlap by 0.5 m'), lines[-5:]
    mentions = sum('overlap by 0.5 m' in l for l in lines)
    assert mentions <= 4 and len(lines) <= 50, (mentions, len(lines))
