# -*- coding: utf-8 -*-
"""Wu et al. (2014), Section 5.2 / Fig. 13: blocks slide.

23 blocks: 14 fixed (a bed and a side wall) and 9 sliding without initial
velocity or friction down a chute whose blocks all have their main axis at
60, 135 and 120 degrees to +x, +y, +z (30 degrees below horizontal).
E = 10 MPa, nu = 0.25, rho = 2600 kg/m^3; largest time step 0.001 s,
largest step displacement 0.01 m.

Reconstructed (Fig. 13 is missing; see ``scenes.slanted_slide``): the OCR'd
text says 11 fixed + 9 sliding = 20 blocks but 23 in total (and 3 + 8 + 12 =
23 MSC shell groups), so 14 are fixed and 9 slide; its angles 50, 135, 120
degrees are not a direction (cos^2 sum 1.163), 60, 135, 120 degrees are
(sum exactly 1). Bed: 5 x 2 blocks 8 x 3 x 1 m; wall: 4 blocks 10 x 1 x 5 m;
sliding: a 3 x 3 stack of 4 x 1 x 1 m blocks against the wall; the bed is
tilted 15 degrees across the chute towards the wall.

Run headless (runs and checks, exit status 1 on a failed check):

    PYTHONPATH=/work/main/build/py yade -n -x examples/paper/slanted_slide.py --steps 1000

or in the GUI with ``yade examples/paper/slanted_slide.py``. Parameters:
``steps`` (6000); also from a yade-batch table or DDA_STEPS.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith('.py')
                                                   else __file__)))
from yade_dda import *          # noqa: E402,F401,F403
import paper_scenes as scenes     # noqa: E402
import paperscript              # noqa: E402

p = paperscript.readParams(steps=6000, collider='MSC')

O.reset()
blocks, mat = scenes.slanted_slide()
ids = paperscript.build(blocks, mat)
O.engines = paperscript.engines(p['collider'])
paperscript.run('slanted_slide', ids, blocks, p['steps'])
