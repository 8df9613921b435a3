"""The narrow phase as a YADE-style functor, usable from scripts on any two DDA
blocks: structural types and gaps on placements with known answers."""
import pytest

import yade_dda
from yade_dda import O, ddaBlock

from helpers import box


def test_pair_functor_reports_types_and_gaps(scene):
    """Ig2_DDABlock_DDABlock_DDAContact on placements with known answers."""
    ig2 = yade_dda.Ig2_DDABlock_DDABlock_DDAContact()
    floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (2, 2, 0)), fixed=True))
    lifted = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0.003), (0.5, 0.5, 1.003))))
    corner = O.bodies.append(ddaBlock(box((0.5, 0.5, 1.003), (1.5, 1.5, 2.003))))  # corner on corner
    far = O.bodies.append(ddaBlock(box((10, 10, 10), (11, 11, 11))))
    face = ig2.go(lifted, floor, 0.01)
    assert face['type'] == 'FF' and len(face['contacts']) == 4
    assert all(c['kind'] == 'VF' and abs(c['gap'] - 0.003) < 1e-12 for c in face['contacts'])
    assert abs(face['separation'] - 0.003) < 1e-12
    assert ig2.go(lifted, floor, 0.002) is None  # farther than the contact distance
    vv = ig2.go(lifted, corner, 0.01)
    assert vv['type'] == 'VV' and len(vv['contacts']) == 1 and abs(vv['contacts'][0]['gap']) < 1e-12
    assert ig2.go(lifted, far, 1.0) is None
    with pytest.raises(ValueError, match='contact distance'):
        ig2.go(lifted, floor, -1)
