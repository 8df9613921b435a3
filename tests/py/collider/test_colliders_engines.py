"""Collider engines (DESSCollider, NBSCollider, AllPairsCollider, MSCCollider) and compareColliders."""
import json
import math

import pytest

import yade_dda
from yade_dda import (O, ddaBlock, DDAIntegrator, DESSCollider, NBSCollider, AllPairsCollider, MSCCollider,
                      compareColliders)
from yade_dda import params as _settings
from yade_dda import scene as _scene
from yade import wrapper

from helpers import box, material, rotate

G = 9.81
ENGINES = {'DESS': DESSCollider, 'NBS': NBSCollider, 'AllPairs': AllPairsCollider}


def smallPile():
    """A fixed floor and 6 slender, slightly turned bars in two crossing layers, 1 cm apart: (vertices, fixed)."""
    blocks = [(box((-4, -4, -1), (4, 4, 0)), True)]
    for k in range(6):
        layer, i = divmod(k, 3)
        lo, hi = ((-3, -1.6 + 1.2 * i, 0.01), (3, -0.8 + 1.2 * i, 0.81)) if layer == 0 else \
            ((-1.6 + 1.2 * i, -3, 0.83), (-0.8 + 1.2 * i, 3, 1.63))
        centre = tuple((a + b) / 2 for a, b in zip(lo, hi))
        blocks.append((rotate(box(lo, hi), (0, 0, 1), 0.05 * (k - 2.5), about=centre), False))
    return blocks


def build(blocks, engines):
    O.reset()
    rock = material(O, young=1e9, frictionDeg=30)
    ids = [O.bodies.append(ddaBlock(points, material=rock, fixed=fixed)) for points, fixed in blocks]
    O.engines = engines
    return ids


def integrator(**kw):
    return DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=0.005, label='dda', **kw)


@pytest.mark.parametrize('name', sorted(ENGINES))
def test_engine_selects_its_strategy(scene, name):
    build(smallPile(), [ENGINES[name](label='collider'), integrator(collider='AllPairs' if name != 'AllPairs' else 'NBS')])
    O.run(3, True)
    assert _scene.current().core.collider() == name            # the engine wins over DDAIntegrator.collider
    assert O.engines[0].strategy == name and O.engines[0].label == 'collider'
    s = yade_dda.stats()
    pairs = 7 * 6 // 2                                         # every pair of the 7 blocks (only one is fixed)
    if name == 'AllPairs':
        assert s['candidatePairs'] == pairs
    else:
        assert s['contactPairs'] <= s['candidatePairs'] <= pairs
    assert s['contactPairs'] > 0


def test_engine_command_carries_the_choice_and_is_cheap_to_recognise(scene):
    engine = NBSCollider()
    assert engine.command.startswith('import yade_dda.')        # not a reader that forces a sync every step
    assert "_select('NBS')" in engine.command
    assert engine.iterPeriod == 1 and engine.initRun
    with pytest.raises(TypeError) as error:
        DESSCollider(segments=3)
    assert 'DESSCollider has no parameter segments' in str(error.value)


def test_without_engine_the_integrator_parameter_applies_again(scene):
    build(smallPile(), [NBSCollider(label='collider'), integrator(collider='AllPairs')])
    O.run(2, True)
    assert _scene.current().core.collider() == 'NBS'
    O.engines = [O.engines[1]]                                  # collider engine removed
    O.run(2, True)
    assert _scene.current().core.collider() == 'AllPairs'


def test_same_trajectories_with_every_strategy(scene):
    """All strategies find the same contacts, so the blocks move identically (bit for bit)."""
    results = {}
    for name, engine in ENGINES.items():
        ids = build(smallPile(), [engine(label='collider'), integrator()])
        closed = []
        for _ in range(12):
            O.run(10, True)
            closed.append(yade_dda.stats()['closedContacts'])
        results[name] = ([tuple(O.bodies[i].state.pos) for i in ids], [tuple(O.bodies[i].state.ori) for i in ids],
                         closed, O.time)
        assert max(closed) > 0                                 # the pile has landed: contacts are exercised
    reference = results['AllPairs']
    for name in ENGINES:
        assert results[name] == reference, name


def test_msc_engine_parameters_reach_the_core(scene):
    """Slender 12 x 1 x 1 m logs: with segments=1 every block has one shell;
    with segments=3 and the default critical length (3 x block size, about
    6.9 m here) each log gets three, and MSC offers fewer sub-unit pairs to
    the narrow phase than DESS for the same contacts."""
    assert 'MSC' in _settings.COLLIDERS
    logs = [(box((0, 1.05 * k, 0), (12, 1.05 * k + 1, 1)), k == 0) for k in range(6)]
    logs += [(box((1.05 * k, 0, 1.01), (1.05 * k + 1, 12, 2.01)), False) for k in range(6)]
    counts = {}
    for name, engine in (('one', MSCCollider(segments=1)), ('three', MSCCollider(segments=3)),
                         ('dess', DESSCollider())):
        build(logs, [engine, integrator()])
        O.run(2, True)
        s = yade_dda.stats()
        counts[name] = (s['shells'], s['subUnitPairs'], s['contacts'])
    assert counts['one'][0] == 12 and counts['three'][0] == 36
    assert counts['three'][2] == counts['dess'][2] == counts['one'][2]
    assert counts['three'][1] < counts['dess'][1]
    with pytest.raises(ValueError):
        MSCCollider(segments=0)


def test_msc_parameters_are_checked_and_stored(scene, monkeypatch):
    monkeypatch.setattr(_settings, 'COLLIDERS', _settings.COLLIDERS + ('MSC',) * ('MSC' not in _settings.COLLIDERS))
    engine = MSCCollider(label='msc')
    assert (engine.criticalLength, engine.segments) == (0.0, 3)
    engine.segments = 5
    assert 'segments=5' in engine.command
    with pytest.raises(ValueError):
        MSCCollider(criticalLength=-1)
    with pytest.raises(ValueError):
        MSCCollider(segments=0)
    with pytest.raises(ValueError):
        MSCCollider(segments=2.5)


def test_compare_colliders_on_a_tiny_scene(scene, tmp_path):
    out = tmp_path / 'cmp' / 'result.json'
    result = compareColliders(smallPile, steps=5, dt=1e-3, gravity=(0, 0, -G), out=str(out),
                              integrator=dict(maxDisplacement=0.005), verbose=False)
    names = [r['strategy'] for r in result['rows']]
    ours = [n for n in ('MSC', 'DESS', 'NBS', 'AllPairs') if n in _settings.COLLIDERS]
    assert names == ours + ['InsertionSortCollider', 'SpatialQuickSortCollider']
    assert result['reference'] == ('MSC' if 'MSC' in ours else 'DESS')
    if 'MSC' not in ours:
        assert 'MSC' in result['skipped']
    for row in result['rows']:
        assert row['steps'] == 5
        assert row['detectionMs'] > 0 and row['candidatePairs'] >= row['contactPairs'] >= 0
        assert len(result['perStep'][row['strategy']]['detectionMs']) == 5
    rows = {r['strategy']: r for r in result['rows']}
    assert rows['AllPairs']['candidatePairs'] == 7 * 6 // 2
    assert rows['DESS']['contactPairs'] == rows['AllPairs']['contactPairs'] == rows['NBS']['contactPairs']
    assert all(d == 0 for d in result['trajectoryDifference'].values())
    # what YADE was told is in the output
    yadeTold = result['told']['InsertionSortCollider']
    assert yadeTold['dt'] == 1e-3 and 'verletDist=0.0' in yadeTold['engines'][1]
    assert 'NewtonIntegrator(damping=0.0, gravity=(0.0, 0.0, -9.81))' in yadeTold['engines']
    assert yadeTold['finite']
    saved = json.loads(out.read_text())
    assert saved['settings']['dt'] == 1e-3 and saved['settings']['blocks'] == 7
    assert [r['strategy'] for r in saved['rows']] == names
    for path in result['files'][1:]:
        with open(path, 'rb') as f:
            assert f.read(8) == b'\x89PNG\r\n\x1a\n'
    assert len(result['files']) == 3


def test_compare_colliders_rejects_bad_input(scene, tmp_path):
    with pytest.raises(ValueError):
        compareColliders(smallPile, steps=0, out=str(tmp_path / 'x.json'))
    with pytest.raises(ValueError):
        compareColliders(smallPile, strategies=('Octree',), out=str(tmp_path / 'x.json'))
    with pytest.raises(ValueError):
        compareColliders(smallPile, integrator=dict(dt=1), out=str(tmp_path / 'x.json'))


def test_compare_colliders_takes_concave_blocks(scene, tmp_path):
    """A concave block (an L of three parts) on a fixed floor beside a cube and under a falling cube:
    every strategy finds the same contact pairs and the same trajectories, YADE runs the L as a clump
    of its parts and stays finite; the L counts as one block."""
    floor = box((-3, -3, -1), (3, 3, 0))
    ell = [box((0, 0, 0), (1, 1, 1)), box((0, 1, 0), (1, 2, 1)), box((1, 1, 0), (2, 2, 1))]
    blocks = [(floor, True), (ell, False), box((1.2, 0, 0), (2.2, 0.9, 1)), box((0.1, 1.1, 1.001), (0.9, 1.9, 1.8))]
    result = compareColliders(blocks, steps=5, dt=1e-3, gravity=(0, 0, -G), out=str(tmp_path / 'ell.json'),
                              integrator=dict(maxDisplacement=0.005), verbose=False, plots=False)
    rows = {r['strategy']: r for r in result['rows']}
    assert result['settings']['blocks'] == 4 and result['settings']['fixedBlocks'] == 1
    pairs = {rows[n]['contactPairs'] for n in ('DESS', 'NBS', 'AllPairs') if n in rows}
    assert len(pairs) == 1 and pairs.pop() > 0
    assert rows['AllPairs']['candidatePairs'] == 6 * 5 // 2   # the broad phase's units are the six parts
    assert all(d == 0 for d in result['trajectoryDifference'].values())
    assert result['told']['InsertionSortCollider']['finite']
    assert 'SpatialQuickSortCollider' in result['skipped'] and 'SpatialQuickSortCollider' not in rows
