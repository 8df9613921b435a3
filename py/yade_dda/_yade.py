"""Makes YADE importable from plain Debian Python and returns its pieces.

Inside ``yade script.py`` YADE is already loaded. From ``/usr/bin/python3``,
YADE's Python package lives outside ``sys.path``; this puts it first and boots
it, so pytest and batch tools can drive YADE directly.
"""
import os
import sys

YADE_PY_DIRS = ('/usr/lib/x86_64-linux-gnu/yade-double/py', '/usr/lib/x86_64-linux-gnu/yade/py')

if 'yade' not in sys.modules:
    for _dir in YADE_PY_DIRS:
        if os.path.isdir(os.path.join(_dir, 'yade')):
            if _dir not in sys.path:
                sys.path.insert(0, _dir)
            break

import yade  # noqa: E402  (boots YADE; registers its math types with Boost.Python)
from yade import wrapper  # noqa: E402
from yade import utils  # noqa: E402

O = wrapper.Omega()
