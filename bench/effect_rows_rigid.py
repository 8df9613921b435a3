"""Benchmark row for the effect "rigid blocks": the same scene with every
moving block rigid (6 unknowns, ddaBlock(..., rigid=True)) and deformable
(12 unknowns), time per step and the largest difference in final positions.

Scene: a 5 x 5 grid of towers of 6 unit cubes (150 moving blocks) standing on a
fixed floor, 0.1 m apart, settling under gravity for 0.2 s; E = 1e12 Pa (a very
stiff rock, so the deformable run is the stiff limit the rigid one should match),
friction 30 deg. Both runs in this process, one thread, one after the other.

Tolerance [m]: a tower of n cubes of side L under its own weight strains block k
by at most sigma_k / E, sigma_k <= (n - k) rho g L x 2 (the load arrives at once),
so its top moves by at most sum_k sigma_k / E x L <= n sigma_max / E x L;
twice that for the elastic start-up the rigid blocks do not have:
tolerance = 2 n sigma_max L / E, with sigma_max the largest stress [Pa] of any
block in the deformable run.

``rows()`` returns the row(s) for bench/effects.py; run standalone
(``/usr/bin/python3 bench/effect_rows_rigid.py``, ``YADE_DDA_BUILD=build/py`` to
use a build tree) it prints them as JSON.
"""
import json
import math
import os
import sys
import time

if os.environ.get('YADE_DDA_BUILD'):
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'py'))
import yade_dda  # noqa: E402
from yade_dda import O, ddaBlock, DDAIntegrator  # noqa: E402
from yade import wrapper  # noqa: E402
from helpers import box  # noqa: E402

GRID = 5          # towers per side
HEIGHT = 6        # cubes per tower
SIDE = 1.0        # cube side [m]
GAP = 0.1         # between towers [m]
YOUNG = 1e12      # [Pa]
DENSITY = 2600.0  # [kg/m^3]
SECONDS = 0.2     # simulated [s]
DT = 1e-3         # [s]


def towers(rigid):
    """Builds the scene; returns the moving bodies' ids."""
    O.reset()
    rock = O.materials.append(wrapper.PolyhedraMat(density=DENSITY, young=YOUNG, poisson=0.25,
                                                   frictionAngle=math.radians(30)))
    span = GRID * (SIDE + GAP)
    O.bodies.append(ddaBlock(box((-1, -1, -1), (span + 1, span + 1, 0)), material=rock, fixed=True))
    ids = []
    for i in range(GRID):
        for j in range(GRID):
            x, y = i * (SIDE + GAP), j * (SIDE + GAP)
            for k in range(HEIGHT):
                ids.append(O.bodies.append(ddaBlock(box((x, y, k * SIDE), (x + SIDE, y + SIDE, (k + 1) * SIDE)),
                                                    material=rock, rigid=rigid)))
    O.engines = [DDAIntegrator(dt=DT, gravity=(0, 0, -9.81), maxDisplacement=0.005, threads=1, label='dda')]
    return ids


def run(rigid, chunk=10):
    """Runs the scene to SECONDS. Timed: the O.run calls only (chunks of `chunk` steps, the
    last step trimmed to end at SECONDS); between chunks, untimed, the largest stress is read."""
    ids = towers(rigid)
    O.run(1, True)   # blocks enter the core; not timed
    first, core, sigma, wall = O.iter, 0.0, 0.0, 0.0
    integrator = O.engines[-1]
    while O.time < SECONDS - 1e-12:
        n = chunk if O.time + (chunk + 1) * DT <= SECONDS else 1
        if n == 1:
            integrator.dt = min(DT, SECONDS - O.time)
        before = yade_dda.stats()['stepTimeTotal']
        start = time.perf_counter()
        O.run(n, True)
        wall += time.perf_counter() - start
        s = yade_dda.stats()
        core += s['stepTimeTotal'] - before
        if not rigid:
            sigma = max(sigma, max(max(abs(x) for x in yade_dda.block(b).stress) for b in ids))
    s = yade_dda.stats()
    steps = O.iter - first
    positions = [tuple(yade_dda.block(b).centroid) for b in ids]
    return dict(positions=positions, steps=steps, wallMs=1e3 * wall / steps, engineMs=1e3 * core / steps,
                sigma=sigma, unknowns=s["unknowns"], strainUnknowns=s["strainUnknowns"],
                time=O.time)


def rows():
    """One row: {effect, scene, msPerStepWith, msPerStepWithout, maxDifference [m], tolerance [m], note}."""
    without = run(False)
    with_ = run(True)
    difference = max(math.dist(a, b) for a, b in zip(with_['positions'], without['positions']))
    tolerance = 2 * HEIGHT * without['sigma'] * SIDE / YOUNG
    note = ('%d towers of %d cubes, E = %.0e Pa, %.2f s, one thread; ms/step is the wall time of O.run '
            '(engine incl. sync: %.3f rigid vs %.3f deformable); unknowns %d vs %d (strain unknowns %d vs %d); '
            'steps %d vs %d; tolerance 2 n sigma_max L / E, sigma_max = %.3g Pa (read every 10 steps)'
            % (GRID * GRID, HEIGHT, YOUNG, SECONDS, with_['engineMs'], without['engineMs'], with_['unknowns'],
               without['unknowns'], with_['strainUnknowns'], without['strainUnknowns'], with_['steps'],
               without['steps'], without['sigma']))
    return [dict(effect='rigid blocks', scene='%d towers of %d unit cubes settling' % (GRID * GRID, HEIGHT),
                 msPerStepWith=with_['wallMs'], msPerStepWithout=without['wallMs'], maxDifference=difference,
                 tolerance=tolerance, note=note)]


if __name__ == '__main__':
    print(json.dumps(rows(), indent=1))
