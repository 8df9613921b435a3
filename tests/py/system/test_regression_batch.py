"""Batch regressions (doc/guide/how-to.md, "Batch regressions"): the quick table through yade-batch and check.py.

This is how CI runs the quick table. One yade-batch run (the fixture `batch` of
tests/py/system/conftest.py, shared with test_sweep.py) of
examples/regression/quick.table plus one row that crashes on purpose, with
the yade_dda this test imports (the build tree under YADE_DDA_BUILD, else the
installed package); then check.py on the records:

- the quick table passes;
- a perturbed stored reference (copied to a temporary directory) fails, and
  the checker names the scene;
- the crashed row fails (no record) instead of vanishing, and so does a
  deleted record; a record whose measured value was edited fails; a record
  from another parameter row is stale.

About 30 s on the 2-core machine (9 short scenes, two at a time; most of it
is YADE's start-up per scene). The table reader of check.py and the table
helper of yade_dda.tools.regression are checked against YADE's own without a
batch.
"""
import importlib.util
import json
import math
import os
import shutil
import subprocess

import pytest

import yade_dda
from yade_dda import O
from yade_dda.tools import regression
from yade import utils

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
REGRESSION = os.path.join(ROOT, 'examples', 'regression')
CHECK = os.path.join(REGRESSION, 'check.py')
QUICK = os.path.join(REGRESSION, 'quick.table')
FULL = os.path.join(REGRESSION, 'full.table')
PYTHON = '/usr/bin/python3'

_spec = importlib.util.spec_from_file_location('regression_check', CHECK)
check = importlib.util.module_from_spec(_spec)      # examples/regression/check.py, under its own name
_spec.loader.exec_module(check)


def run_check(table, records, *args):
    result = subprocess.run([PYTHON, CHECK, table, records] + list(args), capture_output=True, text=True, timeout=300)
    return result.returncode, result.stdout + result.stderr


def failed_scenes(output):
    line = [l for l in output.splitlines() if 'scenes failed:' in l][-1]
    names = line.split('scenes failed:')[1].split(';')[0].strip()
    return [] if names == 'none' else [n.strip() for n in names.split(',')]


def test_quick_table_passes(batch):
    table, records = batch
    code, out = run_check(QUICK, records)
    assert code == 0, out
    descriptions = [row['description'] for row in check.readTable(QUICK).values()]
    for name in descriptions:
        assert name + ' ' in out
    assert 'FAIL' not in out
    # the jobs ran the yade_dda this test imports
    with open(os.path.join(records, descriptions[0] + '.json')) as f:
        record = json.load(f)
    assert record['versions']['yade_dda_path'] == os.path.dirname(os.path.abspath(yade_dda.__file__))


def test_perturbed_reference_fails_and_names_the_scene(batch, tmp_path):
    table, records = batch
    references = tmp_path / 'references'
    shutil.copytree(os.path.join(REGRESSION, 'references'), references)
    path = references / 'tower-DESS.json'
    data = json.loads(path.read_text())
    data['values']['heights'][9] += 1e-5           # five times the tolerance (2e-6 m)
    path.write_text(json.dumps(data))
    code, out = run_check(QUICK, records, '--references', str(references))
    assert code == 1, out
    assert failed_scenes(out) == ['tower-DESS']
    assert any(l.startswith('tower-DESS') and 'heights' in l and l.rstrip().endswith('FAIL') for l in out.splitlines())


def test_crashed_scene_fails_instead_of_vanishing(batch):
    table, records = batch
    code, out = run_check(table, records)
    assert code == 1
    assert failed_scenes(out) == ['crash-on-purpose']
    assert 'no record' in out and 'ValueError' in out     # the end of its log is shown


def test_missing_record_fails(batch, tmp_path):
    table, records = batch
    copy = tmp_path / 'records'
    shutil.copytree(records, copy)
    os.remove(copy / 'wedge-fs0.7.json')
    code, out = run_check(QUICK, str(copy))
    assert code == 1
    assert failed_scenes(out) == ['wedge-fs0.7']


def test_edited_measurement_and_stale_record_fail(batch, tmp_path):
    table, records = batch
    copy = tmp_path / 'records'
    shutil.copytree(records, copy)
    path = copy / 'incline-a30-phi20.json'
    data = json.loads(path.read_text())
    data['checks'][0]['measured'] *= 1.02            # slide distance 2% off; tolerance 1%
    path.write_text(json.dumps(data))
    path = copy / 'resting-phi30.json'
    data = json.loads(path.read_text())
    data['params']['phiDeg'] = 45.0                  # a record of another row
    path.write_text(json.dumps(data))
    code, out = run_check(QUICK, str(copy))
    assert code == 1
    assert failed_scenes(out) == ['incline-a30-phi20', 'resting-phi30']
    assert 'stale record' in out


# ---------------------------------------------------------------- without a batch

@pytest.mark.parametrize('table', [QUICK, FULL], ids=['quick', 'full'])
def test_check_reads_tables_as_yade_does(table):
    ours = check.readTable(table)
    yades = utils.TableParamReader(table).paramDict()
    assert ours == yades
    descriptions = [row['description'] for row in ours.values()]
    assert len(set(descriptions)) == len(descriptions)
    for row in ours.values():
        assert os.path.exists(os.path.join(REGRESSION, row['!SCRIPT']))


def test_full_table_contains_the_quick_table():
    full = {row['description']: row for row in check.readTable(FULL).values()}
    for row in check.readTable(QUICK).values():
        assert full[row['description']] == row


def test_compare_uses_abs_plus_rel_tolerance():
    assert check.compare(1.0 + 0.9e-3, 1.0, 0.0, 1e-3)[0]
    assert not check.compare(1.0 + 1.1e-3, 1.0, 0.0, 1e-3)[0]
    assert check.compare([0.0, 2e-6], [0.0, 0.0], 3e-6, 0.0)[0]
    assert not check.compare([0.0, 4e-6], [0.0, 0.0], 3e-6, 0.0)[0]
    assert not check.compare([1.0], [1.0, 2.0], 1.0, 1.0)[0]          # shapes differ
    assert not check.compare(math.nan, 0.0, 1.0, 0.0)[0]


def test_table_helper_reads_star_and_refuses_values_it_does_not_take(scene, tmp_path):
    table = tmp_path / 't.table'
    table.write_text("description !SCRIPT a     name    other\n"
                     "one         s.py    *     'MSC'   *\n"
                     "two         s.py    2.5   *       7\n")
    regression.readParamsFromTable(tableFileLine='%s:2' % table, a=1.5, name='DESS')
    from yade.params import table as params
    assert (params.a, params.name, params.other) == (1.5, 'MSC', None)
    assert O.tags['description'] == 'one'
    O.reset()
    with pytest.raises(NameError, match='other'):
        regression.readParamsFromTable(tableFileLine='%s:3' % table, a=1.5, name='DESS')
