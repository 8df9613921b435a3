# -*- coding: utf-8 -*-
"""Wu et al. (2014), Section 5.3 / Fig. 16: single block slide.

201 blocks: 200 fixed 10 x 1 x 1 m blocks (long along x) approximating a
curved surface, and one free block sliding down it without friction.
E = 4 MPa, nu = 0.25, rho = 2800 kg/m^3; largest time step 0.001 s,
largest step displacement 0.01 m. Fixed-fixed pairs are never searched.

Reconstructed (Fig. 16 is missing; see ``scenes.single_block_slide``): a
cylindrical trough along x, 2 rows (x in [-10, 0] and [0, 10]) of 100
blocks whose top faces are 1 m chords of a circle of radius 47.75 m spanning
120 degrees (rims 23.9 m above the bottom); the free block, 2 x 1.2 x 1 m,
straddles the joint between the rows and starts at rest 50 degrees up one
side, 10 mm above the surface.

Run headless (runs and checks, exit status 1 on a failed check):

    PYTHONPATH=/work/main/build/py yade -n -x examples/paper/single_block_slide.py --steps 2000

or in the GUI with ``yade examples/paper/single_block_slide.py``. Parameters:
``steps`` (20000); also from a yade-batch table or DDA_STEPS.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith('.py')
                                                   else __file__)))
from yade_dda import *          # noqa: E402,F401,F403
import paper_scenes as scenes     # noqa: E402
import paperscript              # noqa: E402

p = paperscript.readParams(steps=20000, collider='MSC')

O.reset()
blocks, mat = scenes.single_block_slide()
ids = paperscript.build(blocks, mat)
O.engines = paperscript.engines(p['collider'])
paperscript.run('single_block_slide', ids, blocks, p['steps'])
