"""pytest drives YADE from Debian's /usr/bin/python3: yade_dda boots YADE on import.

One process holds one YADE scene (O); the `scene` fixture resets it before each
test. Set YADE_DDA_BUILD=<build dir>/py to test a build tree instead of the
installed package.
"""
import os
import sys

import pytest

if os.environ.get('YADE_DDA_BUILD'):
    sys.path.insert(0, os.environ['YADE_DDA_BUILD'])

import yade_dda  # noqa: E402
from yade_dda import O  # noqa: E402


@pytest.fixture
def scene():
    O.reset()
    yield O
    O.reset()
