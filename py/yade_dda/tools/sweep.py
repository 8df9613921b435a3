"""Sweeps on a cluster: every row of a yade-batch table as its own YADE process on Dask distributed.

    /usr/bin/python3 -m yade_dda.tools.sweep TABLE [--workers N | --scheduler ADDRESS] --out DIR
                                             [--lines 2,5-7] [--scenes DIR] [--retries N] [--timeout S]

Each row of TABLE (a yade-batch table: first line the column names, ``!SCRIPT``
the scene of each row, ``description`` the name of its record) runs as
``yade --threads=1 --nice=10 -x SCENE`` with ``YADE_BATCH=TABLE:LINE``, as
``yade-batch`` runs it, inside one task of Dask distributed: on a
``LocalCluster`` of N worker processes with one thread each (default), or on
the workers of an existing scheduler (``--scheduler tcp://host:8786``, or the
scheduler file of ``dask scheduler --scheduler-file``: a SLURM or Kubernetes
cluster, doc/guide/how-to.md, "Sweeps on a cluster").

The scene writes its record into a directory private to the task (the
worker's local directory); the task sends the record and the scene's output
back, and this process writes ``DIR/<description>.json`` and
``DIR/<description>.log`` -- the file names and the record of
``make regress-run``, so ``examples/regression/check.py TABLE DIR`` reads
them. Both are written atomically (a temporary file, then a rename): a row
that did not finish leaves nothing half written. Records and logs of the
rows about to run are deleted first, so a stale one cannot pass a check.

Scenes are found relative to ``--scenes`` (default: the table's directory),
which is also their working directory; with ``--scheduler`` the workers
need the table, the scenes, YADE and yade_dda at the same paths (a shared
file system, or the same image). The scenes import the yade_dda this process
imported (its directory is put first on their ``PYTHONPATH``).

Progress: a line when a row starts on a worker and one when it ends (row,
status, wall time [s], done/total). A row fails when YADE exits non-zero
without "Yade: normal exit." (yade-batch's rule; a scene that raises), when
it runs past ``--timeout`` [s], or when its worker died more often than Dask
allows; each failure is reported with the path and the last lines of its
log, and the command exits 1 (0 when every row passed). A row that exits
normally is done, as yade-batch has it, with or without a record: a scene
writes one only if it asks to (``yade_dda.tools.regression.Record``, which
writes ``<description>.json`` into ``$YADE_DDA_RECORDS``; doc/guide/how-to.md,
"Batch regressions"). Rows done without one are named in the summary, and
``examples/regression/check.py`` fails a row whose record is missing.

Retries are Dask's own: when a worker dies (killed, out of memory, node
lost) the scheduler resubmits the rows it was running to another worker, up
to ``distributed.scheduler.allowed-failures`` times per row (``--retries``
for the local cluster, default 3; an existing scheduler keeps its own
setting), then reports the row as failed (KilledWorker). A row started
again is reported as "attempt 2". The YADE process of a dead worker dies
with it: it is started through a guard that asks Linux to kill it when its
parent dies (prctl PR_SET_PDEATHSIG), and it writes only into the dead
task's private directory. A scene that fails is no worker death: its row is
not retried.
"""
import argparse
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
import uuid

TOPIC = 'yade-dda-sweep'
"""Dask event topic on which a task says that its row started."""

NO_RECORD = 'done (wrote no record)'
"""Status of a row that exited normally without a record (done, as yade-batch has it; check.py fails it)."""

LOG_LINES = 12
"""Lines of a failed row's log that are printed."""

_PACKAGE_PARENT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
"""The directory holding this file's yade_dda package (yade_dda/tools/sweep.py): first on the scenes' PYTHONPATH."""

# Run in a new process between the worker and YADE: asks the kernel to SIGKILL this process
# when the worker thread that started it ends (PR_SET_PDEATHSIG = 1), checks that the worker is
# still there (it could have died before the request), then becomes YADE (exec keeps the request).
_GUARD = ('import ctypes, os, signal, sys\n'
          'if ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL)) != 0:\n'
          '    sys.exit("yade-dda sweep guard: prctl(PR_SET_PDEATHSIG) failed")\n'
          'if os.getppid() != int(sys.argv[1]):\n'
          '    sys.exit("yade-dda sweep guard: the worker died before the scene started")\n'
          'os.execvp(sys.argv[2], sys.argv[2:])\n')


# ---------------------------------------------------------------- the table

def lineList(text):
    """yade-batch's --lines syntax: '2,5-7' -> [2, 5, 6, 7]."""
    out = []
    for part in text.split(','):
        if '-' in part:
            lo, hi = (int(s) for s in part.split('-'))
            out += list(range(lo, hi + 1))
        elif part.strip():
            out.append(int(part))
    return out


def readTable(table):
    """{line: {column: text}} of a yade-batch table, read by YADE's own reader (as yade-batch reads it)."""
    from .._yade import utils
    return utils.TableParamReader(table).paramDict()


def rowSpecs(table, lines=None, scenes=None, executable='yade', threads=1, nice=10, timeout=None):
    """What each task needs to run its row (plain data, sent to the workers), in table order."""
    table = os.path.abspath(table)
    scenes = os.path.abspath(scenes or os.path.dirname(table))
    rows = readTable(table)
    lines = sorted(rows) if lines is None else list(lines)
    unknown = [line for line in lines if line not in rows]
    if unknown:
        raise ValueError('table %s has no rows on lines %s' % (table, ', '.join(map(str, unknown))))
    descriptions = [rows[line]['description'] for line in lines]
    duplicates = sorted(set(d for d in descriptions if descriptions.count(d) > 1))
    if duplicates:
        raise ValueError('table %s: descriptions must be unique (they name records and logs): %s'
                         % (table, ', '.join(duplicates)))
    inside = os.path.commonpath([table, scenes]) == scenes
    tableName = os.path.relpath(table, scenes) if inside else table
    run = uuid.uuid4().hex[:12]         # names this sweep's tasks and events on a shared scheduler
    return [dict(_rowSpec(rows[line], line, table, tableName, scenes, executable, threads, nice, timeout), run=run)
            for line in lines]


def _rowSpec(row, line, table, tableName, scenes, executable, threads, nice, timeout):
    """yade-batch's reading of the !columns: !SCRIPT, !THREADS (or !OMP_NUM_THREADS), !EXEC;
    any other !NAME becomes the environment variable NAME."""
    script, env = None, {}
    for column, value in row.items():
        if column in ('!THREADS', '!OMP_NUM_THREADS'):
            threads = int(value)
        elif column == '!EXEC':
            executable = value
        elif column == '!SCRIPT':
            script = value
        elif column.startswith('!'):
            env[column[1:]] = value
    if not script:
        raise ValueError('%s line %d: no !SCRIPT column: the table must name the scene of each row' % (table, line))
    script = os.path.join(scenes, script)
    command = [executable, '--threads=%d' % threads] + (['--nice=%d' % nice] if nice is not None else []) + \
        ['-x', script]
    return {'line': line, 'description': row['description'], 'script': script, 'cwd': scenes,
            'batch': '%s:%d' % (tableName, line), 'command': command, 'env': env, 'timeout': timeout,
            'pythonpath': _PACKAGE_PARENT}


# ---------------------------------------------------------------- on a worker

def runRow(spec):
    """Dask task: runs one row's scene in a private directory; returns its record and log as text.

    Never raises for a scene that fails (that is the row's status, not a
    reason to retry); raises only when the row cannot start at all here.
    """
    from distributed import get_worker
    try:
        worker = get_worker()
    except ValueError:              # not in a worker (a direct call)
        worker = None
    where = worker.address if worker else 'local'
    if not os.path.isfile(spec['script']):
        raise FileNotFoundError('scene %s not found on %s (%s): workers need the scenes at the same path'
                                % (spec['script'], where, socket.gethostname()))
    if worker:
        worker.log_event(TOPIC, {'run': spec['run'], 'line': spec['line'], 'worker': where,
                                 'host': socket.gethostname(), 'pid': os.getpid()})
    parent = worker.local_directory if worker else None
    work = tempfile.mkdtemp(prefix='row%d-' % spec['line'], dir=parent)
    try:
        log = os.path.join(work, 'scene.log')
        start = time.time()
        code, timedOut = _runScene(spec, work, log)
        wall = time.time() - start
        logText = _readText(log) or ''
        record = _readText(os.path.join(work, spec['description'] + '.json'))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return {'line': spec['line'], 'description': spec['description'], 'exitStatus': code,
            'normalExit': 'Yade: normal exit.' in logText, 'timedOut': timedOut, 'wallTime': wall,
            'record': record, 'log': logText, 'worker': where, 'host': socket.gethostname()}


def _sceneEnv(spec, work):
    env = dict(os.environ)
    env.update(spec['env'])
    env['YADE_BATCH'] = spec['batch']
    env['YADE_DDA_RECORDS'] = work
    env['DISPLAY'] = ''
    env['PYTHONPATH'] = spec['pythonpath'] + (os.pathsep + env['PYTHONPATH'] if env.get('PYTHONPATH') else '')
    return env


def _runScene(spec, work, log):
    """Runs the scene through the guard; returns (exit status, timed out). On a timeout, or when
    this thread is interrupted, kills the scene's whole process group."""
    command = [sys.executable, '-c', _GUARD, str(os.getpid())] + spec['command']
    with open(log, 'w') as out:
        proc = subprocess.Popen(command, cwd=spec['cwd'], env=_sceneEnv(spec, work), stdin=subprocess.DEVNULL,
                                stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            return proc.wait(timeout=spec['timeout']), False
        except subprocess.TimeoutExpired:
            _killGroup(proc)
            return proc.returncode, True
        except BaseException:
            _killGroup(proc)
            raise


def _killGroup(proc):
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


def _readText(path):
    try:
        with open(path, errors='replace') as f:
            return f.read()
    except FileNotFoundError:
        return None


# ---------------------------------------------------------------- in this process

def writeAtomically(path, text):
    """Writes `text` to `path` through a temporary file in the same directory and a rename."""
    tmp = '%s.%d.tmp' % (path, os.getpid())
    with open(tmp, 'w') as f:
        f.write(text)
    os.replace(tmp, path)


def logTail(text, lines=LOG_LINES):
    """The last non-empty lines of a log, without the sweep's own '=====' lines."""
    kept = [l.rstrip() for l in text.splitlines() if l.strip() and not l.startswith('=====')]
    return kept[-lines:]


class Progress:
    """Counts attempts (from the tasks' start events) and prints one line per event."""

    def __init__(self, specs, stream):
        self.run = specs[0]['run'] if specs else None
        self.specs = {s['line']: s for s in specs}
        self.attempts = {s['line']: 0 for s in specs}
        self.done, self.total, self.stream = 0, len(specs), stream
        self.lock = threading.Lock()

    def say(self, text):
        with self.lock:
            print(text, file=self.stream, flush=True)

    def started(self, event):
        """Handler of the TOPIC events: (timestamp, {'run', 'line', 'worker', 'host', 'pid'}); events of
        another sweep on the same scheduler are not ours."""
        msg = event[1]
        if msg.get('run') != self.run:
            return
        with self.lock:
            self.attempts[msg['line']] += 1
            attempt = self.attempts[msg['line']]
        again = '' if attempt == 1 else ' (its worker was lost; Dask resubmitted it)'
        self.say('row %d %s: started on %s (%s), attempt %d%s'
                 % (msg['line'], self.specs[msg['line']]['description'], msg['worker'], msg['host'], attempt, again))

    def finished(self, line, status, wall):
        with self.lock:
            self.done += 1
            done = self.done
        self.say('row %d %s: %s, %s wall, %d/%d done'
                 % (line, self.specs[line]['description'], status, '-' if wall is None else '%.1f s' % wall,
                    done, self.total))


def _deleteOld(specs, out):
    for spec in specs:
        for ext in ('.json', '.log'):
            path = os.path.join(out, spec['description'] + ext)
            if os.path.exists(path):
                os.remove(path)


def _storeResult(result, attempt, out):
    """Writes the row's record and log; returns (status, problem or None)."""
    base = os.path.join(out, result['description'])
    footer = ('===== yade-dda sweep: row %d (%s), attempt %d, worker %s on %s, exit status %s, %.1f s wall\n'
              % (result['line'], result['description'], attempt, result['worker'], result['host'],
                 result['exitStatus'], result['wallTime']))
    writeAtomically(base + '.log', result['log'] + ('' if result['log'].endswith('\n') else '\n') + footer)
    if result['record'] is not None:
        writeAtomically(base + '.json', result['record'])
    if result['timedOut']:
        return 'FAILED', 'ran past the time limit and was killed'
    if result['exitStatus'] != 0 and not result['normalExit']:
        return 'FAILED', 'YADE exited with status %s' % result['exitStatus']
    if result['record'] is None:   # yade-batch's rule: a scene that exits normally is done
        return NO_RECORD, None
    return 'done', None


def _storeError(spec, error, attempts, out):
    """A row whose task raised (its worker died too often, or it could not start): a log that says so."""
    from distributed import KilledWorker
    if isinstance(error, KilledWorker):
        problem = ('its worker died %d times (each time the scene was killed with it); Dask gave up: %s'
                   % (attempts, error))
    else:
        problem = 'the task raised %s: %s' % (type(error).__name__, error)
    writeAtomically(os.path.join(out, spec['description'] + '.log'),
                    'yade-dda sweep: row %d (%s) failed: %s\n' % (spec['line'], spec['description'], problem))
    return problem


def _client(workers, scheduler, retries, stream):
    """(client, cluster or None): a LocalCluster of `workers` single-threaded processes, or `scheduler`."""
    import dask
    from distributed import Client, LocalCluster
    if scheduler:
        client = Client(scheduler_file=scheduler) if os.path.isfile(scheduler) else Client(scheduler)
        allowed = client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.allowed_failures)
        workers = len(client.scheduler_info()['workers'])
        print('sweep: scheduler %s, %d worker%s connected; Dask resubmits a row whose worker dies up to %d times '
              '(the scheduler\'s distributed.scheduler.allowed-failures)'
              % (scheduler, workers, '' if workers == 1 else 's', allowed), file=stream, flush=True)
        return client, None
    # One row at a time on each worker, the others queued on the scheduler (for tables of more than
    # twice as many rows as workers: Dask's root-task queuing), so a lost worker takes only its own row.
    with dask.config.set({'distributed.scheduler.allowed-failures': retries,
                          'distributed.scheduler.worker-saturation': 1.0}):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host='127.0.0.1',
                               dashboard_address=None)
    print('sweep: local cluster, %d worker processes of 1 thread; Dask resubmits a row whose worker dies '
          'up to %d times' % (workers, retries), file=stream, flush=True)
    return Client(cluster), cluster


class _LightWorkers:
    """While a local cluster lives: its worker processes do not import yade_dda (which boots YADE).

    The tasks are pickled by value (cloudpickle), so no worker needs this
    module. Under ``python3 -m yade_dda.tools.sweep``, multiprocessing's spawn would
    re-import the main module by its name, package first, in every worker
    (and in each one a nanny restarts); without ``__main__.__spec__`` it runs
    this file by its path instead, which imports only the standard library.
    """

    def __enter__(self):
        import cloudpickle
        module = sys.modules[__name__]
        if __name__ != '__main__' and __name__ not in cloudpickle.list_registry_pickle_by_value():
            cloudpickle.register_pickle_by_value(module)
        self.main = sys.modules['__main__']
        self.spec = getattr(self.main, '__spec__', None)
        if self.main is module:
            self.main.__spec__ = None
        return self

    def __exit__(self, *exc):
        if self.main is sys.modules[__name__]:
            self.main.__spec__ = self.spec


def _collect(client, specs, out, progress):
    """Submits every row, stores each result as it arrives; returns {line: problem} of the failed rows."""
    from distributed import as_completed
    futures = {client.submit(runRow, spec, key='yade-dda-row-%d-%s-%s' % (spec['line'], spec['description'],
                                                                          spec['run']), pure=False): spec
               for spec in specs}
    failed = {}
    for future in as_completed(list(futures)):
        spec = futures[future]
        try:
            result = future.result()
        except Exception as error:      # KilledWorker, or the row could not start
            failed[spec['line']] = _storeError(spec, error, progress.attempts[spec['line']], out)
            progress.finished(spec['line'], 'FAILED', None)
            continue
        status, problem = _storeResult(result, max(1, progress.attempts[spec['line']]), out)
        if problem:
            failed[spec['line']] = problem
        progress.finished(spec['line'], status, result['wallTime'])
    return failed


def _report(specs, failed, out, wall, stream):
    byLine = {s['line']: s for s in specs}
    for line in sorted(failed):
        path = os.path.join(out, byLine[line]['description'] + '.log')
        print('FAILED row %d %s: %s; log %s ends:' % (line, byLine[line]['description'], failed[line], path),
              file=stream)
        for text in logTail(_readText(path) or ''):
            print('      | ' + text, file=stream)
    bare = [spec['description'] for spec in specs if spec['line'] not in failed
            and not os.path.isfile(os.path.join(out, spec['description'] + '.json'))]
    print('sweep: %d rows, %d done%s, %d failed%s; %.1f s wall; records and logs in %s'
          % (len(specs), len(specs) - len(failed), ' (%d wrote no record: %s)' % (len(bare), ', '.join(bare))
             if bare else '', len(failed),
             ' (%s)' % ', '.join(byLine[l]['description'] for l in sorted(failed)) if failed else '', wall, out),
          file=stream, flush=True)


def run(table, out, workers=None, scheduler=None, lines=None, scenes=None, retries=3, timeout=None,
        executable='yade', threads=1, nice=10, stream=None):
    """Runs the rows of `table` (all, or `lines`) on Dask; writes records and logs into `out`.
    Returns the number of rows that failed."""
    specs = rowSpecs(table, lines, scenes, executable, threads, nice, timeout)
    return runRows(specs, out, workers, scheduler, retries, stream, table)


def runRows(specs, out, workers=None, scheduler=None, retries=3, stream=None, name='table'):
    """Runs the rows `specs` (from rowSpecs); returns the number of rows that failed."""
    stream = stream or sys.stdout
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    _deleteOld(specs, out)
    start = time.time()
    progress = Progress(specs, stream)
    with _LightWorkers():
        client, cluster = _client(workers or os.cpu_count() or 1, scheduler, retries, stream)
        try:
            client.subscribe_topic(TOPIC, progress.started)
            print('sweep: %s, %d rows; records and logs in %s' % (name, len(specs), out), file=stream, flush=True)
            failed = _collect(client, specs, out, progress)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    _report(specs, failed, out, time.time() - start, stream)
    return len(failed)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog='python3 -m yade_dda.tools.sweep', description=__doc__.split('\n\n')[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=textwrap.fill("A row is done when its scene exits normally (yade-batch's rule), failed when YADE exits non-zero, "
               "runs past --timeout or loses its worker too often. Records are optional: a scene that is to be "
               "checked writes one with yade_dda.tools.regression.Record(...).write(), into $YADE_DDA_RECORDS, "
               "which the sweep sets; rows done without one are named in the summary. examples/regression/check.py TABLE "
               "--out's DIR then compares the records with their closed forms and references.", 79))
    parser.add_argument('table', help='a yade-batch table with a !SCRIPT column')
    parser.add_argument('--out', required=True, help='directory of the records and logs (<description>.json, .log)')
    where = parser.add_mutually_exclusive_group()
    where.add_argument('--workers', type=int, default=None,
                       help='worker processes of the local cluster, one thread each (default: the cores, %d)'
                       % (os.cpu_count() or 1))
    where.add_argument('--scheduler', default=None, help='a running Dask scheduler: its address (tcp://host:8786) '
                       'or the file `dask scheduler --scheduler-file FILE` wrote')
    parser.add_argument('--lines', default=None, help="rows of the table to run, yade-batch's syntax (2,5-7)")
    parser.add_argument('--scenes', default=None, help="directory of the scenes named in !SCRIPT, and their "
                        "working directory (default: the table's directory)")
    parser.add_argument('--retries', type=int, default=3, help='local cluster: times a row is resubmitted when '
                        'its worker dies (distributed.scheduler.allowed-failures; default %(default)s)')
    parser.add_argument('--timeout', type=float, default=None, help='kill a row after this many seconds of wall '
                        'time and report it failed (default: none)')
    parser.add_argument('--yade', default='yade', help='YADE executable (default %(default)s; !EXEC overrides)')
    parser.add_argument('--nice', type=int, default=10, help='nice value of the scenes (default %(default)s)')
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 1:
        parser.error('--workers must be at least 1')
    try:
        lines = None if args.lines is None else lineList(args.lines)
        specs = rowSpecs(args.table, lines, args.scenes, args.yade, 1, args.nice, args.timeout)
    except ValueError as e:
        parser.error(str(e))
    try:
        failed = runRows(specs, args.out, args.workers, args.scheduler, args.retries, name=args.table)
    except KeyboardInterrupt:
        print('sweep: interrupted; rows not finished left no record', file=sys.stderr)
        return 130
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
