"""Sweeps on a cluster (doc/guide/how-to.md, "Sweeps on a cluster"): `python3 -m yade_dda.tools.sweep` on Dask.

- The quick table (`python3 -m yade_dda.tools.sweep examples/regression/quick.table
  --workers 2 --out DIR`, a local cluster) passes check.py; the records and
  logs have yade-batch's file names, and each record says what the
  yade-batch run of the same row says (the session fixture `batch` of
  conftest.py, also checked by test_regression_batch.py): same parameters,
  same checks, bitwise the same measured values.
- A worker killed (SIGKILL, by the PID its scene reported in a marker file)
  while its row runs: the scene's YADE dies with it, Dask resubmits the row,
  its second attempt writes the one record, which passes check.py.
- In the same run a row whose scene raises is reported FAILED with the path
  and the last lines of its log (the exception), writes no record, and the
  command exits 1; the other rows' records are written. A row whose scene
  exits normally without writing a record is done, as yade-batch has it,
  and named in the summary; check.py fails it.
- An existing scheduler (`dask scheduler`, `dask worker` started apart, on
  the loopback): two rows of the quick table through its scheduler file.

About 11 s on the 2-core machine for the quick table, 5 s for the kill and
5 s for the existing scheduler (each YADE process starts in about 1 s; the
sweep's own process starts YADE once more, as it imports yade_dda; the
workers do not).
"""
import json
import os
import signal
import subprocess
import time

import pytest

import yade_dda

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
REGRESSION = os.path.join(ROOT, 'examples', 'regression')
CHECK = os.path.join(REGRESSION, 'check.py')
QUICK = os.path.join(REGRESSION, 'quick.table')
PYTHON = '/usr/bin/python3'
SWEEP = [PYTHON, '-m', 'yade_dda.tools.sweep']

# A scene for the kill and the failure: with a marker path, its first attempt writes the marker
# (its PID and its parent's, the worker's) and holds for holdSeconds; an attempt that finds the
# marker records itself as attempt 2 at once. fail=1 raises; record=0 exits normally without a record.
HOLD_SCENE = '''\
import os, time
from yade_dda.tools import regression
regression.readParamsFromTable(marker='', holdSeconds=0.0, fail=0, record=1)
from yade.params.table import *
if fail:
    raise RuntimeError('this row fails on purpose')
attempt = 1
if marker and os.path.exists(marker):
    attempt = 2
elif marker:
    with open(marker + '.tmp', 'w') as f:
        f.write('%d %d\\n' % (os.getpid(), os.getppid()))
    os.replace(marker + '.tmp', marker)
    time.sleep(holdSeconds)                       # the test kills the worker meanwhile
rec = regression.Record()
rec.closedForm('attempt', attempt, 2 if marker else 1, abs=0.5)   # the held attempt must never record
rec.measure('pid', os.getpid())
if record:
    rec.write()
'''
HOLD_TABLE = '''\
description  !SCRIPT  marker   holdSeconds  fail  record
killed-once  hold.py  '{marker}'  60        0     1
raises       hold.py  *        *            1     1
plain        hold.py  *        *            0     1
norecord     hold.py  *        *            0     0
'''


def scene_env():
    """The sweep and its scenes import the yade_dda this test imports (as in conftest.py's `batch`)."""
    env = dict(os.environ)
    package = os.path.dirname(os.path.dirname(os.path.abspath(yade_dda.__file__)))
    env['PYTHONPATH'] = package + os.pathsep + env.get('PYTHONPATH', '')
    env.pop('YADE_BATCH', None)
    return env


def run_check(table, records, *args):
    result = subprocess.run([PYTHON, CHECK, table, records] + list(args), capture_output=True, text=True, timeout=300)
    return result.returncode, result.stdout + result.stderr


def table_lines(table):
    """{description: line} of a table, as check.py reads it."""
    import importlib.util
    spec = importlib.util.spec_from_file_location('regression_check', CHECK)
    check = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(check)
    return {row['description']: line for line, row in check.readTable(table).items()}


def proc_state(pid):
    """(state letter, parent PID) of a process, or None when it is gone."""
    try:
        with open('/proc/%d/stat' % pid) as f:
            fields = f.read().rsplit(')', 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return fields[0], int(fields[1])


def alive(pid):
    state = proc_state(pid)
    return state is not None and state[0] not in 'ZX'


@pytest.fixture(scope='module')
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp('sweep') / 'quick'
    start = time.time()
    result = subprocess.run(SWEEP + [QUICK, '--workers', '2', '--out', str(out)], cwd=REGRESSION, env=scene_env(),
                            capture_output=True, text=True, timeout=900)
    return result, str(out), time.time() - start


def test_quick_table_passes_check(quick):
    result, out, wall = quick
    assert result.returncode == 0, result.stdout + result.stderr
    code, report = run_check(QUICK, out)
    assert code == 0, report
    lines = table_lines(QUICK)
    progress = result.stdout.splitlines()
    for description, line in lines.items():
        assert any(l.startswith('row %d %s: done, ' % (line, description)) for l in progress), result.stdout
    assert 'row %d %s: started on tcp://127.0.0.1:' % (lines['freefall-dt1e-2'], 'freefall-dt1e-2') in result.stdout
    assert '%d/%d done' % (len(lines), len(lines)) in result.stdout
    assert 'sweep: %d rows, %d done, 0 failed' % (len(lines), len(lines)) in result.stdout
    print('quick table through the sweep, 2 workers: %.1f s' % wall)


def test_records_and_logs_are_those_of_yade_batch(quick, batch):
    result, out, wall = quick
    table, batchRecords = batch
    names = sorted(os.listdir(out))
    for description in table_lines(QUICK):
        assert description + '.json' in names and description + '.log' in names
        assert os.path.exists(os.path.join(batchRecords, description + '.log'))
        with open(os.path.join(out, description + '.json')) as f:
            ours = json.load(f)
        with open(os.path.join(batchRecords, description + '.json')) as f:
            theirs = json.load(f)
        assert set(ours) == set(theirs)
        for key in ('format', 'description', 'script', 'params', 'checks', 'measured'):
            assert ours[key] == theirs[key], (description, key)
        assert ours['table'] == 'quick.table:%s' % theirs['table'].rsplit(':', 1)[1]     # the same row
        assert ours['run']['steps'] == theirs['run']['steps']
        assert ours['versions']['yade_dda_path'] == theirs['versions']['yade_dda_path']
    assert not [n for n in names if n.endswith('.tmp')]


# ---------------------------------------------------------------- a killed worker, a failing row

@pytest.fixture(scope='module')
def killed(tmp_path_factory):
    """Runs HOLD_TABLE on 2 workers, SIGKILLs the worker of the held row once its scene reported."""
    work = tmp_path_factory.mktemp('sweep-kill')
    marker = work / 'marker'
    (work / 'hold.py').write_text(HOLD_SCENE)
    (work / 'hold.table').write_text(HOLD_TABLE.format(marker=marker))
    out = work / 'out'
    with open(work / 'sweep.out', 'w') as log:
        proc = subprocess.Popen(SWEEP + [str(work / 'hold.table'), '--workers', '2', '--out', str(out)],
                                cwd=str(work), env=scene_env(), stdout=log, stderr=subprocess.STDOUT)
    scene = worker = None
    try:
        deadline = time.time() + 120
        while not marker.exists() and proc.poll() is None and time.time() < deadline:
            time.sleep(0.1)
        assert marker.exists(), 'the held row never started: %s' % (work / 'sweep.out').read_text()
        scene, worker = (int(s) for s in marker.read_text().split())
        workerParent = proc_state(worker)[1]
        os.kill(worker, signal.SIGKILL)        # a worker process of the sweep this test started
        deadline = time.time() + 15
        while alive(scene) and time.time() < deadline:
            time.sleep(0.1)
        sceneSurvived = alive(scene)
        code = proc.wait(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        if scene and alive(scene):
            os.kill(scene, signal.SIGKILL)     # the scene this test started, left behind by a failure
    return {'code': code, 'output': (work / 'sweep.out').read_text(), 'out': str(out),
            'table': str(work / 'hold.table'),
            'scene': scene, 'worker': worker, 'workerParent': workerParent, 'sweep': proc.pid,
            'sceneSurvived': sceneSurvived}


def test_a_row_whose_worker_dies_is_retried(killed):
    output = killed['output']
    assert killed['workerParent'] == killed['sweep'], 'killed %d, not a worker of the sweep' % killed['worker']
    assert not killed['sceneSurvived'], 'the scene of the killed worker still runs'
    line = table_lines(killed['table'])['killed-once']
    assert 'row %d killed-once: started on' % line in output
    assert 'attempt 2 (its worker was lost; Dask resubmitted it)' in output, output
    assert 'row %d killed-once: done, ' % line in output, output
    with open(os.path.join(killed['out'], 'killed-once.json')) as f:
        record = json.load(f)
    assert record['checks'][0]['measured'] == 2                  # the second attempt wrote it
    assert record['measured']['pid'] != killed['scene']
    with open(os.path.join(killed['out'], 'killed-once.log')) as f:
        assert 'attempt 2,' in f.read().splitlines()[-1]
    code, report = run_check(killed['table'], killed['out'], '--lines', '%d,%d' % (line, line + 2))
    assert code == 0, report
    assert not [n for n in os.listdir(killed['out']) if n.endswith('.tmp')]


def test_a_failing_row_is_reported_with_its_log(killed):
    output, out = killed['output'], killed['out']
    assert killed['code'] == 1, output
    line = table_lines(killed['table'])['raises']
    log = os.path.join(out, 'raises.log')
    assert 'FAILED row %d raises: YADE exited with status 1; log %s ends:' % (line, log) in output, output
    report = output[output.index('FAILED row %d raises' % line):]
    assert 'RuntimeError: this row fails on purpose' in report
    assert 'sweep: 4 rows, 3 done (1 wrote no record: norecord), 1 failed (raises)' in output
    assert os.path.exists(log) and not os.path.exists(os.path.join(out, 'raises.json'))
    assert os.path.exists(os.path.join(out, 'plain.json')) and os.path.exists(os.path.join(out, 'killed-once.json'))
    code, report = run_check(killed['table'], out)
    assert code == 1 and 'RuntimeError' in report           # check.py shows the end of the same log


def test_a_row_that_exits_normally_without_a_record_is_done(killed):
    """yade-batch's rule: a scene that exits normally is done; the sweep says it wrote no record (an
    ordinary scene, not written for check.py), and check.py, which needs the record, fails that row."""
    output, out = killed['output'], killed['out']
    line = table_lines(killed['table'])['norecord']
    assert 'row %d norecord: done (wrote no record), ' % line in output, output
    assert 'FAILED row %d' % line not in output
    assert os.path.exists(os.path.join(out, 'norecord.log')) and not os.path.exists(os.path.join(out, 'norecord.json'))
    code, report = run_check(killed['table'], out, '--lines', str(line))
    assert code == 1 and 'norecord' in report, report


# ---------------------------------------------------------------- an existing scheduler

def test_an_existing_scheduler_runs_the_rows(tmp_path):
    """`dask scheduler` and `dask worker` started apart (as srun would start them), on this machine's
    loopback; the workers' Python has no yade_dda on its path (tasks travel by value), the scenes get
    the sweep's through PYTHONPATH. The sweep reaches the scheduler through its scheduler file."""
    env = {k: v for k, v in os.environ.items() if k not in ('PYTHONPATH', 'YADE_DDA_BUILD')}
    schedulerFile = tmp_path / 'scheduler.json'
    started = []
    try:
        started.append(subprocess.Popen(['dask', 'scheduler', '--host', '127.0.0.1', '--port', '0', '--no-dashboard',
                                         '--scheduler-file', str(schedulerFile)], cwd=str(tmp_path), env=env,
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.time() + 60
        while not schedulerFile.exists() and time.time() < deadline:
            time.sleep(0.2)
        started.append(subprocess.Popen(['dask', 'worker', '--scheduler-file', str(schedulerFile), '--nthreads', '1',
                                         '--no-dashboard', '--local-directory', str(tmp_path)], cwd=str(tmp_path),
                                        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        lines = table_lines(QUICK)
        rows = '%d,%d' % (lines['freefall-dt1e-2'], lines['incline-a30-phi20'])
        out = tmp_path / 'out'
        result = subprocess.run(SWEEP + [QUICK, '--scheduler', str(schedulerFile), '--lines', rows, '--out', str(out)],
                                env=scene_env(), capture_output=True, text=True, timeout=300)
    finally:
        for proc in reversed(started):        # the scheduler and worker this test started
            proc.terminate()
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'sweep: scheduler %s, ' % schedulerFile in result.stdout      # not a local cluster
    code, report = run_check(QUICK, str(out), '--lines', rows)
    assert code == 0, report
    assert sorted(os.listdir(out)) == ['freefall-dt1e-2.json', 'freefall-dt1e-2.log',
                                       'incline-a30-phi20.json', 'incline-a30-phi20.log']
