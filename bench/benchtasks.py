"""Child processes for the benchmarks: each measurement runs alone, one thread.

A bench script runs itself again as `script --worker TASKFILE`. The task is
a JSON dict; its 'result' entry names the file where the child writes what
its worker returns (JSON). bench/colliders.py and bench/accuracy.py share
this protocol.
"""
import json
import os
import subprocess
import sys


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
