# -*- coding: utf-8 -*-
"""Wu et al. (2014), Section 5.1 / Fig. 10: hexahedra drop.

70 blocks: 68 free slender hexahedra (length x 1 x 1 m, length = 20, 40 or
60 m: the paper's three slenderness cases) dropped onto two fixed pentahedra
(triangular prisms). E = 4 MPa, nu = 0.25, rho = 2600 kg/m^3, frictionless;
largest time step 0.001 s, largest step displacement 0.01 m.

Fig. 10 is missing from our copy of the paper, so the arrangement is ours
(see ``scenes.hexahedra_drop``): 4 layers of 17 parallel blocks, alternate
layers crossing (lowest along x), each layer spread over a length x length
square, 0.2 m apart, above a V-shaped trough formed by the two fixed
prisms (faces at 25 degrees, axis along y). The paper fixes each prism by
four nodes; here they are fixed blocks.

Run headless (runs and checks, exit status 1 on a failed check):

    PYTHONPATH=/work/main/build/py yade -n -x examples/paper/hexahedra_drop.py --length 40 --steps 2000

or in the GUI with ``yade examples/paper/hexahedra_drop.py`` (runs without
blocking and prints the summary at the last step). Parameters: ``length``
[m] (20), ``steps`` (600); also from a yade-batch table or DDA_LENGTH /
DDA_STEPS.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith('.py')
                                                   else __file__)))
from yade_dda import *          # noqa: E402,F401,F403
import paper_scenes as scenes     # noqa: E402
import paperscript              # noqa: E402

p = paperscript.readParams(length=20.0, steps=600, collider='MSC')

O.reset()
blocks, mat = scenes.hexahedra_drop(length=p['length'])
ids = paperscript.build(blocks, mat)
O.engines = paperscript.engines(p['collider'])
paperscript.run('hexahedra_drop (L = %g m)' % p['length'], ids, blocks, p['steps'])
