"""Every broad phase gives the contact set AllPairs gives, at every step of the
paper's three scenes (Wu et al. 2014, Sec. 5; examples/paper), and MSC's
narrow phase, which loops over the sub-units linked to overlapping shells
only, never makes more sub-unit tests than DESS's on them.

A step's contact set is every sub-contact's (body ids, kind, structural type,
state, contact point, gap), compared exactly: the same features at the same
geometry give the same floats, and one contact found or missed by a strategy
would also change every later step.
"""
import os
import sys

import pytest

from yade_dda import O, DDAIntegrator, ddaBlock, stats, contacts
from yade import wrapper

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'examples', 'paper'))
import paper_scenes as scenes  # noqa: E402

STRATEGIES = ('AllPairs', 'MSC', 'DESS', 'NBS')

# scene, arguments, steps: long enough for the hexahedra to land on the
# pentahedra (about 0.2 s), the slanted blocks and the single block to slide.
CASES = [
    ('hexahedra_drop', dict(length=20.0), 260),
    ('hexahedra_drop', dict(length=60.0), 260),
    ('slanted_slide', dict(), 150),
    ('single_block_slide', dict(), 200),
]


def run(name, kwargs, steps, collider):
    O.reset()
    blocks, m = scenes.SCENES[name](**kwargs)
    rock = O.materials.append(wrapper.PolyhedraMat(young=m['young'], poisson=m['poisson'], density=m['density'],
                                                   frictionAngle=m['frictionAngle']))
    for vertices, fixed in blocks:
        O.bodies.append(ddaBlock(vertices, material=rock, fixed=fixed))
    O.engines = [DDAIntegrator(dt=scenes.STEP['dt'], maxDisplacement=scenes.STEP['maxDisplacement'],
                               gravity=(0, 0, -9.81), collider=collider)]
    sets, work = [], []
    for _ in range(steps):
        O.step()
        sets.append(sorted((c.id1, c.id2, c.kind, c.type, c.state, tuple(c.point), c.gap) for c in contacts()))
        s = stats()
        work.append((s['candidatePairs'], s['subUnitPairs'], s['subUnitTests'], s['fullSearchPairs']))
    return sets, work


@pytest.mark.parametrize('name, kwargs, steps', CASES,
                         ids=['hexahedra_drop_20m', 'hexahedra_drop_60m', 'slanted_slide', 'single_block_slide'])
def test_every_strategy_finds_the_all_pairs_contacts_at_every_step(scene, name, kwargs, steps):
    results = {collider: run(name, kwargs, steps, collider) for collider in STRATEGIES}
    reference, _ = results['AllPairs']
    assert sum(len(s) for s in reference) > 0, 'the scene makes contacts'
    for collider in STRATEGIES[1:]:
        found, _ = results[collider]
        for step, (a, b) in enumerate(zip(reference, found)):
            assert a == b, '%s differs from AllPairs at step %d' % (collider, step + 1)
    # MSC: the linked sub-units only, never more work than DESS, and no
    # pair needed the full search (the scenes never penetrate by d0 / 2).
    _, msc = results['MSC']
    _, dess = results['DESS']
    for step, (m, d) in enumerate(zip(msc, dess)):
        assert m[0] <= d[0], 'step %d: MSC candidate pairs %d > DESS %d' % (step + 1, m[0], d[0])
        assert m[1] <= d[1], 'step %d: MSC sub-unit pairs %d > DESS %d' % (step + 1, m[1], d[1])
        assert m[2] <= d[2], 'step %d: MSC sub-unit tests %d > DESS %d' % (step + 1, m[2], d[2])
        assert m[3] == 0 and d[3] == 0
    if name != 'slanted_slide':   # its blocks are short of the critical length: one shell each, as DESS
        assert sum(m[2] for m in msc) < sum(d[2] for d in dess)


def test_slender_deposit_every_strategy_finds_the_all_pairs_contacts(scene):
    """A loose deposit of 150 slender blocks as bench/colliders.py builds them
    (each within d0 of the block it landed on, none overlapping), 40 steps
    under gravity: MSC's frame-tested shells and DESS give AllPairs' contacts
    at every step, MSC proposes at most twice the pairs within d0 (its target),
    and no sub-contact starts deeper than an edge crossing may (d0): crossed
    logs once got edge crossings 1 m "deep" from a face axis of theirs."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'bench'))
    import colliders as bench  # noqa: E402
    verts, _ = bench.slenderScene(150, seed=2)
    settings = bench.SLENDER
    d0 = settings['contactDistance']
    results = {}
    for collider in ('AllPairs', 'MSC', 'DESS'):
        O.reset()
        rock = O.materials.append(wrapper.PolyhedraMat(**settings['material']))
        for v in verts:
            O.bodies.append(ddaBlock([tuple(p) for p in v.tolist()], material=rock))
        O.engines = [DDAIntegrator(dt=settings['dt'], maxDisplacement=settings['maxDisplacement'],
                                   contactDistance=d0, gravity=(0, 0, -9.81), collider=collider)]
        sets, work = [], []
        for _ in range(40):
            O.step()
            sets.append(sorted((c.id1, c.id2, c.kind, c.type, c.state, tuple(c.point), c.gap) for c in contacts()))
            s = stats()
            work.append((s['candidatePairs'], s['contactPairs']))
        results[collider] = sets, work
    reference, _ = results['AllPairs']
    assert sum(len(s) for s in reference) > 100
    assert min(c[6] for c in reference[0]) >= -1.001 * d0
    for collider in ('MSC', 'DESS'):
        for step, (a, b) in enumerate(zip(reference, results[collider][0])):
            assert a == b, '%s differs from AllPairs at step %d' % (collider, step + 1)
    for step, (candidates, within) in enumerate(results['MSC'][1]):
        assert 0 < candidates <= 2 * within, 'step %d: %d MSC candidates for %d pairs within d0' % (
            step + 1, candidates, within)


def _deposit(seed, collider, threads, steps=25):
    """1,100 slender blocks in two layers, turned a little at random (seeded), landing on a floor:
    above the threshold at which the core's per-block loops, MSC's shell update and the sync's
    preparation run threaded. Returns the contact set of every step, the final corners, and what
    YADE's bodies show after every step (O.step() syncs each one)."""
    import math
    import random
    from helpers import box, rotate
    rng = random.Random(seed)
    O.reset()
    O.bodies.append(ddaBlock(box((-1, -1, -1), (36, 18, 0)), fixed=True))
    for i in range(1100):
        layer, k = divmod(i, 550)
        x, y = 0.7 * (k % 50), 0.35 * (k // 50) + (0.1 if layer else 0)
        z = 0.002 + 0.25 * layer
        corners = box((x, y, z), (x + 0.6, y + 0.3, z + 0.2))
        corners = rotate(corners, (rng.random(), rng.random(), 1.0), rng.uniform(-0.01, 0.01),
                         about=(x + 0.3, y + 0.15, z + 0.1))
        O.bodies.append(ddaBlock(corners, velocity=(0, 0, -0.2)))
    O.engines = [DDAIntegrator(dt=1e-3, maxDisplacement=0.005, gravity=(0, 0, -9.81), collider=collider,
                               threads=threads)]
    sets, shown = [], []
    for _ in range(steps):
        O.step()
        sets.append(sorted((c.id1, c.id2, c.kind, c.type, c.state, tuple(c.point), c.gap) for c in contacts()))
        shown.append([(tuple(b.state.pos), tuple(b.state.ori[i] for i in range(4)), tuple(b.state.vel),
                       tuple(b.state.angVel), tuple(tuple(v) for v in b.shape.v)) for b in O.bodies])
    assert math.isfinite(stats()['maxDisplacement'])
    return sets, [tuple(v) for b in O.bodies for v in __import__('yade_dda').block(b).vertices], shown


@pytest.mark.parametrize('seed', [11])
def test_threads_change_no_contact_and_no_motion_of_a_deposit(scene, seed):
    """MSC and DESS on 1 and 2 threads give bitwise the same contacts at every step and the same
    corners, and those contacts are AllPairs'; YADE's bodies show bitwise the same states and
    vertices after every step on 1 and 2 threads."""
    print('seed', seed)
    reference, corners, shownOnOne = _deposit(seed, 'AllPairs', 1)
    assert sum(len(s) for s in reference) > 1000, 'the deposit makes contacts'
    for collider in ('MSC', 'DESS'):
        for threads in (1, 2):
            found, foundCorners, shown = _deposit(seed, collider, threads)
            for step, (a, b) in enumerate(zip(reference, found)):
                assert a == b, '%s on %d threads differs from AllPairs at step %d' % (collider, threads, step)
            assert foundCorners == corners, '%s on %d threads moved the blocks differently' % (collider, threads)
            for step, (a, b) in enumerate(zip(shownOnOne, shown)):
                assert a == b, "YADE's bodies under %s on %d threads differ at step %d" % (collider, threads, step)
