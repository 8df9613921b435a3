"""Saving and loading DDA scenes with YADE's own ``O.save``/``O.load``, and checkpoints.

YADE serializes its scene (bodies, engines, tags) but knows nothing of the DDA
core, which holds the true state: deformed vertices, 12-unknown velocities,
stresses, strains, contact history, the next time step. Importing yade_dda
wraps ``Omega.save``, ``saveTmp``, ``load``, ``loadTmp`` and ``reload``:

- before YADE saves, the core's state (a versioned, checksummed binary from
  ``_core.Scene.saveState``, zlib-compressed, base64) is put in
  ``O.tags['yade_dda.state']``, which YADE writes in every format (.yade,
  .yade.gz, .xml, .xml.bz2, .bz2, and saveTmp's memory); bodies are synced
  first so the file shows the current state too;
- after YADE loads, the core scene is rebuilt from that tag, bit for bit, and
  the run continues exactly as if it had never stopped.

The state is tied to its scene: it carries the scene's token (``O.tags
['yade_dda.scene']``) and the iteration at which it was written, and is used
only when both match the loaded scene. A loaded scene always gets a new core
scene (a fresh token), never the one still alive in this process, and the
core scene of the YADE scene that the load replaced is dropped.

A file saved without DDA state (before yade_dda could save it, or by a path
that bypasses ``O.save``) loads, but its DDA blocks cannot continue: any DDA
call raises RuntimeError saying so. A state that cannot be read raises
ValueError naming the problem, and no DDA scene is made from it.

Example (resume from the newest checkpoint)::

    O.load(yade_dda.latestCheckpoint('checkpoints'))
    O.run()
"""
import base64
import binascii
import json
import os
import re
import struct
import warnings
import zlib

from ._yade import O, wrapper
from . import _core
from . import scene as _scene
from .engines import _Parameter, _initEngine, _finite

STATE_TAG = 'yade_dda.state'
# Text format of the tag: "<FORMAT> <base64 of zlib of (u64 info length, info JSON, core state)>".
FORMAT = 'yade_dda-state/1'


def _tag(name):
    """O.tags[name], or '' when absent (YADE's tags have no get or del)."""
    return O.tags[name] if name in O.tags.keys() else ''


def encodeState(scene):
    """The tag text holding a DDA scene's full state (see the module docstring)."""
    info = dict(token=scene.token, iter=O.iter, steps=scene.core.steps(), bodies=scene.bodyOfBlock,
                cover=list(scene.cover) if getattr(scene, 'cover', None) is not None else None,
                checked=getattr(scene, 'overlapsChecked', 0))
    infoBytes = json.dumps(info, separators=(',', ':')).encode('utf-8')
    raw = struct.pack('<Q', len(infoBytes)) + infoBytes + scene.core.saveState()
    return FORMAT + ' ' + base64.b64encode(zlib.compress(raw, 1)).decode('ascii')


def decodeState(text):
    """(info dict, core state bytes) from a tag text; ValueError naming what is wrong."""
    where = "O.tags['%s']" % STATE_TAG
    head, _, body = text.partition(' ')
    if not head.startswith('yade_dda-state/'):
        raise ValueError('%s does not hold a yade_dda state (it starts with %r)' % (where, text[:20]))
    if head != FORMAT:
        raise ValueError('%s has format %s; this yade_dda reads %s' % (where, head, FORMAT))
    try:
        compressed = base64.b64decode(body.encode('ascii'), validate=True)
    except (binascii.Error, UnicodeEncodeError, ValueError) as error:
        raise ValueError('%s is truncated or corrupt: not base64 (%s)' % (where, error)) from None
    try:
        raw = zlib.decompress(compressed)
    except zlib.error as error:
        raise ValueError('%s is truncated or corrupt: zlib says %s' % (where, error)) from None
    if len(raw) < 8:
        raise ValueError('%s is truncated: %d bytes' % (where, len(raw)))
    (n,) = struct.unpack('<Q', raw[:8])
    try:
        info = json.loads(raw[8:8 + n].decode('utf-8'))
        if not isinstance(info, dict) or not {'token', 'iter', 'steps', 'bodies'} <= set(info):
            raise ValueError('keys missing')
    except ValueError as error:
        raise ValueError('%s is corrupt: its header cannot be read (%s)' % (where, error)) from None
    return info, raw[8 + n:]


def storeState():
    """Puts the current DDA scene's state into O.tags (what the wrapped O.save
    does before YADE writes). Pending blocks (appended, not yet stepped) enter
    the core first and bodies are synced. Returns the tag's length in
    characters, 0 when the scene has no DDA scene to store."""
    try:
        scene = _scene.current(create=False)
    except RuntimeError:
        return 0   # DDA state that could not be restored: save what YADE has
    if scene is None:
        return 0
    scene.resolvePending()
    scene.sync(everything=True)
    text = encodeState(scene)
    O.tags[STATE_TAG] = text
    return len(text)


def restoreState():
    """Rebuilds the DDA scene of the current YADE scene from
    ``O.tags['yade_dda.state']`` (what the wrapped O.load does after YADE
    reads). Returns the new DDA scene, or None when the YADE scene has no DDA
    blocks. Raises ValueError naming the problem when the state is missing for
    a DDA scene, stale, corrupt or of another version; then nothing changes."""
    token = _tag(_scene.TAG)
    text = _tag(STATE_TAG)
    if not token:
        return None
    if not text:
        raise ValueError(
            'this YADE scene has DDA blocks but was saved without their DDA state (a file saved before yade_dda '
            'could save it, or by a path that bypasses O.save); its DDA blocks cannot continue')
    info, state = decodeState(text)
    if info['token'] != token:
        raise ValueError("O.tags['%s'] belongs to another DDA scene (token %s, this scene's is %s): stale state, "
                         'not used' % (STATE_TAG, info['token'], token))
    if info['iter'] != O.iter:
        raise ValueError("O.tags['%s'] was written at iteration %d but the scene is at iteration %d: stale state "
                         '(the scene was saved again without yade_dda?), not used' % (STATE_TAG, info['iter'], O.iter))
    core = _core.Scene()
    core.loadState(state)
    bodies = info['bodies']
    checked = info.get('checked', core.blockCount() if core.steps() > 0 else 0)
    if (core.steps() != info['steps'] or core.blockCount() != len(bodies) or not isinstance(checked, int)
            or isinstance(checked, bool) or not 0 <= checked <= len(bodies)):
        raise ValueError("O.tags['%s'] is corrupt: its header and its core state disagree" % STATE_TAG)
    for index, bodyId in enumerate(bodies):
        body = O.bodies[bodyId] if 0 <= bodyId < len(O.bodies) else None
        if body is None or not isinstance(body.shape, wrapper.Polyhedra):
            raise ValueError('DDA block %d is shown by body %d, which is %s in the loaded scene: the saved DDA state '
                             'does not match its bodies' % (index, bodyId, 'missing' if body is None
                                                             else 'a %s' % type(body.shape).__name__))
    scene = _scene.DDAScene(_scene.newToken())
    scene.core = core
    scene.bodyOfBlock = list(bodies)
    scene.cover = tuple(info['cover']) if info.get('cover') is not None else None
    # The blocks the saved scene had already checked for initial overlaps (guards.checkInitialOverlaps)
    # stay checked: checked again, blocks pressed into each other by their contacts (an impact, a block
    # sliding into a step) would be refused as overlapping and the run could not resume. Blocks that
    # entered the core when the scene was saved (pending ones) are still checked at the next step, as
    # they would have been without the save. States written before this was stored: all blocks of a
    # scene that has stepped count as checked, none of one that has not.
    scene.overlapsChecked = checked
    _scene.register(scene)
    O.tags[STATE_TAG] = ''
    return scene


# ---- the wrapped Omega methods

def _currentToken():
    return _tag(_scene.TAG) or None


def _wrapSave(original):
    def save(self, *args, **kwargs):
        stored = storeState()
        try:
            return original(self, *args, **kwargs)
        finally:
            if stored:
                O.tags[STATE_TAG] = ''
    save.__doc__ = original.__doc__ + '\n\n(yade_dda: also saves the DDA state, see yade_dda.saveload.)'
    save._yadeDDA = original
    return save


def afterLoad(before):
    """What the wrapped loads do once YADE has read a scene: forget the core
    scenes of the replaced and of the loaded token (both are stale now), then
    rebuild the loaded scene's DDA state from its tag. A scene with DDA blocks
    but no saved state loads with a warning; DDA calls then raise."""
    loaded = _currentToken()
    for token in (before, loaded):
        if token:
            _scene.drop(token)
    if loaded and not _tag(STATE_TAG):
        warnings.warn('the loaded scene has DDA blocks but no saved DDA state (saved before yade_dda could save it, '
                      'or by a path that bypasses O.save): its DDA blocks cannot continue', RuntimeWarning)
        return None
    return restoreState()


def _wrapLoad(original):
    def load(self, *args, **kwargs):
        before = _currentToken()
        result = original(self, *args, **kwargs)
        afterLoad(before)
        return result
    load.__doc__ = original.__doc__ + '\n\n(yade_dda: also restores the DDA state, see yade_dda.saveload.)'
    load._yadeDDA = original
    return load


def _install():
    for name, wrap in (('save', _wrapSave), ('saveTmp', _wrapSave), ('load', _wrapLoad), ('loadTmp', _wrapLoad),
                       ('reload', _wrapLoad)):
        method = getattr(wrapper.Omega, name)
        original = getattr(method, '_yadeDDA', method)   # never wrap twice (module reloads)
        setattr(wrapper.Omega, name, wrap(original))


_install()


# ---- checkpoints

_CHECKPOINT_NAME = re.compile(r'^(?P<name>.+)-(?P<iter>\d{10})(?P<ext>\.(yade|xml)(\.gz|\.bz2)?)$')
_FORMATS = ('.yade.gz', '.yade', '.xml', '.xml.gz', '.xml.bz2')


def _fsyncPath(path, directory=False):
    fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if directory else 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def checkpoints(directory, name='checkpoint'):
    """Complete checkpoints in ``directory`` written under ``name``, oldest first,
    as (iteration, path). Temporary files of unfinished writes are never listed."""
    found = []
    try:
        entries = os.listdir(directory)
    except FileNotFoundError:
        return found
    for entry in entries:
        match = _CHECKPOINT_NAME.match(entry)
        if match and match.group('name') == name:
            found.append((int(match.group('iter')), os.path.join(directory, entry)))
    return sorted(found)


def latestCheckpoint(directory, name='checkpoint'):
    """Path of the newest complete checkpoint in ``directory``, or None. Resume with::

        O.load(yade_dda.latestCheckpoint('checkpoints')); O.run()
    """
    found = checkpoints(directory, name)
    return found[-1][1] if found else None


def writeCheckpoint(directory, name='checkpoint', keep=3, format='.yade.gz'):
    """Saves the scene (YADE and DDA state) as ``directory/name-<iteration>.<format>``
    so that no partial file is ever visible under that name: it is written to a
    temporary file in the same directory, flushed to disk (fsync), renamed over
    the final name atomically (os.replace) and the directory entry is synced.
    Then all but the newest ``keep`` checkpoints of that name are deleted, and
    temporary files of writers that no longer run. Returns the path."""
    if format not in _FORMATS:
        raise ValueError('checkpoint format must be one of %s, got %r' % (', '.join(_FORMATS), format))
    os.makedirs(directory, exist_ok=True)
    final = os.path.join(directory, '%s-%010d%s' % (name, O.iter, format))
    temporary = os.path.join(directory, '.tmp-%d-%s-%010d%s' % (os.getpid(), name, O.iter, format))
    try:
        O.save(temporary, True)
        _fsyncPath(temporary)
        os.replace(temporary, final)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise
    _fsyncPath(directory, directory=True)
    for _, old in checkpoints(directory, name)[:-keep]:
        os.remove(old)
    for entry in os.listdir(directory):
        match = re.match(r'^\.tmp-(\d+)-', entry)
        if match and int(match.group(1)) != os.getpid() and not _running(int(match.group(1))):
            try:
                os.remove(os.path.join(directory, entry))
            except FileNotFoundError:
                pass
    return final


def _running(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _checkString(what):
    def check(value):
        if not isinstance(value, str) or not value:
            raise ValueError('%s must be a non-empty string, got %r' % (what, value))
        return value
    return check


def _checkFormat(value):
    if value not in _FORMATS:
        raise ValueError('format must be one of %s, got %r' % (', '.join(_FORMATS), value))
    return value


class Checkpoint(wrapper.PyRunner):
    """Saves the whole scene (YADE's and the DDA state) every ``period``
    iterations, crash-safe, keeping the newest ``keep`` files.

    Files are ``directory/name-<iteration, 10 digits><format>``; each is written
    to a temporary file in the same directory, fsynced and renamed atomically,
    so a process killed mid-write leaves the previous checkpoints intact and
    never a partial file under a checkpoint's name (see writeCheckpoint). The
    engine may stand anywhere in ``O.engines``. Resume::

        O.load(yade_dda.latestCheckpoint('checkpoints'))
        O.run()

    Parameters: ``period`` (iterations, >= 1), ``directory``, ``name``
    ('checkpoint'), ``keep`` (>= 1, default 3), ``format`` ('.yade.gz',
    '.yade', '.xml', '.xml.gz' or '.xml.bz2'). Example::

        O.engines = [DDAIntegrator(dt=1e-3), Checkpoint(period=10000, directory='checkpoints')]
    """

    period = _Parameter(1000, lambda v: int(_finite('period', v, 1)), 'iterations between checkpoints')
    directory = _Parameter('checkpoints', _checkString('directory'), 'directory of the checkpoint files')
    name = _Parameter('checkpoint', _checkString('name'), 'file name stem')
    keep = _Parameter(3, lambda v: int(_finite('keep', v, 1)), 'checkpoints kept')
    format = _Parameter('.yade.gz', _checkFormat, 'file format by extension')

    _names = ('period', 'directory', 'name', 'keep', 'format')

    def __init__(self, label='', **params):
        wrapper.PyRunner.__init__(self)
        _initEngine(self, label, params)
        self.initRun = False

    def _updateCommand(self):
        params = dict(self._params)
        self.iterPeriod = params.pop('period')
        self.command = ('import yade_dda.saveload as _ddaSave; _ddaSave.writeCheckpoint(%r, %r, %r, %r)'
                        % (params['directory'], params['name'], params['keep'], params['format']))
