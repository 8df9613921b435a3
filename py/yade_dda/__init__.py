"""yade-dda: three-dimensional Discontinuous Deformation Analysis in YADE.

Polyhedral blocks with 12 unknowns each (translation, rotation, strain),
advanced by Shi's implicit time scheme. A script reads like any YADE script::

    from yade_dda import *
    mat = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
    O.bodies.append(ddaBlock(vertices, material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
    O.run(1000, True)

All quantities are SI: metres, seconds, kilograms, pascals, newtons, radians.

``from yade_dda import *`` gives what a scene script uses (``__all__``). The
bench tools stay out of it and load when first asked for:
``yade_dda.compareColliders`` (yade_dda.compare), ``yade_dda.accuracySweep``
(``yade_dda.accuracy.sweep``), ``from yade_dda import regression`` and the
module ``yade_dda.sweep`` (``python3 -m yade_dda.sweep``: a yade-batch table
on Dask distributed).
"""
from ._yade import O
from ._core import __version__  # noqa: F401  (CMakeLists.txt's project version)
from .hooks import installHooks
from .blocks import ddaBlock, rigidBlock, concaveBlock, boxCorners
from .rockmass import cutRockMass
from .engines import DDAIntegrator
from .colliders import MSCCollider, DESSCollider, NBSCollider, AllPairsCollider
from .recorder import DDAVTKRecorder
from .saveload import Checkpoint, latestCheckpoint, writeCheckpoint, storeState, restoreState
from .scene import (stats, sync, block, blockOf, setVelocity, addPointLoad, addFixedPoint,
                    printStats, contacts, Ig2_DDABlock_DDABlock_DDAContact)

from . import saveload as _saveload
from .typedengines import typedEngines as _typedEngines

installHooks()
_saveload.onLoad(_typedEngines)

__all__ = ['ddaBlock', 'rigidBlock', 'concaveBlock', 'boxCorners', 'cutRockMass', 'DDAIntegrator', 'MSCCollider', 'DESSCollider', 'NBSCollider', 'AllPairsCollider',
           'Checkpoint', 'latestCheckpoint', 'DDAVTKRecorder', 'stats', 'printStats', 'sync', 'block', 'blockOf',
           'setVelocity', 'addPointLoad', 'addFixedPoint', 'contacts', 'Ig2_DDABlock_DDABlock_DDAContact', 'O']

_TOOLS = ('compare', 'accuracy', 'regression', 'compareColliders', 'accuracySweep', 'sweep')
"""Bench tools: attributes of the package, loaded on first use, out of ``import *``."""


def __getattr__(name):
    """Loads a bench tool (see _TOOLS) on first use (PEP 562). (Importing a
    submodule makes it an attribute of the package; ``from . import compare``
    would ask this function again.)"""
    if name in ('compare', 'compareColliders'):
        from .compare import compareColliders
        return compareColliders if name == 'compareColliders' else globals()['compare']
    if name in ('accuracy', 'accuracySweep'):
        from .accuracy import sweep
        return sweep if name == 'accuracySweep' else globals()['accuracy']
    if name == 'regression':
        from .regression import versions  # noqa: F401
        return globals()['regression']
    if name == 'sweep':
        from .sweep import runRows  # noqa: F401
        return globals()['sweep']
    raise AttributeError('module %r has no attribute %r' % (__name__, name))
