"""The three test scenes of Wu et al. (2014), Section 5 (examples/paper):
block counts, fixed counts, valid blocks, no initial penetration, and a few
DDA steps without NaN.

Geometry comes from examples/paper/paper_scenes.py (pure Python); each scene is
built with ddaBlock and run for a few steps with the paper's step controls
(dt 0.001 s, 0.01 m per step).
"""
import math
import os
import sys

import pytest

from yade_dda import O, DDAIntegrator, ddaBlock, stats, block, contacts
from yade import wrapper

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'examples', 'paper'))
import paper_scenes as scenes  # noqa: E402

G = 9.81

CASES = [
    # builder, kwargs, (total, fixed), material (young, density), steps
    ('hexahedra_drop', dict(length=20.0), (70, 2), (4e6, 2600), 250),   # the lowest layer lands at ~0.2 s
    ('hexahedra_drop', dict(length=60.0), (70, 2), (4e6, 2600), 5),
    ('slanted_slide', dict(), (23, 14), (10e6, 2600), 200),
    ('single_block_slide', dict(), (201, 200), (4e6, 2800), 300),
]


def test_geometry_is_pure_python_and_consistent():
    for name, kwargs, (total, nfixed), (young, density), _ in CASES:
        blocks, mat = scenes.SCENES[name](**kwargs)
        assert scenes.counts(blocks) == (total, nfixed, total - nfixed)
        assert mat['young'] == young and mat['density'] == density
        assert mat['poisson'] == 0.25 and mat['frictionAngle'] == 0.0
        for vertices, fixed in blocks:
            assert isinstance(fixed, bool) and len(vertices) in (6, 8)
            assert all(math.isfinite(c) for p in vertices for c in p)
    # The slanted scene's main axis: 60, 135, 120 degrees to +x, +y, +z.
    s, t, n = scenes.slide_frame()
    for axis, angle in zip(s, scenes.SLIDE_AXIS_ANGLES):
        assert abs(math.degrees(math.acos(axis)) - angle) < 1e-9
    assert abs(sum(a * b for a, b in zip(s, t))) < 1e-12 and abs(sum(a * b for a, b in zip(s, n))) < 1e-12
    # Hexahedra long axis follows the parameter.
    for L in (20.0, 40.0, 60.0):
        blocks, _ = scenes.hexahedra_drop(length=L)
        free = [v for v, fixed in blocks if not fixed]
        extents = sorted(max(p[i] for p in free[0]) - min(p[i] for p in free[0]) for i in range(3))
        assert extents == pytest.approx([1.0, 1.0, L])


@pytest.mark.parametrize('name, kwargs, expected, mat, steps', CASES,
                         ids=['hexahedra_drop_20m', 'hexahedra_drop_60m', 'slanted_slide', 'single_block_slide'])
def test_scene_builds_and_runs(scene, name, kwargs, expected, mat, steps):
    blocks, m = scenes.SCENES[name](**kwargs)
    rock = O.materials.append(wrapper.PolyhedraMat(young=m['young'], poisson=m['poisson'], density=m['density'],
                                                   frictionAngle=m['frictionAngle']))
    ids = [O.bodies.append(ddaBlock(v, material=rock, fixed=fixed)) for v, fixed in blocks]
    total, nfixed = expected
    assert len(ids) == total
    assert sum(1 for i in ids if block(i).fixed) == nfixed
    O.engines = [DDAIntegrator(dt=scenes.STEP['dt'], gravity=(0, 0, -G),
                               maxDisplacement=scenes.STEP['maxDisplacement'], label='dda')]
    O.step()
    s = stats()
    assert s['blocks'] == total and s['movingBlocks'] == total - nfixed
    # No block starts inside another.
    assert s['maxPenetration'] < 1e-6
    assert min([c.gap for c in contacts()] or [0.0]) > -1e-6
    closedMost = [0]

    def sample():
        closedMost[0] = max(closedMost[0], stats()['closedContacts'])

    O.engines = O.engines + [wrapper.PyRunner(iterPeriod=5, command='sample()')]
    sys.modules['__main__'].sample = sample
    O.run(steps - 1, True)
    s = stats()
    assert O.iter == steps
    assert all(math.isfinite(x) for i in ids for x in tuple(block(i).centroid) + tuple(block(i).velocity))
    assert s['maxPenetration'] < 0.01
    if steps > 100:
        assert closedMost[0] > 0          # resting on or landed on the fixed blocks
    # Falling or starting to slide: every free block moved down.
    for i, (vertices, fixed) in zip(ids, blocks):
        if fixed:
            continue
        z0 = sum(p[2] for p in vertices) / len(vertices)
        assert block(i).centroid[2] < z0 + 1e-9
