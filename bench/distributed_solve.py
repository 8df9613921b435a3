"""Benchmark: a distributed (MPI) solve of the coupled system K D = F of a jointed rock mass (SI units: m, s, bytes).

A prototype of the iterative path on several processes, measured on a system
saved from a real step. The seeded confined mass of tests/py/rockmass_scenes.py
(a cube of the given edge cut by three oblique joint sets at about 1 m, the
blocks touching its sides or base held, E = 1e9 Pa) is released as cut
(startFromRest=False) and stepped twice at dt = 1e-3 s; the largest connected
component of the last solve's system (yade_dda.coupledSystem()) is saved.

The solve, on P MPI ranks (numpy, scipy and mpi4py; no YADE): the block rows
are split by recursive coordinate bisection of their centroids; each rank
holds its rows' 12x12 blocks as a scipy BSR matrix over [owned | ghost]
columns, exchanges the ghost rows' values with its neighbours (nonblocking
point-to-point) before every product, and sums dot products and infinity
norms by Allreduce. The method is the product's serial one: conjugate
gradients preconditioned by block Jacobi (12x12 diagonal blocks inverted),
from x = 0, stopping at a normwise backward error
|b - K x|_inf / (|K|_inf |x|_inf + |b|_inf) <= 1e-10 (the recurrence's
residual decides when to compute the true one). Rank 0 also solves the
assembled system directly (scipy's spsolve) as the reference.

Per side and process count: rows (blocks) and links of the system,
iterations, the backward error reached, the largest error against the
reference relative to its largest entry, setup time [ms] (partition, local
matrices, communication plan, preconditioner), the solve's time and its time
per iteration [ms] (median of --repeats solves; each figure the largest over
the ranks), the shares of it in the halo exchange and in Allreduce (wall
clock, the largest over the ranks; both include waiting for the slower
rank), the compute imbalance, each rank's CPU time over its wall time (below
1 when another process took its core: the times are then not the solve's),
ghost rows and halo bytes sent per iteration per rank, and the speed-up over
P = 1.

Writes bench/out/distributed_solve_<side>.npz (the saved systems) and
bench/out/distributed_solve.json, and prints a table.
Run: PYTHONPATH=<built package>/py /usr/bin/python3 bench/distributed_solve.py
[--sides 11,14] [--procs 1,2] [--repeats 15] (about a minute a side at 11 and
14 m, mostly the two steps; 21 m takes about 6 minutes: 3 to step, 1 for the
reference in each run). One part alone:
  ... distributed_solve.py --save FILE.npz --side 14        (needs YADE)
  mpirun -n 2 /usr/bin/python3 bench/distributed_solve.py --solve FILE.npz
"""
import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
# imported here, not at first use: its import would otherwise count as setup time
from scipy.sparse import bsr_matrix

import benchtasks  # bench/benchtasks.py: the RESULT protocol and the timed steps

HERE = os.path.dirname(os.path.abspath(__file__))
B = 12                  # unknowns per block row
RIGID = 6               # unknowns of a rigid block (its strain rows 6..11 are not unknowns)
TOLERANCE = 1e-10       # the product's iterativeTolerance
MAX_ITERATIONS = 2000   # the product's cap on conjugate-gradient iterations


# ---------------------------------------------------------------- --save (YADE)

def save_system(path, side, seed):
    """Steps the seeded mass twice and saves the largest component of its coupled system to `path`."""
    sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'py'))
    import yade_dda
    from yade_dda import O
    import rockmass_scenes as R
    case = R.draw_case(seed, kind='oblique', side=side)
    ids, _, free = R.build_scene(case, dt=1e-3, threads=1, startFromRest=False)
    O.step()
    O.step()
    s = yade_dda.coupledSystem()
    starts = s['components']
    c = int(np.argmax(np.diff(starts)))
    first, last = int(starts[c]), int(starts[c + 1])
    links = s['links']
    inside = (links[:, 0] >= first) & (links[:, 1] < last)   # lo < hi, so both ends in [first, last)
    np.savez(path, seed=seed, side=side, blocks=len(ids), free=len(free), description=R.describe(case),
             bodies=np.asarray(s['bodies'][first:last]), sizes=s['sizes'][first:last],
             centroids=s['centroids'][first:last], diagonal=s['diagonal'][first:last],
             links=links[inside] - first, offDiagonal=s['offDiagonal'][inside], force=s['force'][first:last])
    print('saved %s: %d rows, %d links (largest of %d components)' % (path, last - first, int(inside.sum()),
                                                                    len(starts) - 1))


# ---------------------------------------------------------------- the system, partition

def load_system(path):
    """The saved system as a dict, restricted for rigid blocks: their strain rows and columns
    become the identity's, uncoupled, with a zero right-hand side (as the product solves it)."""
    f = np.load(path)
    s = {k: f[k] for k in f.files}
    diagonal, off, force = s['diagonal'].copy(), s['offDiagonal'].copy(), s['force'].copy()
    rigid = s['sizes'] == RIGID
    diagonal[rigid, RIGID:, :] = 0.0
    diagonal[rigid, :, RIGID:] = 0.0
    diagonal[rigid, RIGID:, RIGID:] = np.eye(B - RIGID)
    off[rigid[s['links'][:, 0]], RIGID:, :] = 0.0
    off[rigid[s['links'][:, 1]], :, RIGID:] = 0.0
    force[rigid, RIGID:] = 0.0
    s.update(diagonal=diagonal, offDiagonal=off, force=force, rigid=rigid)
    return s


def bisect(centroids, rows, parts, first, owner):
    """Recursive coordinate bisection: `rows` to ranks first .. first+parts-1, halves by row count
    along the longest extent. Ties (equal coordinates) go by row number, so it is deterministic."""
    if parts == 1:
        owner[rows] = first
        return
    left = parts // 2
    points = centroids[rows]
    axis = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
    ordered = rows[np.lexsort((rows, points[:, axis]))]
    cut = len(rows) * left // parts
    bisect(centroids, ordered[:cut], left, first, owner)
    bisect(centroids, ordered[cut:], parts - left, first + left, owner)


def partition(centroids, parts):
    """The owning rank of each row."""
    owner = np.zeros(len(centroids), dtype=np.int64)
    bisect(centroids, np.arange(len(centroids)), parts, 0, owner)
    return owner


def directed_links(system):
    """Every off-diagonal block in both orientations: (row, column, link, transposed)."""
    lo, hi = system['links'][:, 0].astype(np.int64), system['links'][:, 1].astype(np.int64)
    index = np.arange(len(lo))
    return (np.concatenate([lo, hi]), np.concatenate([hi, lo]), np.concatenate([index, index]),
            np.concatenate([np.zeros(len(lo), bool), np.ones(len(lo), bool)]))


def block_matrix(rows, cols, blocks, shape_rows, shape_cols):
    """A BSR matrix of 12x12 blocks; each block row's blocks in ascending column order, which
    fixes the order of its product's sums."""
    order = np.lexsort((cols, rows))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=shape_rows))])
    return bsr_matrix((np.ascontiguousarray(blocks[order]), cols[order], indptr),
                      shape=(B * shape_rows, B * shape_cols))


def largest_row_sum(matrix, rigid):
    """|K|_inf over the block rows of a BSR `matrix` (a rigid block's strain rows left out, as
    the product's |K| does: they are not unknowns)."""
    absolute = bsr_matrix((np.abs(matrix.data), matrix.indices, matrix.indptr), shape=matrix.shape)
    sums = (absolute @ np.ones(matrix.shape[1])).reshape(-1, B)
    sums[rigid, RIGID:] = 0.0
    return float(sums.max(initial=0.0))


def global_matrix(system):
    """The assembled K (rank 0's reference)."""
    n = len(system['sizes'])
    rows, cols, link, transposed = directed_links(system)
    off = system['offDiagonal'][link]
    off[transposed] = off[transposed].transpose(0, 2, 1)
    diag = np.arange(n)
    return block_matrix(np.concatenate([diag, rows]), np.concatenate([diag, cols]),
                        np.concatenate([system['diagonal'], off]), n, n)


# ---------------------------------------------------------------- communication

class Halo:
    """The ghost rows' exchange: per neighbour rank, the owned rows it needs (sent) and the
    slice of the [owned | ghost] vector its rows fill (received). Times itself."""

    def __init__(self, comm, sends, receives):
        from mpi4py import MPI
        self.comm, self.sends, self.receives = comm, sends, receives
        self.wait_all = MPI.Request.Waitall
        self.buffers = [np.empty((len(rows), B)) for _, rows in sends]
        self.seconds, self.exchanges, self.bytes_sent = 0.0, 0, 0

    def exchange(self, extended):
        """Fills the ghost part of `extended` ([owned | ghost] rows, flat) from their owners."""
        t = time.perf_counter()
        requests = [self.comm.Irecv(extended[B * start:B * (start + count)], source=rank)
                    for rank, start, count in self.receives]
        by_row = extended.reshape(-1, B)
        for (rank, rows), buffer in zip(self.sends, self.buffers):
            np.take(by_row, rows, axis=0, out=buffer)
            requests.append(self.comm.Isend(buffer, dest=rank))
            self.bytes_sent += buffer.nbytes
        self.wait_all(requests)
        self.exchanges += 1
        self.seconds += time.perf_counter() - t


class Reduce:
    """Global sums and maxima by Allreduce, timed. OpenMPI's Allreduce combines the ranks'
    values in an order its algorithm fixes for a given process count: a sum has the same bits
    run after run with P ranks, but not the same as with another P (the results then agree
    to the solver's tolerance, not bitwise)."""

    def __init__(self, comm):
        from mpi4py import MPI
        self.comm, self.sum_op, self.max_op = comm, MPI.SUM, MPI.MAX
        self.seconds, self.calls = 0.0, 0

    def _all(self, values, op):
        t = time.perf_counter()
        out = np.empty_like(values)
        self.comm.Allreduce(values, out, op=op)
        self.calls += 1
        self.seconds += time.perf_counter() - t
        return out

    def sum(self, value):
        return float(self._all(np.array([value]), self.sum_op)[0])

    def max(self, *values):
        return tuple(float(v) for v in self._all(np.array(values, dtype=float), self.max_op))


# ---------------------------------------------------------------- the local system

def ghost_plan(comm, owner, columns):
    """The ghost rows among `columns` (sorted by owning rank, then row, so each neighbour's
    arrive in one slice); per rank q, the ghosts q owns (requested from q) and the owned rows
    q needs, learnt from q by one all-to-all of the request lists."""
    ghosts = np.unique(columns[owner[columns] != comm.rank])
    ghosts = ghosts[np.lexsort((ghosts, owner[ghosts]))]
    requests = [ghosts[owner[ghosts] == q] for q in range(comm.size)]
    return ghosts, requests, comm.alltoall(requests)


class LocalSystem:
    """One rank's part: its rows of K as a BSR matrix over [owned | ghost] columns, the halo
    that fills the ghosts, the preconditioner (its diagonal blocks' inverses, block-diagonal
    BSR) and |K|_inf. Vectors are flat: the owned rows' 12 values each, in ascending row order."""

    def __init__(self, comm, system, owner):
        self.timings = {}
        t = time.perf_counter()
        self.owned = np.flatnonzero(owner == comm.rank)
        rows, cols, link, transposed = directed_links(system)
        mine = owner[rows] == comm.rank
        rows, cols, link, transposed = rows[mine], cols[mine], link[mine], transposed[mine]
        self.ghosts, requests, needed = ghost_plan(comm, owner, cols)
        n = len(self.owned)
        local = np.full(len(owner), -1, dtype=np.int64)
        local[self.owned] = np.arange(n)
        local[self.ghosts] = n + np.arange(len(self.ghosts))
        starts = n + np.concatenate([[0], np.cumsum([len(r) for r in requests])])
        self.halo = Halo(comm, [(q, local[r]) for q, r in enumerate(needed) if len(r)],
                         [(q, int(starts[q]), len(r)) for q, r in enumerate(requests) if len(r)])
        self.reduce = Reduce(comm)
        self.product_seconds = 0.0
        self.timings['planMs'] = 1e3 * (time.perf_counter() - t)

        t = time.perf_counter()
        off = system['offDiagonal'][link]
        off[transposed] = off[transposed].transpose(0, 2, 1)
        diag = np.arange(n)
        self.matrix = block_matrix(np.concatenate([diag, local[rows]]), np.concatenate([diag, local[cols]]),
                                   np.concatenate([system['diagonal'][self.owned], off]), n, n + len(self.ghosts))
        self.size, self.extended_size = B * n, B * (n + len(self.ghosts))
        self.timings['localMatrixMs'] = 1e3 * (time.perf_counter() - t)

        t = time.perf_counter()
        self.preconditioner = block_matrix(diag, diag, block_inverses(system['diagonal'][self.owned]), n, n)
        self.timings['preconditionerMs'] = 1e3 * (time.perf_counter() - t)
        self.norm_k = self.reduce.max(largest_row_sum(self.matrix, system['rigid'][self.owned]))[0]

    def extended(self):
        """A zero [owned | ghost] vector; its first `size` entries are the owned part."""
        return np.zeros(self.extended_size)

    def reset_counters(self):
        self.halo.seconds = self.reduce.seconds = self.product_seconds = 0.0
        self.halo.exchanges = self.halo.bytes_sent = self.reduce.calls = 0

    def multiply(self, extended):
        """K x for the owned rows, x given as an [owned | ghost] vector whose ghosts this fills."""
        self.halo.exchange(extended)
        t = time.perf_counter()
        product = self.matrix @ extended
        self.product_seconds += time.perf_counter() - t
        return product

    def precondition(self, r):
        return self.preconditioner @ r

    def dot(self, a, b):
        # numpy's pairwise sum: an order fixed by the length alone
        return self.reduce.sum(np.sum(a * b))

    def largest(self, *vectors):
        """The infinity norms of the global vectors (owned parts given), in one Allreduce."""
        return self.reduce.max(*(float(np.abs(v).max(initial=0.0)) for v in vectors))


def block_inverses(diagonal):
    """The inverses of symmetric positive definite 12x12 blocks, by Cholesky (raises
    numpy.linalg.LinAlgError for a block that is not positive definite)."""
    lower_inverse = np.linalg.inv(np.linalg.cholesky(diagonal))
    return np.ascontiguousarray(lower_inverse.transpose(0, 2, 1) @ lower_inverse)


# ---------------------------------------------------------------- the solver

def conjugate_gradients(system, b, tolerance, max_iterations):
    """Block-Jacobi preconditioned CG from x = 0, the product's loop (BlockConjugateGradient):
    when the recurrence's residual meets the backward-error bound, the true residual decides,
    and the iteration goes on from it if it does not. Returns (x, iterations, backward error
    of the true residual, converged)."""
    x_extended, p_extended = system.extended(), system.extended()
    x, p = x_extended[:system.size], p_extended[:system.size]
    norm_b = system.largest(b)[0]

    def residual():
        r = b - system.multiply(x_extended)
        largest_r, largest_x = system.largest(r, x)
        scale = system.norm_k * largest_x + norm_b
        return r, (largest_r / scale if scale > 0 else 0.0)

    r, backward = residual()
    converged, iterations = backward <= tolerance, 0
    if not converged:
        z = system.precondition(r)
        p[:] = z
        rz = system.dot(r, z)
        while iterations < max_iterations:
            iterations += 1
            q = system.multiply(p_extended)
            pq = system.dot(p, q)
            if not (pq > 0 and math.isfinite(pq)):
                break
            alpha = rz / pq
            x += alpha * p
            r -= alpha * q
            largest_r, largest_x = system.largest(r, x)
            if largest_r <= tolerance * (system.norm_k * largest_x + norm_b):
                r, backward = residual()
                if backward <= tolerance:
                    converged = True
                    break
            z = system.precondition(r)
            rz_next = system.dot(r, z)
            beta, rz = rz_next / rz, rz_next
            p[:] = z + beta * p
        if not converged:
            r, backward = residual()
    return x.copy(), iterations, backward, converged


def timed_solves(comm, local, b, repeats):
    """Solves `repeats` times from x = 0. Returns the solution, iterations, backward error,
    whether it converged, whether every repeat gave the same bits, and per repeat a row of
    TIMED: this rank's seconds (wall clock) and counts."""
    from mpi4py import MPI
    per_repeat, solutions = [], []
    for _ in range(repeats):
        local.reset_counters()
        comm.Barrier()   # the ranks start together: the time is the solve's, not the previous repeat's skew
        wall, cpu = time.perf_counter(), time.process_time()
        x, iterations, backward, converged = conjugate_gradients(local, b, TOLERANCE, MAX_ITERATIONS)
        per_repeat.append((time.perf_counter() - wall, local.halo.seconds, local.reduce.seconds,
                           local.product_seconds, time.process_time() - cpu, local.halo.bytes_sent,
                           local.halo.exchanges, local.reduce.calls))
        solutions.append(x)
    same = all(np.array_equal(solutions[0], s) for s in solutions[1:])
    same = bool(comm.allreduce(same, op=MPI.LAND))
    return solutions[0], iterations, backward, converged, same, np.array(per_repeat)


TIMED = ('solve', 'halo', 'allreduce', 'product', 'cpu', 'bytesSent', 'exchanges', 'allreduces')


def backward_error(matrix, x, b, rigid):
    """|b - K x|_inf / (|K|_inf |x|_inf + |b|_inf) on the assembled K (rank 0's check)."""
    scale = largest_row_sum(matrix, rigid) * np.abs(x).max() + np.abs(b).max()
    return float(np.abs(b - matrix @ x).max() / scale) if scale > 0 else 0.0


# ---------------------------------------------------------------- --solve (under mpirun)

def solve_file(path, repeats):
    """Rank r's part of the distributed solve of the saved system; rank 0 prints RESULT."""
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    t = time.perf_counter()
    # every rank reads the whole file: a prototype's shortcut (the product would assemble its rows in place)
    system = load_system(path)
    load_ms = 1e3 * (time.perf_counter() - t)
    comm.Barrier()
    t = time.perf_counter()
    owner = partition(system['centroids'], comm.size)
    partition_ms = 1e3 * (time.perf_counter() - t)
    local = LocalSystem(comm, system, owner)
    comm.Barrier()   # setup ends when every rank is ready
    setup_ms = 1e3 * (time.perf_counter() - t)
    phases = {k: comm.allreduce(v, op=MPI.MAX) for k, v in dict(partitionMs=partition_ms, **local.timings).items()}
    x, iterations, backward, converged, same, per_repeat = timed_solves(
        comm, local, system['force'][local.owned].ravel(), repeats)
    slowest = np.empty((repeats, 3))
    comm.Allreduce(np.ascontiguousarray(per_repeat[:, :3]), slowest, op=MPI.MAX)
    median = int(np.argsort(slowest[:, 0], kind='stable')[repeats // 2])
    mine = dict(zip(TIMED, per_repeat[median]))
    rank = dict(rows=len(local.owned), ghostRows=len(local.ghosts), neighbours=len(local.halo.sends),
                haloBytesPerIteration=mine['bytesSent'] / max(iterations, 1),
                haloExchangesPerIteration=mine['exchanges'] / max(iterations, 1),
                allreducesPerIteration=mine['allreduces'] / max(iterations, 1),
                computeMs=1e3 * (mine['solve'] - mine['halo'] - mine['allreduce']),
                productShare=mine['product'] / mine['solve'],
                cpuPerWall=mine['cpu'] / mine['solve'])
    ranks = comm.gather(rank, root=0)
    pieces = comm.gather((local.owned, x.reshape(-1, B)), root=0)
    if comm.rank == 0:
        solve_s, halo_s, reduce_s = slowest[median]
        compute = [r['computeMs'] for r in ranks]
        result = dict(side=float(system['side']), seed=int(system['seed']), blocks=int(system['blocks']),
                      free=int(system['free']), rows=len(owner), links=len(system['links']), procs=comm.size,
                      cutLinks=int((owner[system['links'][:, 0]] != owner[system['links'][:, 1]]).sum()),
                      iterations=iterations, converged=converged, backwardError=backward, loadMs=load_ms,
                      setupMs=setup_ms, setupPhasesMs=phases, repeats=repeats, bitwiseRepeatable=same,
                      solveMs=1e3 * solve_s, msPerIteration=1e3 * solve_s / max(iterations, 1),
                      haloShare=halo_s / solve_s, allreduceShare=reduce_s / solve_s,
                      computeImbalance=max(compute) / float(np.mean(compute)), ranks=ranks)
        result.update(compare_with_reference(system, pieces))
        benchtasks.printResult(result)


def compare_with_reference(system, pieces):
    """The gathered solution against a direct solve of the assembled system."""
    from scipy.sparse.linalg import spsolve
    x = np.empty_like(system['force'])
    for rows, values in pieces:
        x[rows] = values
    x, b = x.ravel(), system['force'].ravel()
    matrix = global_matrix(system)
    t = time.perf_counter()
    # K is symmetric: a minimum-degree ordering of K + K^T fills in less than the default COLAMD
    reference = spsolve(matrix.tocsc(), b, permc_spec='MMD_AT_PLUS_A')
    reference_s = time.perf_counter() - t
    return dict(errorVsReference=float(np.abs(x - reference).max() / np.abs(reference).max()),
                backwardErrorAssembled=backward_error(matrix, x, b, system['rigid']),
                referenceBackwardError=backward_error(matrix, reference, b, system['rigid']),
                referenceSeconds=reference_s, solutionDigest=hashlib.sha256(x.tobytes()).hexdigest()[:16])


# ---------------------------------------------------------------- the default run

def mpi_solve(path, procs, repeats):
    """One `mpirun -n procs` of --solve: its RESULT dict."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1',
               OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
    command = ['mpirun', '-n', str(procs), '--oversubscribe'] + (['--allow-run-as-root'] if os.geteuid() == 0 else [])
    command += [sys.executable, os.path.abspath(__file__), '--solve', path, '--repeats', str(repeats)]
    return benchtasks.resultOf(command, ' '.join(command), env=env)


def run_side(side, seed, procs, repeats, out):
    """Saves the side's system (in its own process: YADE) and solves it on each process count."""
    path = os.path.join(out, 'distributed_solve_%g.npz' % side)
    proc = subprocess.run([sys.executable, os.path.abspath(__file__), '--save', path, '--side', str(side),
                           '--seed', str(seed)], capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit('saving side %g failed:\n%s' % (side, proc.stderr[-3000:]))
    rows = [mpi_solve(path, p, repeats) for p in procs]
    serial = [r for r in rows if r['procs'] == 1]
    for r in rows:
        r['speedup'] = serial[0]['solveMs'] / r['solveMs'] if serial else None
    return rows


# imbal: the largest rank's compute time (solve less halo and Allreduce) over the mean; cpu/wall: the
# smallest rank's CPU time over its wall time in the solve (below 1: the rank waited for a core)
HEADER = ('side', 'rows', 'links', 'P', 'iter', 'ms/iter', 'halo', 'allred', 'imbal', 'cpu/wall', 'setup ms',
          'ghosts', 'halo B/it', 'speed-up', 'error', 'backward')
HEADER_FORMAT = '%4s %6s %6s %2s %5s %8s %6s %6s %5s %8s %8s %6s %9s %8s %8s %8s'


def table_line(r):
    speedup = '%.2f' % r['speedup'] if r['speedup'] is not None else '-'
    return ('%4g %6d %6d %2d %5d %8.3f %5.1f%% %5.1f%% %5.2f %8.2f %8.1f %6d %9.0f %8s %8.1e %8.1e' % (
        r['side'], r['rows'], r['links'], r['procs'], r['iterations'], r['msPerIteration'], 100 * r['haloShare'],
        100 * r['allreduceShare'], r['computeImbalance'], min(k['cpuPerWall'] for k in r['ranks']), r['setupMs'],
        max(k['ghostRows'] for k in r['ranks']),
        max(k['haloBytesPerIteration'] for k in r['ranks']), speedup, r['errorVsReference'], r['backwardError']))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--sides', default='11,14', help='cube edges [m]')
    parser.add_argument('--procs', default='1,2', help='MPI process counts')
    parser.add_argument('--seed', type=int, default=1, help="the rock mass's seed")
    parser.add_argument('--repeats', type=int, default=15, help='solves timed per run (the median reported)')
    parser.add_argument('--save', metavar='FILE.npz', help='only save the system of --side (needs YADE)')
    parser.add_argument('--side', type=float, default=14.0, help='cube edge [m] for --save')
    parser.add_argument('--solve', metavar='FILE.npz', help='only solve a saved system (run under mpirun)')
    args = parser.parse_args()
    if args.save:
        save_system(args.save, args.side, args.seed)
        return
    if args.solve:
        solve_file(args.solve, args.repeats)
        return
    out = os.path.join(HERE, 'out')
    os.makedirs(out, exist_ok=True)
    print(HEADER_FORMAT % HEADER, flush=True)
    rows = []
    for side in [float(s) for s in args.sides.split(',')]:
        for r in run_side(side, args.seed, [int(p) for p in args.procs.split(',')], args.repeats, out):
            rows.append(r)
            print(table_line(r), flush=True)
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=HERE, capture_output=True,
                            text=True).stdout.strip()
    with open(os.path.join(out, 'distributed_solve.json'), 'w') as f:
        json.dump(dict(commit=commit, tolerance=TOLERANCE, rows=rows), f, indent=1)
    print('wrote bench/out/distributed_solve.json (commit %s)' % commit)


if __name__ == '__main__':
    main()
