"""Every mutation patch (tests/mutations/*.patch, doc/testing.md "Mutation checks") still applies to
the sources: a patch whose target moved would make `make mutations` fail to apply it, and the
mechanism it guards would go unchecked (two patches went stale that way when the solver's
contacts took their bodies)."""
import glob
import os
import subprocess

import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..', '..'))
PATCHES = sorted(glob.glob(os.path.join(REPO, 'tests', 'mutations', '*.patch')))


def test_there_are_mutation_patches():
    assert len(PATCHES) >= 20


@pytest.mark.parametrize('patch', PATCHES, ids=[os.path.basename(p) for p in PATCHES])
def test_the_patch_applies(patch):
    done = subprocess.run(['git', 'apply', '--check', patch], cwd=REPO, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    assert done.returncode == 0, '%s no longer applies: %s' % (os.path.basename(patch), done.stdout)
