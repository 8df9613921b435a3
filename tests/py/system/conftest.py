"""Fixtures of the system tests shared by more than one file.

`batch`: one yade-batch run of examples/regression/quick.table plus a row that
crashes on purpose, for the whole session: test_regression_batch.py checks
it, test_sweep.py compares the records of `python3 -m yade_dda.tools.sweep`
with it. The jobs import the yade_dda this test process imports (the build tree
under YADE_DDA_BUILD, else the installed package).
"""
import os
import subprocess

import pytest

import yade_dda

REGRESSION = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))),
                          'examples', 'regression')
QUICK = os.path.join(REGRESSION, 'quick.table')
CRASH_ROW = "crash-on-purpose  incline.py  2e-3  0.5  'DESS'  45  50  *   # a toppling cube: the scene refuses it\n"


def scene_env(**extra):
    """The environment of a batch: YADE's scenes import the yade_dda this process imported."""
    env = dict(os.environ)
    package = os.path.dirname(os.path.dirname(os.path.abspath(yade_dda.__file__)))
    env['PYTHONPATH'] = package + os.pathsep + env.get('PYTHONPATH', '')
    env.pop('YADE_BATCH', None)
    env.update(extra)
    return env


@pytest.fixture(scope='session')
def batch(tmp_path_factory):
    """yade-batch on the quick table plus CRASH_ROW; returns (table with the crash row, records dir)."""
    work = tmp_path_factory.mktemp('regress')
    table = work / 'quick+crash.table'
    with open(QUICK) as f:
        table.write_text(f.read() + CRASH_ROW)
    records = work / 'records'
    records.mkdir()
    with open(work / 'yade-batch.log', 'w') as log:
        subprocess.run(['yade-batch', '-j', '2', '--disable-pynotify', '--log', str(records / '@.log'), str(table)],
                       cwd=REGRESSION, env=scene_env(YADE_DDA_RECORDS=str(records)), stdout=log,
                       stderr=subprocess.STDOUT, timeout=900)
    return str(table), str(records)
