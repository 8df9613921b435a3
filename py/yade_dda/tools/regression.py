"""Regression scenes for ``yade-batch``: read a table row, run, write a result record.

A regression scene is an ordinary YADE script (``examples/regression/*.py``)
run by ``yade-batch`` with a parameter table whose ``!SCRIPT`` column names
the script of each row::

    from yade_dda import *
    from yade_dda.tools import regression
    regression.readParamsFromTable(slope=30.0, phi=20.0, dt=1e-3, tEnd=1.0, collider='DESS')
    from yade.params.table import *
    ...                                       # build the scene, run it
    rec = regression.Record()
    rec.closedForm('slide', measured, expected, rel=0.01, formula='g (sin a - tan(phi) cos a) t^2 / 2')
    rec.reference('centroids', [list(c) for c in centroids], abs=1e-6)
    rec.write()

`readParamsFromTable` is YADE's ``yade.utils.readParamsFromTable`` with one
addition that lets scenes with different parameters share one table: a
column the scene does not take must hold ``*`` in its row (read: "not used
here"), and any other value there is an error naming the column. Outside
``yade-batch`` (``yade -n -x scene.py``) the defaults are used.

`Record.write` puts ``<description>.json`` (the table row's ``description``)
into the directory named by the environment variable ``YADE_DDA_RECORDS``,
or into the current directory when it is not set. The record holds the
parameters, each check (measured value, expected value or "compare with the
stored reference", tolerance), the run (steps, simulated and wall time) and
the versions; ``examples/regression/check.py`` decides pass or fail.

A check passes when ``|measured - expected| <= abs + rel |expected|`` for
every component (the reference's value is the expected one).
"""
import datetime
import hashlib
import json
import math
import os
import subprocess
import sys
import time
import warnings

from .._yade import O, utils

RECORDS_ENV = 'YADE_DDA_RECORDS'
"""The environment variable naming the directory records are written to (else the working directory)."""
FORMAT = 1
"""The version of a record's layout, written into every record as 'format'."""

_state = {'declared': None, 'table': None, 'start': None}


def readParamsFromTable(tableFileLine=None, noTableOk=True, **defaults):
    """YADE's ``utils.readParamsFromTable(**defaults)`` for a table shared by several scenes.

    `defaults` are the scene's parameters and their values outside a batch.
    Table columns the scene does not take must be ``*`` in its row; they are
    passed to YADE as ``None`` (so ``from yade.params.table import *`` also
    defines them, as ``None``) and left out of the record. Starts the wall
    clock of the record. Returns the number of parameters the row set.
    """
    _state['start'] = time.time()
    tableFileLine = tableFileLine or os.environ.get('YADE_BATCH') or None   # yade-batch sets 'table:line'
    _state['declared'] = sorted(defaults)
    _state['table'] = tableFileLine
    if not tableFileLine:
        return utils.readParamsFromTable(noTableOk=noTableOk, **defaults)
    tableFile, line = tableFileLine.rsplit(':', 1)
    rows = utils.TableParamReader(tableFile).paramDict()
    if int(line) not in rows:
        raise RuntimeError('table %s has no row on line %s' % (tableFile, line))
    row = rows[int(line)]
    starred = {}
    for column, value in row.items():
        if column == 'description' or column.startswith('!'):
            continue
        if column not in defaults and value != '*':
            raise NameError("%s line %s: column `%s' is %s, but this scene takes no parameter `%s' "
                            "(its parameters: %s); write * in columns a scene does not use"
                            % (tableFile, line, column, value, column, ', '.join(sorted(defaults))))
        if value == '*':
            starred[column] = defaults.get(column)
    # YADE 2023.02a's readParamsFromTable passes the default of a '*' cell to eval() (a TypeError for
    # a number, a NameError for a string such as 'DESS') and then stores the unevaluated default. So
    # '*' cells get their default's repr, which evaluates, and the true defaults are stored afterwards.
    params = dict(defaults)
    for column, value in starred.items():
        text = repr(value)
        try:
            same = eval(text, dict(math.__dict__)) == value
        except Exception:
            same = False
        if not same:
            raise TypeError("%s line %s: '*' in column `%s' needs a default that Python can write and read "
                            'back (a number, string, tuple...), got %r' % (tableFile, line, column, value))
        params[column] = text
    count = utils.readParamsFromTable(tableFileLine=tableFileLine, noTableOk=noTableOk, **params)
    if starred:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')      # "Overwriting yade.params.table which already exists"
            utils.saveVars('table', loadNow=True, **starred)
    return count


def _params():
    """The scene's own parameters (those given to readParamsFromTable) with their values in this run."""
    import yade.params.table as table
    return {name: getattr(table, name) for name in (_state['declared'] or [])}


def _scriptPath():
    """Path of the running scene: YADE runs `yade [options] script.py` with sys.argv[0] = the script."""
    script = sys.argv[0] if sys.argv and sys.argv[0].endswith('.py') else None
    return os.path.abspath(script) if script else None


def _description(script):
    description = O.tags['description'] if 'description' in O.tags.keys() else ''
    if description:
        return description
    return os.path.splitext(os.path.basename(script or 'scene'))[0]


def versions(script=None):
    """Versions worth keeping with a result: YADE, Python, the yade_dda module in use
    (path and a hash of its compiled core), and the git commit of the scene's source tree."""
    import yade
    from .. import _core
    yade_dda = sys.modules[__name__.split('.')[0]]   # the package (loaded before its modules), not imported again
    out = {'yade': str(yade.config.version), 'python': sys.version.split()[0],
           'yade_dda': getattr(yade_dda, '__version__', None),
           'yade_dda_path': os.path.dirname(os.path.abspath(yade_dda.__file__))}
    try:
        with open(_core.__file__, 'rb') as f:
            out['yade_dda_core_sha256'] = hashlib.sha256(f.read()).hexdigest()[:16]
    except OSError:
        out['yade_dda_core_sha256'] = None
    out['source_commit'] = None
    if script:
        try:
            out['source_commit'] = subprocess.run(
                ['git', '-C', os.path.dirname(script), 'describe', '--always', '--dirty'],
                capture_output=True, text=True, timeout=10).stdout.strip() or None
        except (OSError, subprocess.SubprocessError):
            pass
    return out


def _plain(value):
    """JSON-ready copy: YADE vectors and tuples become lists of floats."""
    if isinstance(value, (str, bool)) or value is None:
        return value
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    try:
        return [_plain(v) for v in value]
    except TypeError:
        return float(value)


def _components(value):
    if isinstance(value, (list, tuple)):
        return [c for v in value for c in _components(v)]
    return [value]


def _checkTolerance(name, abs, rel):
    if abs < 0 or rel < 0 or not (math.isfinite(abs) and math.isfinite(rel)) or abs + rel == 0:
        raise ValueError('check %s: give a tolerance abs >= 0 and/or rel >= 0, not both zero (got abs=%r, rel=%r)'
                         % (name, abs, rel))


class Record:
    """The result record of one regression run (one table row).

    `closedForm` and `reference` add checks; `measure` adds a value kept for
    information only; `write` writes the JSON file and returns its path.
    """

    def __init__(self, description=None):
        self.script = _scriptPath()
        self.description = description or _description(self.script)
        self.checks = []
        self.measured = {}

    def closedForm(self, name, measured, expected, abs=0.0, rel=0.0, formula='', unit=''):
        """Check `measured` against the closed form's `expected` (scalars or equal-shaped lists)."""
        _checkTolerance(name, abs, rel)
        self.checks.append(dict(name=name, kind='closedForm', measured=_plain(measured), expected=_plain(expected),
                                abs=abs, rel=rel, formula=formula, unit=unit))

    def reference(self, name, measured, abs=0.0, rel=0.0, unit='', note=''):
        """Check `measured` against the stored reference (examples/regression/references/<description>.json)."""
        _checkTolerance(name, abs, rel)
        self.checks.append(dict(name=name, kind='reference', measured=_plain(measured), abs=abs, rel=rel,
                                unit=unit, note=note))

    def measure(self, name, value):
        """Records `value` (a number, a vector or a list of them, SI units) under `name`, without a check."""
        self.measured[name] = _plain(value)

    def data(self):
        """The record as a dict: format, description, script, table, params, checks, measured, run (steps,
        simulated and wall time), versions and when it was written."""
        start = _state['start']
        return {
            'format': FORMAT,
            'description': self.description,
            'script': os.path.basename(self.script) if self.script else None,
            'table': _state['table'],
            'params': _plain(_params()),
            'checks': self.checks,
            'measured': self.measured,
            'run': {'steps': O.iter, 'simTime': O.time,
                    'wallTime': None if start is None else time.time() - start},
            'versions': versions(self.script),
            'written': datetime.datetime.now().isoformat(timespec='seconds'),
        }

    def write(self, directory=None):
        """Writes <description>.json into `directory` (default: $YADE_DDA_RECORDS, else the current directory)."""
        data = self.data()
        for check in self.checks:
            for v in _components(check['measured']) + _components(check.get('expected', 0.0)):
                if not isinstance(v, (int, float)):
                    raise TypeError('check %s: values must be numbers or lists of numbers, got %r' % (check['name'], v))
        directory = directory or os.environ.get(RECORDS_ENV) or os.getcwd()
        os.makedirs(directory, exist_ok=True)
        path = os.path.join(directory, self.description + '.json')
        with open(path + '.tmp', 'w') as f:
            json.dump(data, f, indent=1, allow_nan=True)
        os.replace(path + '.tmp', path)
        print('regression record written: %s (%d checks, %.2f s wall)' % (path, len(self.checks),
                                                                         data['run']['wallTime'] or 0.0))
        return path


def runTo(tEnd, budgetFactor=4):
    """Runs the current scene until O.time reaches tEnd [s]: whole steps of the
    integrator's dt, the last one trimmed to land on tEnd.

    A step that is cut (displacement or open-close control) makes O.time lag;
    the remaining time is then run step by step. Raises RuntimeError, with
    the time reached, when more than `budgetFactor` times the nominal number of
    steps would be needed (a collapsing time step is a failure of the scene).
    """
    dda = [e for e in O.engines if type(e).__name__ == 'DDAIntegrator']
    if len(dda) != 1:
        raise RuntimeError('runTo needs exactly one DDAIntegrator in O.engines')
    dda = dda[0]
    dt = dda.dt
    n = int(math.floor((tEnd - O.time) / dt + 1e-9)) - 1
    budget = budgetFactor * (max(n, 0) + 1) + 100
    if n > 0:
        O.run(n, True)
        budget -= n
    try:
        while O.time < tEnd - 1e-12 * max(1.0, tEnd):
            if budget <= 0:
                raise RuntimeError('time step collapsed: O.time = %.6g s of %.6g s after %d steps' % (O.time, tEnd, O.iter))
            dda.dt = min(dt, tEnd - O.time)
            O.step()
            budget -= 1
    finally:
        dda.dt = dt
