"""yade_dda.__version__ is CMakeLists.txt's project version, and results record it."""
import os
import re

import yade_dda
from yade_dda.tools import regression

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def test_version_is_the_projects():
    text = open(os.path.join(REPO, 'CMakeLists.txt'), encoding='utf-8').read()
    declared = re.search(r'project\(yade_dda VERSION (\d+\.\d+\.\d+)', text).group(1)
    assert yade_dda.__version__ == declared


def test_regression_records_carry_the_version():
    assert regression.versions()['yade_dda'] == yade_dda.__version__
