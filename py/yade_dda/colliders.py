"""Collider engines of yade-dda: the broad phase of DDA contact detection as
an entry of ``O.engines``, in the place YADE's ``InsertionSortCollider`` takes.

Each engine is a ``PyRunner`` whose command, run every step before
``DDAIntegrator``, tells the DDA scene which of the core's broad phases to
use this step (a dictionary write, about as cheap as an empty PyRunner). The
broad phase itself runs inside ``DDAIntegrator``'s single call into the core,
so selecting it costs nothing more. Without a collider engine the integrator
uses its own ``collider`` parameter.

All strategies produce the same candidate pairs within the contact distance
d0 and therefore the same contacts and the same trajectories; they differ in
how much work the search takes (``stats()['time']['broadPhase']`` and
``['narrowPhase']``, ``stats()['candidatePairs']``). The command string
carries every parameter, so an engine that comes back from
``O.save()``/``O.load()`` (as a plain PyRunner) is made again from it (typedengines.py).
"""
from ._yade import O, wrapper
from . import _core
from . import guards as _guards
from . import params as _settings
from . import scene as _scene
from .guards import COLLIDER_COMMAND
from .params import Engine, Parameter, finite, initEngine, keywordsOnly


def _select(name, **parameters):
    """Selects the core broad phase `name` for this step of the current DDA scene.

    Called by the collider engines' commands; DDAIntegrator's step of the
    same iteration uses it instead of its own ``collider`` parameter.
    """
    if name not in _settings.COLLIDERS:
        raise ValueError('collider %r is not available in this build (available: %s)'
                         % (name, ', '.join(_settings.COLLIDERS)))
    scene = _scene.current()
    previous = scene.colliderChoice
    if previous is None or previous[0] != O.iter - 1:
        _guards.checkColliderOrder(O.engines)   # first call, or the engine list may have changed
    # (iteration, strategy, its parameters): honoured by integratorStep at this iteration only,
    # so removing the collider engine returns the choice to DDAIntegrator.collider.
    scene.colliderChoice = (O.iter, name, parameters)


class _ColliderEngine(Engine, wrapper.PyRunner):
    """Common part: typed parameters kept in the command string, every step from the first."""

    _strategy = None
    _names = ()
    _periodAdvice = ('; it chooses the broad phase for the iteration it runs in, and DESS and MSC already reuse '
                     'their candidate pairs while no block left its allowance (DDAIntegrator.reuseCandidatePairs)')

    def __init__(self, *args, label='', **params):
        keywordsOnly(type(self), args)
        wrapper.PyRunner.__init__(self)
        initEngine(self, label, params)

    @property
    def strategy(self):
        """Name of the core broad phase this engine selects."""
        return self._strategy

    def _updateCommand(self):
        args = ''.join(', %s=%r' % (name, self._params[name]) for name in self._names)
        self._setYade('command', '%s%r%s)' % (COLLIDER_COMMAND, self._strategy, args))


class DESSCollider(_ColliderEngine):
    """DESS broad phase for DDA blocks (replaces InsertionSortCollider).

    Double-ended spatial sorting (Perkins & Williams 2001): each block's
    axis-aligned box, widened by the contact distance d0 [m] on every side, is
    sorted by its lower end along the axis on which the blocks spread most and
    swept up to its upper end; pairs whose boxes overlap on all three axes
    become candidates for the narrow phase. O(n log n) per step; fixed-fixed
    pairs are never reported. The default strategy.

    Parameters: none besides ``label`` (d0 comes from ``DDAIntegrator``).

    Example::

        O.engines = [DESSCollider(label='collider'), DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
        O.run(1000, True)
    """

    _strategy = 'DESS'


class NBSCollider(_ColliderEngine):
    """NBS broad phase for DDA blocks (replaces InsertionSortCollider).

    No Binary Search (Munjiza & Andrews 1998): each block is covered by one
    bounding sphere (about the centre of its box, radius to the farthest
    vertex plus d0 [m]) binned into a regular grid of cells one largest sphere
    diameter wide; overlapping spheres in the same or neighbouring cells
    become candidates. About O(n) per step, but a slender block's sphere is
    large and meets many blocks it never touches.

    Parameters: none besides ``label`` (d0 comes from ``DDAIntegrator``).

    Example::

        O.engines = [NBSCollider(label='collider'), DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
        O.run(1000, True)
    """

    _strategy = 'NBS'


class AllPairsCollider(_ColliderEngine):
    """Every pair of DDA blocks (except fixed-fixed) as a candidate: the reference.

    O(n^2) per step; the correctness oracle the other strategies are tested
    against (they must find exactly its contacts). Use for small scenes and
    for checking.

    Parameters: none besides ``label``.

    Example::

        O.engines = [AllPairsCollider(label='collider'), DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
        O.run(100, True)
    """

    _strategy = 'AllPairs'


def _criticalLength(value):
    return finite('criticalLength', value, 0, unit=' m')


def _segments(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or int(value) != value:
        raise ValueError('segments must be an integer >= 1, got %r' % (value,))
    if not 1 <= value <= _core.mscMaxSegments:
        raise ValueError('segments must be an integer in [1, %d], got %r' % (_core.mscMaxSegments, value))
    return int(value)


class MSCCollider(_ColliderEngine):
    """Multi-shell cover broad phase for DDA blocks (Wu et al. 2014, Sec. 3;
    replaces InsertionSortCollider).

    Edges longer than the critical length lambda [m] are divided into N
    segments; the vertices and division points of a block are grouped, each
    group covered by an axis-aligned shell (widened by d0) linked to its
    vertices, edges and faces. Only overlapping shells of two blocks are
    tested, and only their linked sub-units meet in the narrow phase, so a
    slender or inclined block no longer drags in every block near its single
    box or sphere. Reports ``shellPairs`` and ``subUnitPairs`` in ``stats()``.

    Parameters:

    - ``criticalLength`` [m]: lambda, edges longer than this are divided;
      0 (default) = 3 x the block size (cube root of its volume).
    - ``segments``: N, the number of segments a long edge is divided into
      (default 3, >= 1).

    Example::

        O.engines = [MSCCollider(criticalLength=0, segments=3, label='collider'), DDAIntegrator(dt=1e-3)]
        O.run(1000, True)
    """

    _strategy = 'MSC'
    _names = ('criticalLength', 'segments')
    criticalLength = Parameter(0.0, _criticalLength, 'lambda [m]: edges longer than this are divided; 0 = 3 x block size')
    segments = Parameter(3, _segments, 'N: segments per divided edge')

    def __init__(self, *args, label='', **params):
        keywordsOnly(type(self), args)
        _ColliderEngine.__init__(self, label=label, **params)


def available():
    """Names of the broad phases this build of the core provides, e.g. ('DESS', 'NBS', 'AllPairs')."""
    return tuple(_settings.COLLIDERS)


ENGINES = {engine._strategy: engine for engine in (MSCCollider, DESSCollider, NBSCollider, AllPairsCollider)}
"""Collider engine class of each strategy name."""
