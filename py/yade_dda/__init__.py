"""yade-dda: three-dimensional Discontinuous Deformation Analysis in YADE.

Polyhedral blocks with 12 unknowns each (translation, rotation, strain),
advanced by Shi's implicit time scheme. A script reads like any YADE script::

    from yade_dda import *
    mat = O.materials.append(PolyhedraMat(young=4e6, poisson=0.25, density=2600))
    O.bodies.append(ddaBlock(vertices, material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), label='dda')]
    O.run(1000, True)

All quantities are SI: metres, seconds, kilograms, pascals, newtons, radians.
"""
from . import _yade
from ._yade import O
from . import guards  # noqa: F401  (O.bodies.erase/clear guards for DDA blocks)
from .blocks import ddaBlock, rigidBlock
from .engines import DDAIntegrator
from .colliders import MSCCollider, DESSCollider, NBSCollider, AllPairsCollider
from .compare import compareColliders
from .saveload import Checkpoint, latestCheckpoint, writeCheckpoint, storeState, restoreState
from .accuracy import sweep
from .scene import (stats, sync, block, blockOf, setVelocity, addPointLoad, addFixedPoint,
                    printStats, contacts, Ig2_DDABlock_DDABlock_DDAContact)

__all__ = ['ddaBlock', 'rigidBlock', 'DDAIntegrator', 'MSCCollider', 'DESSCollider', 'NBSCollider', 'AllPairsCollider',
           'compareColliders', 'Checkpoint', 'latestCheckpoint', 'sweep', 'stats', 'printStats', 'sync', 'block',
           'blockOf',
           'setVelocity', 'addPointLoad', 'addFixedPoint', 'contacts', 'Ig2_DDABlock_DDABlock_DDAContact', 'O']
