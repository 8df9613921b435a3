"""yade-dda: three-dimensional Discontinuous Deformation Analysis in YADE.

Polyhedral blocks with 12 unknowns each (translation, rotation, strain),
advanced by Shi's implicit time scheme. A script reads like any YADE script::

    from yade_dda import *
    mat = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
    O.bodies.append(ddaBlock(vertices, material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
    O.run(1000, True)

All quantities are SI: metres, seconds, kilograms, pascals, newtons, radians.

``from yade_dda import *`` gives what a scene script uses (``__all__``); the
modules of the package are that scene API. The workflow tools are the
subpackage ``yade_dda.tools``, which ``import yade_dda`` does not load:
``yade_dda.tools.compare`` (``compareColliders``: every collider on one set of
blocks), ``yade_dda.tools.accuracy`` (``sweep``: accuracy against time),
``yade_dda.tools.regression`` (records of yade-batch regression scenes) and
``yade_dda.tools.sweep`` (``python3 -m yade_dda.tools.sweep``: a yade-batch
table on Dask distributed). Two of them are also names of the package, loaded
when first asked for and out of ``import *``: ``yade_dda.compareColliders``
and ``yade_dda.accuracySweep`` (``yade_dda.tools.accuracy.sweep``).
"""
from ._yade import O
from ._core import __version__  # noqa: F401  (CMakeLists.txt's project version)
from .hooks import installHooks
from .blocks import ddaBlock, rigidBlock, concaveBlock, boxCorners
from .rockmass import cutRockMass
from .shaking import baseMotion, baseMotionState, baseMotionRecord
from .engines import DDAIntegrator
from .colliders import MSCCollider, DESSCollider, NBSCollider, AllPairsCollider
from .recorder import DDAVTKRecorder
from .saveload import Checkpoint, latestCheckpoint, writeCheckpoint, storeState, restoreState
from .scene import (stats, sync, block, blockOf, setVelocity, addPointLoad, addFixedPoint,
                    printStats, contacts, coupledSystem, Ig2_DDABlock_DDABlock_DDAContact)

from . import saveload as _saveload
from .typedengines import typedEngines as _typedEngines

installHooks()
_saveload.onLoad(_typedEngines)

__all__ = ['ddaBlock', 'rigidBlock', 'concaveBlock', 'boxCorners', 'cutRockMass', 'DDAIntegrator', 'MSCCollider', 'DESSCollider', 'NBSCollider', 'AllPairsCollider',
           'Checkpoint', 'latestCheckpoint', 'DDAVTKRecorder', 'stats', 'printStats', 'sync', 'block', 'blockOf',
           'setVelocity', 'addPointLoad', 'addFixedPoint', 'baseMotion', 'baseMotionState', 'baseMotionRecord', 'contacts', 'coupledSystem', 'Ig2_DDABlock_DDABlock_DDAContact', 'O']

_TOOLS = ('compareColliders', 'accuracySweep')
"""Tools of yade_dda.tools that are also names of the package: loaded on first use, out of ``import *``."""


def __getattr__(name):
    """Loads a tool named in _TOOLS from yade_dda.tools on first use (PEP 562)."""
    if name == 'compareColliders':
        from .tools.compare import compareColliders
        return compareColliders
    if name == 'accuracySweep':
        from .tools.accuracy import sweep
        return sweep
    raise AttributeError('module %r has no attribute %r' % (__name__, name))
