"""Save, load and continue gives the same state as an uninterrupted run, bitwise.

The scene (saveload_scene.py) has sliding, locked and open contacts, stressed
and strained blocks and MSC's covers. It runs N steps, is saved, runs on
(so the live core scene has moved past the file), is loaded and runs M more
steps; every block's vertices, centroid, 12 rates, stress, strain and
rotation, every contact's state, forces and point, O.iter, O.time and the
next dt must equal those of an uninterrupted N + M step run, bit for bit
(the state is written bit for bit and in container order, so nothing
changes summation order).
"""
import ast
import base64
import gzip
import json
import os
import random
import signal
import struct
import subprocess
import sys
import time
import warnings
import zlib

import pytest

import yade_dda
from yade_dda import O, _core, engines, saveload
from yade_dda import scene as ddaScene
from yade import wrapper

sys.path.insert(0, os.path.dirname(__file__))
import saveload_scene  # noqa: E402

N, M = 40, 40
HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture(scope='module')
def reference():
    saveload_scene.build()
    O.run(N, True)
    atSave = saveload_scene.state()
    O.run(M, True)
    final = saveload_scene.state()
    O.reset()
    return atSave, final


def test_scene_has_every_contact_state(reference):
    atSave, _ = reference
    states = {c[4] for c in atSave['contacts']}
    assert {'open', 'sliding', 'locked'} <= states, states
    moving = [b for b in atSave['blocks'] if any(float.fromhex(x) != 0 for x in b[2])]
    assert len(moving) == 3
    for b in moving:
        assert any(float.fromhex(x) != 0 for x in b[3]), 'stress'
        assert any(float.fromhex(x) != 0 for x in b[4]), 'strain'


def _compare(got, want):
    got, want = json.loads(json.dumps(got)), json.loads(json.dumps(want))   # tuples and lists alike
    assert got['iter'] == want['iter'] and got['steps'] == want['steps']
    assert got['time'] == want['time'] and got['nextDt'] == want['nextDt']
    for k, (a, b) in enumerate(zip(got['blocks'], want['blocks'])):
        assert a == b, 'block %d differs' % k
    assert got['contacts'] == want['contacts']


@pytest.mark.parametrize('form', ['.yade', '.yade.gz', '.xml', '.xml.bz2', '.bz2', 'saveTmp'])
def test_save_load_continue_is_bitwise(scene, reference, tmp_path, form):
    saveload_scene.build()
    O.run(N, True)
    path = str(tmp_path / ('scene' + form))
    if form == 'saveTmp':
        O.saveTmp('saveload')
    else:
        O.save(path)
    assert saveload.tag(saveload.STATE_TAG) == '', 'the state tag is emptied after saving'
    O.run(17, True)   # the live core scene runs past the saved state
    if form == 'saveTmp':
        O.loadTmp('saveload')
    else:
        O.load(path)
    assert O.iter == N
    _compare(saveload_scene.state(), reference[0])
    O.run(M, True)
    _compare(saveload_scene.state(), reference[1])


def _continueAcrossSaveLoad(tmp_path, runOn, **build):
    """Runs N + M steps of saveload_scene.build(**build) uninterrupted, then N,
    save, runOn more, load, M; returns the uninterrupted final state."""
    saveload_scene.build(**build)
    O.run(N + M, True)
    want = saveload_scene.state()
    saveload_scene.build(**build)
    O.run(N, True)
    O.save(str(tmp_path / 'scene.yade'))
    O.run(runOn, True)
    O.load(str(tmp_path / 'scene.yade'))
    return want


@pytest.mark.parametrize('collider', ['DESS', 'NBS', 'AllPairs'])
def test_save_load_continue_is_bitwise_with_each_collider(scene, tmp_path, collider):
    """The other strategies keep caches (DESS's candidate pairs, within Verlet
    boxes) that are not saved but rebuilt: the continuation must still be
    bitwise that of an uninterrupted run."""
    want = _continueAcrossSaveLoad(tmp_path, 11, collider=collider)
    O.run(M, True)
    _compare(saveload_scene.state(), want)


def test_rigid_block_stays_rigid_across_save_load(scene, tmp_path):
    """A rigid block's flag is part of the saved state: loaded, it keeps 6
    unknowns and no strain, and the run continues bitwise."""
    want = _continueAcrossSaveLoad(tmp_path, 7, rigidTop=True)
    assert yade_dda.block(O.bodies[4]).rigid and not yade_dda.block(O.bodies[3]).rigid
    O.run(M, True)
    assert yade_dda.stats()['rigidBlocks'] == 1
    assert all(x == 0 for x in yade_dda.block(O.bodies[4]).strain)
    _compare(saveload_scene.state(), want)


def test_load_replaces_the_live_core_scene(scene, tmp_path):
    saveload_scene.build()
    O.run(5, True)
    before = ddaScene.current()
    O.save(str(tmp_path / 'a.yade'))
    O.load(str(tmp_path / 'a.yade'))
    after = ddaScene.current()
    assert after is not before and after.token != before.token
    assert before.token not in ddaScene._scenes, 'the replaced scene is dropped'
    assert O.tags[ddaScene.TAG] == after.token


CHILD_LOAD = r'''
import os, sys, json
sys.path.insert(0, %(here)r)
import yade_dda
from yade_dda import O
from yade import wrapper
import saveload_scene
if %(unwrapped)r:
    wrapper.Omega.load._yadeDDA(O, %(path)r)   # YADE's own load: restored at the first DDA call
else:
    O.load(%(path)r)
O.run(%(steps)d, True)
print('STATE ' + json.dumps(saveload_scene.state()))
'''


def _env():
    """The environment of a child process: it imports the yade_dda this process tests."""
    env = dict(os.environ)
    package = os.path.dirname(os.path.dirname(os.path.abspath(yade_dda.__file__)))
    env['PYTHONPATH'] = package + os.pathsep + env.get('PYTHONPATH', '')
    return env


def _child(script, timeout=120, **kw):
    return subprocess.run([sys.executable, '-c', script % kw], capture_output=True, text=True, timeout=timeout,
                          env=_env())


def _childState(out):
    line = [x for x in out.stdout.splitlines() if x.startswith('STATE ')]
    assert line, out.stdout[-2000:] + out.stderr[-3000:]
    return json.loads(line[-1][6:])


@pytest.mark.parametrize('unwrapped', [False, True])
def test_load_in_a_fresh_process(scene, reference, tmp_path, unwrapped):
    saveload_scene.build()
    O.run(N, True)
    path = str(tmp_path / 'scene.yade.gz')
    O.save(path)
    out = _child(CHILD_LOAD, here=HERE, path=path, steps=M, unwrapped=unwrapped)
    _compare(_childState(out), reference[1])


IMPACT_STEPS = 20


def _deepOverlaps():
    """Pairs of the current scene's blocks pressed into each other deeper than
    blocks entering a scene may overlap (guards.checkInitialOverlaps, all blocks)."""
    text = O.engines[0].command
    _, settings = engines._parse(ast.literal_eval(text[text.index('(') + 1:-1]))
    return ddaScene.current().core.initialOverlaps(0, [], settings)


@pytest.mark.parametrize('how', ['save', 'checkpoint'])
def test_save_load_during_an_impact(scene, tmp_path, how):
    """Saved while a falling block is pressed into the floor deeper than blocks
    entering a scene may overlap, the scene loads and continues bitwise. Its
    blocks passed the initial-overlap check when they entered; the loaded scene
    must not check them again as if new (it did: the first step after the load
    raised, O.run gave RuntimeError 'PyRunner error', and a checkpoint written
    at such a moment, e.g. by test_checkpoint_survives_sigkill's child, could
    not be resumed)."""
    saveload_scene.impact()
    deep = []
    for k in range(1, IMPACT_STEPS + 1):
        O.run(1, True)
        if _deepOverlaps():
            deep.append(k)
    want = saveload_scene.state()
    assert len(deep) >= 3, 'the scene must press the blocks deeper than the tolerance at several steps: %s' % deep
    if how == 'save':
        saved = []
        for k in deep:
            saveload_scene.impact()
            O.run(k, True)
            path = str(tmp_path / ('impact-%d.yade' % k))
            O.save(path)
            saved.append((k, path))
    else:
        directory = str(tmp_path / 'ck')
        saveload_scene.impact(engines=[yade_dda.Checkpoint(period=1, directory=directory, keep=1000, format='.yade')])
        O.run(IMPACT_STEPS, True)
        saved = [(k, path) for k, path in saveload.checkpoints(directory) if k in deep]
        assert len(saved) == len(deep), saved
    for k, path in saved:
        O.load(path)
        assert O.iter == k
        O.run(IMPACT_STEPS - k, True)
        _compare(saveload_scene.state(), want)


# ---- bad states

def _encode(info, core):
    infoBytes = json.dumps(info).encode()
    return saveload.FORMAT + ' ' + base64.b64encode(zlib.compress(struct.pack('<Q', len(infoBytes)) + infoBytes + core)).decode()


def _cut(text):
    """The tag text cut in the middle of its base64 (a length no base64 can have)."""
    head, body = text.split(' ', 1)
    n = len(body) // 2
    return head + ' ' + body[:n - (n % 4) + 1]


def _encodeText(text, change):
    """The tag text with its compressed bytes changed."""
    head, body = text.split(' ', 1)
    return head + ' ' + base64.b64encode(change(base64.b64decode(body))).decode()


def _stored():
    saveload.storeState()
    return O.tags[saveload.STATE_TAG]


def _snapshot():
    live = ddaScene.current()
    return live, live.core.saveState(), O.tags[ddaScene.TAG]


def _flip(core, offset):
    return core[:offset] + bytes([core[offset] ^ 0x40]) + core[offset + 1:]


BAD_STATES = {
    'truncated text': (lambda text, info, core: _cut(text), 'truncated or corrupt: not base64'),
    'truncated compressed data': (lambda text, info, core: _encodeText(text, lambda b: b[:len(b) // 2]),
                                  'truncated or corrupt: zlib'),
    'not base64': (lambda text, info, core: text[:-10] + '!!!!' + text[-6:], 'not base64'),
    'other tag format': (lambda text, info, core: text.replace(saveload.FORMAT, 'yade_dda-state/9', 1),
                         'format yade_dda-state/9; this yade_dda reads yade_dda-state/1'),
    'not a state': (lambda text, info, core: 'hello', 'does not hold a yade_dda state'),
    'core version': (lambda text, info, core: _encode(info, core[:16] + struct.pack('<I', 6) + core[20:]),
                     'format version 6; this build of yade_dda reads version 5'),
    'core checksum': (lambda text, info, core: _encode(info, _flip(core, len(core) // 2)),
                      'checksum does not match'),
    'core truncated': (lambda text, info, core: _encode(info, core[:-100]), 'truncated or padded'),
    'core not a state': (lambda text, info, core: _encode(info, b'x' * 100), 'not a saved DDA state'),
    'stale iteration': (lambda text, info, core: _encode(dict(info, iter=info['iter'] - 1), core),
                        'written at iteration 9 but the scene is at iteration 10: stale'),
    'other scene': (lambda text, info, core: _encode(dict(info, token='abc'), core), 'belongs to another DDA scene'),
}


@pytest.mark.parametrize('case', sorted(BAD_STATES))
def test_bad_state_raises_and_changes_nothing(scene, case):
    saveload_scene.build()
    O.run(10, True)
    text = _stored()
    info, core = saveload.decodeState(text)
    make, message = BAD_STATES[case]
    live, liveState, token = _snapshot()
    O.tags[saveload.STATE_TAG] = make(text, info, core)
    with pytest.raises(ValueError) as error:
        saveload.restoreState()
    assert message in str(error.value)
    assert ddaScene.current() is live and O.tags[ddaScene.TAG] == token
    assert live.core.saveState() == liveState, 'the scene is unchanged'


def test_core_load_state_is_all_or_nothing(scene):
    saveload_scene.build()
    O.run(10, True)
    core = ddaScene.current().core
    good = core.saveState()
    other = _core.Scene()
    for bad in (good[:len(good) // 3], _flip(good, 200), b''):
        with pytest.raises(ValueError):
            core.loadState(bad)
        assert core.saveState() == good
    with pytest.raises(ValueError, match='must be bytes'):
        other.loadState('text')
    other.loadState(good)
    assert other.saveState() == good


def _corruptFile(tmp_path):
    """The saveload scene run 10 steps and saved by YADE's own save (which writes the tags as they
    are) with its DDA state cut in half; the running scene keeps no state tag. Returns the path."""
    saveload_scene.build()
    O.run(10, True)
    text = _stored()
    O.tags[saveload.STATE_TAG] = text[:len(text) // 2]
    path = str(tmp_path / 'corrupt.yade')
    wrapper.Omega.save._yadeDDA(O, path)
    O.tags[saveload.STATE_TAG] = ''
    return path


def test_load_of_a_corrupt_file_raises_and_puts_the_scene_back(scene, tmp_path):
    path = _corruptFile(tmp_path)
    before = (O.iter, [tuple(yade_dda.block(i).vertices) for i in range(5)])
    with pytest.raises(ValueError, match='truncated or corrupt.*the running scene was put back as it was'):
        O.load(path)
    assert (O.iter, [tuple(yade_dda.block(i).vertices) for i in range(5)]) == before
    O.step()


def test_a_corrupt_state_loaded_into_an_empty_scene_stops_the_dda(scene, tmp_path):
    """With no running scene to put back, YADE's bodies stay loaded and DDA calls say why they cannot go on."""
    path = _corruptFile(tmp_path)
    O.reset()
    with pytest.raises(ValueError, match='truncated or corrupt'):
        O.load(path)
    assert len(O.bodies) == 5, 'YADE loaded its bodies'
    with pytest.raises(RuntimeError, match='cannot be restored: .*truncated or corrupt'):
        O.step()


def test_load_of_a_file_without_dda_state(scene, tmp_path):
    """A file saved before this feature (or by YADE's own save) has the DDA
    token but no state: it loads with a warning, DDA calls then raise."""
    saveload_scene.build()
    O.run(10, True)
    path = str(tmp_path / 'old.yade')
    wrapper.Omega.save._yadeDDA(O, path)
    with pytest.warns(RuntimeWarning, match='no saved DDA state'):
        O.load(path)
    with pytest.raises(RuntimeError, match='saved without their DDA state'):
        yade_dda.stats()
    with pytest.raises(RuntimeError, match='saved without their DDA state'):
        O.step()


def test_save_resolves_pending_blocks(scene, tmp_path):
    """Blocks appended but not yet stepped enter the core when saved."""
    saveload_scene.build()
    O.run(3, True)
    extra = O.bodies.append(yade_dda.ddaBlock(saveload_scene.box(-5, -0.5, 0, -4, 0.5, 1)))
    O.save(str(tmp_path / 'p.yade'))
    O.load(str(tmp_path / 'p.yade'))
    assert yade_dda.blockOf(extra) == 5
    O.run(2, True)


# ---- checkpoints

def test_checkpoint_parameters(scene):
    with pytest.raises(ValueError, match='period'):
        yade_dda.Checkpoint(period=0)
    with pytest.raises(ValueError, match='format'):
        yade_dda.Checkpoint(format='.txt')
    with pytest.raises(TypeError, match='has no parameter perod'):
        yade_dda.Checkpoint(perod=3)
    c = yade_dda.Checkpoint(period=7, directory='d', keep=2)
    assert c.iterPeriod == 7 and 'writeCheckpoint' in c.command


def test_checkpoints_keep_the_newest(scene, reference, tmp_path):
    directory = str(tmp_path / 'ck')
    saveload_scene.build(engines=[yade_dda.Checkpoint(period=10, directory=directory, keep=2, format='.yade')])
    O.run(N, True)
    # Written at iterations 10, 20 and 30 (after that iteration's DDA step:
    # the engine follows the integrator); the newest two are kept.
    found = saveload.checkpoints(directory)
    assert [i for i, _ in found] == [N - 20, N - 10], found
    latest = yade_dda.latestCheckpoint(directory)
    assert latest.endswith('checkpoint-%010d.yade' % (N - 10))
    assert not [f for f in os.listdir(directory) if f.startswith('.tmp')]
    O.load(latest)
    O.run(M + 10, True)
    _compare(saveload_scene.state(), reference[1])


CHILD_WRITER = r'''
import sys
sys.path.insert(0, %(here)r)
import yade_dda
from yade_dda import O
import saveload_scene
saveload_scene.build(engines=[yade_dda.Checkpoint(period=2, directory=%(directory)r, keep=3, format='.yade.gz')])
print('READY', flush=True)
O.run(100000, True)
'''


def test_checkpoint_survives_sigkill(scene, tmp_path):
    """A child writes a checkpoint every 2 steps and is killed with SIGKILL at
    a random moment. While it runs, every file under a checkpoint's name is a
    complete gzip stream; afterwards the newest loads and continues exactly
    like an uninterrupted run."""
    directory = str(tmp_path / 'ck')
    child = subprocess.Popen([sys.executable, '-c', CHILD_WRITER % dict(here=HERE, directory=directory)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
    try:
        while not child.stdout.readline().startswith('READY'):   # YADE prints a banner first
            assert child.poll() is None, child.stderr.read()[-3000:]
        deadline = time.time() + 1.5 + random.random() * 2
        checked = 0
        while time.time() < deadline or len(saveload.checkpoints(directory)) < 2:
            assert child.poll() is None, child.stderr.read()[-3000:]
            for _, path in saveload.checkpoints(directory):
                try:
                    with gzip.open(path) as f:
                        f.read()   # EOFError or BadGzipFile for a partial file
                    checked += 1
                except FileNotFoundError:
                    pass           # pruned meanwhile
            assert time.time() < deadline + 60, 'no checkpoints written'
        child.send_signal(signal.SIGKILL)
        child.wait(30)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert checked > 0
    found = saveload.checkpoints(directory)
    assert 1 <= len(found) <= 4   # keep=3, plus one written between the replace and the pruning
    iteration, latest = found[-1]
    O.load(latest)
    assert O.iter == iteration
    O.run(6, True)
    resumed = saveload_scene.state()
    saveload_scene.build()
    O.run(iteration + 6, True)
    _compare(resumed, saveload_scene.state())
