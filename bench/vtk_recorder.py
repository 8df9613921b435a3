"""Benchmark: wall time of one DDAVTKRecorder output (blocks .vtu, contacts .vtp, both .pvd).

Each scene is a grid of columns of unit cubes standing on a fixed floor
(columns 0.5 m apart, cubes 1 mm apart in a column; maxDisplacement 0.01 m, so
d0 = 0.025 m at every size), run a few steps under
gravity so that every cube has closed contacts; then yade_dda.recorder.record
writes the scene `--repeats` times and the fastest output is reported, split
into reading the core (blocks, contacts) and writing (VTK). The first output
(which also reads every block's faces once) is reported apart. Writes
bench/out/vtk_recorder.json; prints a table.
Run: /usr/bin/python3 bench/vtk_recorder.py [--sizes 1000,10000] [--repeats 3]
"""
import argparse
import json
import math
import os
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from yade_dda import recorder, scene  # noqa: E402
from helpers import box, material  # noqa: E402

LAYERS = 5


def build(n):
    """n blocks: a floor and columns of LAYERS cubes."""
    rock = material(O, young=1e8, frictionDeg=30)
    columns = int(math.ceil((n - 1) / LAYERS))
    side = int(math.ceil(math.sqrt(columns)))
    O.bodies.append(ddaBlock(box((-1, -1, -1), (1.5 * side + 1, 1.5 * side + 1, 0)), material=rock, fixed=True))
    for k in range(n - 1):
        column, layer = k // LAYERS, k % LAYERS
        x, y, z = 1.5 * (column % side), 1.5 * (column // side), 1.001 * layer + 0.001
        O.bodies.append(ddaBlock(box((x, y, z), (x + 1, y + 1, z + 1)), material=rock))


def timed(function, *args):
    start = time.perf_counter()
    result = function(*args)
    return time.perf_counter() - start, result


def measure(n, repeats, directory):
    O.reset()
    build(n)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.01, label='dda')]
    O.run(3, True)
    prefix = os.path.join(directory, 'n%d-' % n)
    first, _ = timed(recorder.record, prefix)
    rows = []
    for _ in range(repeats):
        current = scene.current()
        with recorder._collectorPaused():   # as record() reads
            read, blocks = timed(recorder._blockArrays, current, prefix)
            readContacts, contacts = timed(recorder._contactArrays, current)
        write, _ = timed(recorder._writeBlocks, os.path.join(directory, 'b.vtu'), blocks)
        writeContacts, _ = timed(recorder._writeContacts, os.path.join(directory, 'c.vtp'), contacts)
        total, (blocksPath, contactsPath) = timed(recorder.record, prefix)
        rows.append(dict(total=total, readBlocks=read, readContacts=readContacts, writeBlocks=write,
                         writeContacts=writeContacts))
    best = min(rows, key=lambda row: row['total'])
    return dict(blocks=n, contacts=len(yade_dda.contacts()), closedContacts=len(yade_dda.contacts('closed')),
                first=first, bytesBlocks=os.path.getsize(blocksPath), bytesContacts=os.path.getsize(contactsPath),
                **best)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--sizes', default='1000,10000')
    parser.add_argument('--repeats', type=int, default=3)
    args = parser.parse_args()
    directory = tempfile.mkdtemp(prefix='yade_dda-vtk-bench-')
    try:
        results = [measure(int(n), args.repeats, directory) for n in args.sizes.split(',')]
    finally:
        shutil.rmtree(directory)
    print('%7s %9s %9s %8s %8s %8s %8s %8s %9s %9s' % ('blocks', 'contacts', 'output s', 'first s', 'read b', 'read c',
                                                      'write b', 'write c', 'vtu MB', 'vtp MB'))
    for r in results:
        print('%7d %9d %9.3f %8.3f %8.3f %8.3f %8.3f %8.3f %9.2f %9.2f' % (
            r['blocks'], r['contacts'], r['total'], r['first'], r['readBlocks'], r['readContacts'], r['writeBlocks'],
            r['writeContacts'], r['bytesBlocks'] / 1e6, r['bytesContacts'] / 1e6))
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'out')
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, 'vtk_recorder.json'), 'w') as f:
        json.dump(results, f, indent=1)


if __name__ == '__main__':
    main()
