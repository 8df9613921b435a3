"""Prescribed motion of fixed blocks: ground shaking, a shaking table, a moving boundary.

``baseMotion`` gives fixed DDA blocks a translation history (acceleration or velocity against
time: a table, a function, or a file such as a recorded accelerogram); the contacts with moving
blocks carry it. ``baseMotionState`` and ``baseMotionRecord`` read the base's motion now (the
latter as plain numbers for ``yade.plot.addData``). The kinematics are exact within a step
(pkg/dda/solver/BaseMotion.hpp) and the work the base does is the energy account's
``boundaryWork``.
"""
import math
import numbers
import os

from .scene import current


def baseMotion(bodies, acceleration=None, velocity=None, direction=None, scale=1.0, start=None, sampling=None,
               duration=None):
    """Moves fixed DDA blocks by a prescribed translation history; returns the motion's index.

    Give exactly one of ``acceleration`` [m/s^2] or ``velocity`` [m/s], as

    - a table: rows ``(time [s], value)``, the times strictly increasing from >= 0, the value a number
      (along ``direction``) or a 3-vector; linear between rows;
    - a file name: a text file of two columns, time [s] and value (four: time and a 3-vector),
      separated by spaces, tabs or commas; ``#`` starts a comment, blank lines are skipped (a recorded
      accelerogram, in g with ``scale=9.81``);
    - a callable ``f(t)`` of the history's time [s] returning a number or a 3-vector, tabulated every
      ``sampling`` [s] over ``[0, duration]`` [s] (both required).

    ``bodies``: a fixed DDA block (Body or id) or a list of them; a concave block moves whole.
    ``direction``: what a number's value acts along (normalised), default ``(1, 0, 0)``.
    ``scale``: multiplies every value [-]. ``start``: the scene time [s] of the history's time 0
    (default: the scene's time now).

    Kinematics: the history is integrated in closed form over each step (piecewise linear
    acceleration: cubic displacement), so a cut or any dt moves the blocks exactly. Before its first
    time the base is at rest; an acceleration table has zero acceleration after its last time (the
    base keeps the velocity reached), a velocity table keeps its last velocity. The start from rest
    holds the base still; it moves from the first dynamic step. Translation only. Bad input raises
    ``ValueError`` (or ``TypeError``) naming the problem. Example (a 2 Hz, 0.3 g shaking table)::

        baseMotion(table, acceleration=lambda t: 0.3 * 9.81 * math.sin(4 * math.pi * t),
                   sampling=1e-3, duration=5.0)
    """
    scene = _require()
    indices = _fixedBlocks(scene, bodies)
    kind, history = _oneHistory(acceleration, velocity)
    scale = _finite(scale, 'scale')
    times, values = _table(history, kind, sampling, duration)
    values = _vectors(values, direction, scale, kind)
    start = scene.core.time() if start is None else _finite(start, 'start')
    return scene.core.addBaseMotion(indices, kind, times, values, start)


def _require():
    scene = current(create=False)
    if scene is None:
        raise RuntimeError('this YADE scene has no DDA blocks (make them with ddaBlock)')
    return scene


def baseMotionState(motion=0):
    """The base's motion at the scene's time now as a dict of Vector3: ``displacement`` [m] since its
    start, ``velocity`` [m/s], ``acceleration`` [m/s^2] (motion: baseMotion's index)."""
    scene = _require()
    u, v, a = scene.core.baseMotionAt(_motionIndex(scene, motion), scene.core.time())
    return dict(displacement=u, velocity=v, acceleration=a)


def baseMotionRecord(motion=0, prefix='base'):
    """The base's motion now as plain numbers for ``yade.plot.addData``: ``<prefix>Ux, Uy, Uz`` [m],
    ``Vx, Vy, Vz`` [m/s], ``Ax, Ay, Az`` [m/s^2]. Example::

        plot.addData(t=O.time, slip=slip(), **baseMotionRecord())
    """
    state = baseMotionState(motion)
    out = {}
    for letter, key in (('U', 'displacement'), ('V', 'velocity'), ('A', 'acceleration')):
        for axis, value in zip('xyz', state[key]):
            out[prefix + letter + axis] = value
    return out


def _motionIndex(scene, motion):
    count = scene.core.baseMotionCount()
    if not isinstance(motion, int) or isinstance(motion, bool) or not 0 <= motion < count:
        raise ValueError('no base motion %r (the scene has %d; baseMotion returns the index)' % (motion, count))
    return motion


def _fixedBlocks(scene, bodies):
    """Block indices of the fixed DDA blocks `bodies` (one or a list)."""
    many = bodies if isinstance(bodies, (list, tuple, range)) else [bodies]
    if not many:
        raise ValueError('baseMotion needs at least one fixed DDA block')
    indices = []
    for body in many:
        try:
            index = scene.blockIndex(body)
        except KeyError as error:
            raise ValueError('baseMotion: %s' % error.args[0]) from None
        if not scene.core.isFixed(index):
            raise ValueError('baseMotion: body %d is not fixed: only a fixed DDA block (fixed=True) can be given a '
                             'prescribed motion' % scene.bodyOfBlock[index])
        indices.append(index)
    return indices


def _oneHistory(acceleration, velocity):
    if (acceleration is None) == (velocity is None):
        raise ValueError('baseMotion needs exactly one of acceleration= or velocity=')
    return ('acceleration', acceleration) if velocity is None else ('velocity', velocity)


def _finite(value, what):
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise TypeError('%s must be a number, got %r' % (what, value)) from None
    if not math.isfinite(value):
        raise ValueError('%s must be finite, got %r' % (what, value))
    return value


def _table(history, kind, sampling, duration):
    """(times, values) of a table, a file or a callable."""
    if isinstance(history, (str, os.PathLike)):
        return readMotionFile(os.fspath(history))
    if callable(history):
        if sampling is None or duration is None:
            raise ValueError('a %s given as a function needs sampling= and duration= [s] to tabulate it' % kind)
        sampling, duration = _finite(sampling, 'sampling'), _finite(duration, 'duration')
        if not (sampling > 0 and duration > 0):
            raise ValueError('sampling and duration must be > 0 s, got %r and %r' % (sampling, duration))
        count = int(math.ceil(duration / sampling - 1e-9))
        times = [min(k * sampling, duration) for k in range(count + 1)]
        return times, [history(t) for t in times]
    try:
        rows = [tuple(row) for row in history]
    except TypeError:
        raise TypeError('the %s must be a table of (time, value) rows, a file name or a function, got %r'
                        % (kind, history)) from None
    if not rows:
        raise ValueError('the %s table is empty' % kind)
    for k, row in enumerate(rows):
        if len(row) != 2:
            raise ValueError('row %d of the %s table must be (time, value), got %r' % (k, kind, row))
    return [_finite(t, 'time of row %d' % k) for k, (t, _) in enumerate(rows)], [v for _, v in rows]


def readMotionFile(path):
    """(times [s], values) of a motion file: two columns (time, value) or four (time and a 3-vector),
    separated by spaces, tabs or commas; ``#`` starts a comment. ValueError names the line."""
    try:
        with open(path) as stream:
            lines = stream.readlines()
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError('cannot read the base motion file %r: %s' % (path, error)) from None
    times, values = [], []
    for number, line in enumerate(lines, 1):
        fields = line.split('#', 1)[0].replace(',', ' ').split()
        if not fields:
            continue
        try:
            numbers = [float(f) for f in fields]
        except ValueError:
            raise ValueError('%s, line %d: not numbers: %r' % (path, number, line.strip())) from None
        if len(numbers) not in (2, 4):
            raise ValueError('%s, line %d: expected 2 columns (time, value) or 4 (time, x, y, z), got %d'
                             % (path, number, len(numbers)))
        times.append(numbers[0])
        values.append(numbers[1] if len(numbers) == 2 else tuple(numbers[1:]))
    if not times:
        raise ValueError('the base motion file %r holds no rows' % path)
    return times, values


def _vectors(values, direction, scale, kind):
    """The values as 3-tuples times scale: numbers along the unit direction, 3-vectors as they are."""
    unit = None
    if direction is not None:
        d = [_finite(x, 'direction') for x in direction]
        norm = math.sqrt(sum(x * x for x in d)) if len(d) == 3 else 0.0
        if not norm > 0:
            raise ValueError('direction must be a non-zero 3-vector, got %r' % (direction,))
        unit = [x / norm for x in d]
    out = []
    for k, value in enumerate(values):
        if isinstance(value, numbers.Real) and not isinstance(value, bool):
            along = unit or (1.0, 0.0, 0.0)
            out.append(tuple(scale * float(value) * x for x in along))
            continue
        try:
            vector = [float(x) for x in value]
        except (TypeError, ValueError):
            raise TypeError('%s %d must be a number or a 3-vector, got %r' % (kind, k, value)) from None
        if len(vector) != 3 or unit is not None:
            raise ValueError('%s %d: a 3-vector value takes no direction=, and a vector has 3 components, got %r'
                             % (kind, k, value))
        out.append(tuple(scale * x for x in vector))
    return out
