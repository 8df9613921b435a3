"""Saving and loading DDA scenes with YADE's own ``O.save``/``O.load``, and checkpoints.

YADE serializes its scene (bodies, engines, tags) but knows nothing of the DDA
core, which holds the true state: deformed vertices, 12-unknown velocities,
stresses, strains, contact history, the next time step. Importing yade_dda
wraps ``Omega.save``, ``saveTmp``, ``load``, ``loadTmp`` and ``reload``
(``yade_dda.installHooks``, with storeState and afterLoad from here):

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
import os
import re
import warnings

from ._yade import O, wrapper
from . import scene as _scene
from .params import Engine, Parameter, initEngine, integer, keywordsOnly
from .scene import restoreState
from .state import FORMAT, STATE_TAG, decodeState, encodeState, tag  # noqa: F401  (part of saveload's API)

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


# ---- around YADE's save and load (installed on Omega by yade_dda.hooks.installHooks)

def currentToken():
    """The DDA token of the current YADE scene, or None."""
    return tag(_scene.TAG) or None


_onLoad = []


def onLoad(function):
    """Runs function() after every load, before the DDA state is restored (the package registers
    typedengines.typedEngines: the engine classes live in modules that import this one)."""
    if function not in _onLoad:
        _onLoad.append(function)


def afterLoad(before):
    """What the wrapped loads do once YADE has read a scene: forget the core
    scenes of the replaced and of the loaded token (both are stale now), then
    rebuild the loaded scene's DDA state from its tag. A scene with DDA blocks
    but no saved state loads with a warning; DDA calls then raise. First
    the functions given to onLoad run (the package gives typedEngines: the
    yade_dda engines, which YADE loads as plain PyRunners, get their classes
    back)."""
    for function in _onLoad:
        function()
    loaded = currentToken()
    for token in (before, loaded):
        if token:
            _scene.drop(token)
    if loaded and not tag(STATE_TAG):
        warnings.warn('the loaded scene has DDA blocks but no saved DDA state (saved before yade_dda could save it, '
                      'or by a path that bypasses O.save): its DDA blocks cannot continue', RuntimeWarning)
        return None
    return restoreState()


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


def latestCheckpoint(directory, name='checkpoint', missingOk=False):
    """Path of the newest complete checkpoint in ``directory`` written under
    ``name``. With none there, FileNotFoundError naming the directory and the
    file names looked for, or None with ``missingOk=True`` (a script that
    resumes when it can and starts afresh otherwise). Resume with::

        O.load(yade_dda.latestCheckpoint('checkpoints')); O.run()
    """
    found = checkpoints(directory, name)
    if found:
        return found[-1][1]
    if missingOk:
        return None
    raise FileNotFoundError('no checkpoint %s-<iteration><format> in %r (%s)' % (
        name, directory,
        'the directory does not exist' if not os.path.isdir(directory) else 'nothing saved there yet'))


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


class Checkpoint(Engine, wrapper.PyRunner):
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

    period = Parameter(1000, integer('period', 1), 'iterations between checkpoints')
    directory = Parameter('checkpoints', _checkString('directory'), 'directory of the checkpoint files')
    name = Parameter('checkpoint', _checkString('name'), 'file name stem')
    keep = Parameter(3, integer('keep', 1), 'checkpoints kept')
    format = Parameter('.yade.gz', _checkFormat, 'file format by extension')

    _names = ('period', 'directory', 'name', 'keep', 'format')

    def __init__(self, *args, label='', **params):
        keywordsOnly(type(self), args)
        wrapper.PyRunner.__init__(self)
        initEngine(self, label, params)
        self._setYade('initRun', False)

    def _checkPeriod(self, name, value):
        # iterPeriod is `period`'s; virtPeriod and realPeriod are YADE's own (a checkpoint every
        # hour of wall time: realPeriod=3600), nDo too.
        if name == 'iterPeriod' and value != self.period:
            raise ValueError('Checkpoint: set period (iterations between checkpoints), not iterPeriod; got %r' % value)

    def _updateCommand(self):
        params = dict(self._params)
        self._setYade('iterPeriod', params.pop('period'))
        self._setYade('command', ('import yade_dda.saveload as _ddaSave; _ddaSave.writeCheckpoint(%r, %r, %r, %r)'
                        % (params['directory'], params['name'], params['keep'], params['format'])))
