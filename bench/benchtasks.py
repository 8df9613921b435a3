"""Child processes for the benchmarks: each measurement runs alone, one thread.

A bench script runs itself again as `script --worker TASKFILE`. The task is
a JSON dict; its 'result' entry names the file where the child writes what
its worker returns (JSON). bench/colliders.py and bench/accuracy.py share
this protocol.

The rock-mass and solver benches (bench/rock_mass_rest.py, rock_mass_scale.py,
solver.py, distributed_solve.py) run a child that prints its result as one
line `RESULT <json>` instead (printResult, resultOf); timedSteps is their
timed loop of steps.
"""
import json
import os
import subprocess
import sys
import time


def serveWorker(taskFile, worker):
    """The child's side: runs worker(task) on the task file and writes the result to task['result']."""
    with open(taskFile) as f:
        task = json.load(f)
    result = worker(task)
    with open(task['result'], 'w') as f:
        json.dump(result, f)


def runWorker(script, task, taskFile, timeout, captureStdout):
    """The parent's side: writes `task` to taskFile, runs `script --worker taskFile` with
    OMP_NUM_THREADS=1 (stderr captured; stdout captured or passed through), waits at most
    `timeout` [s] (subprocess.TimeoutExpired beyond), and returns (process, result), the
    result None when the child failed. The task and result files are removed once read."""
    with open(taskFile, 'w') as f:
        json.dump(task, f)
    env = dict(os.environ, OMP_NUM_THREADS='1')
    proc = subprocess.run([sys.executable, os.path.abspath(script), '--worker', taskFile], env=env,
                          stdout=subprocess.PIPE if captureStdout else None, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    if proc.returncode != 0 or not os.path.exists(task['result']):
        return proc, None
    with open(task['result']) as f:
        result = json.load(f)
    os.remove(task['result'])
    os.remove(taskFile)
    return proc, result


def printResult(result):
    """The child's side of the RESULT protocol: prints `result` (JSON) on one line."""
    print('RESULT ' + json.dumps(result), flush=True)


def resultOf(command, what, env=None):
    """The parent's side: runs `command`, returns the dict of its last RESULT line, and exits
    naming `what` with the tails of the child's output when it failed or printed none."""
    proc = subprocess.run(command, capture_output=True, text=True, env=env)
    lines = [line for line in proc.stdout.splitlines() if line.startswith('RESULT ')]
    if proc.returncode != 0 or not lines:
        raise SystemExit('%s failed:\n%s\n%s' % (what, proc.stdout[-2000:], proc.stderr[-3000:]))
    return json.loads(lines[-1][len('RESULT '):])


def timedSteps(steps):
    """Steps the current DDA scene `steps` times; the means a step [ms, solves] of what
    yade_dda.stats() reports, and the largest component and coarse aggregate count seen."""
    import yade_dda
    from yade_dda import O
    wall = narrow = assembly = solve = 0.0
    solves = iterations = iterated = aggregates = cuts = fallbacks = largest = 0
    for _ in range(steps):
        t = time.time()
        O.step()
        wall += time.time() - t
        s = yade_dda.stats()
        solves += s['openCloseIterationsTotal']
        iterations += s['iterativeIterations']
        iterated += s['iterativeComponents']
        fallbacks += s['iterativeFallbacks']
        largest = max(largest, s['largestComponent'])
        aggregates = max(aggregates, s['coarseAggregates'])
        cuts += s['stepCuts']
        narrow += s['time']['narrowPhase']
        assembly += s['time']['assembly']
        solve += s['time']['solve']
    return dict(msPerStep=1e3 * wall / steps, msNarrowPhase=1e3 * narrow / steps, msAssembly=1e3 * assembly / steps,
                msSolve=1e3 * solve / steps, msPerSolve=1e3 * solve / max(solves, 1), solvesPerStep=solves / steps,
                iterationsPerSolve=iterations / max(iterated, 1), iterativeFallbacks=fallbacks,
                largestComponent=largest, coarseAggregates=aggregates, stepCuts=cuts)
