"""The C++ core's layers only look down (doc/DESIGN.md, "Source layout and layers").

LAYERS below is the one definition of the layer order. Each entry is
(rank, name, folders under pkg/): a file may include headers of its own layer
and of layers of lower rank; two layers of equal rank are siblings and include
nothing of each other (the broad phase proposes pairs, the narrow phase
decides; neither knows the other). Every folder under pkg/ that holds sources
must be listed, so a new folder is placed in the order when it is made.

Includes are read from `#include "..."` lines, resolved as the compiler does
(next to the including file first, then from pkg/); system and library
headers (<...>) are not checked. The Python package (py/yade_dda) is the layer
above the binding and includes no C++ header.
"""
import os
import re

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

LAYERS = [
    (0, 'core', ['dda/core']),          # basic types, errors, serialization, heap accounting
    (1, 'geometry', ['dda/geometry']),  # convex polyhedra, mass properties, sub-units
    (2, 'block', ['dda/block']),        # a block: shape, displacement function, material
    (3, 'narrow phase', ['dda/contact']),  # pair detection, distances, stencils, contact history
    (3, 'broad phase', ['dda/collider']),  # candidate pairs (AllPairs, DESS, NBS, MSC)
    (4, 'solver', ['dda/solver']),      # contact law, equations, open-close iteration, World
    (5, 'binding', ['py']),             # the Boost.Python module yade_dda._core
]

INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.M)
SOURCE_SUFFIXES = ('.hpp', '.cpp', '.h', '.cc')


def layer_of(path, pkg):
    """(rank, name) of the file at `path` (absolute), or None when no layer holds it."""
    relative = os.path.relpath(path, pkg).replace(os.sep, '/')
    for rank, name, folders in LAYERS:
        if any(relative == f or relative.startswith(f + '/') for f in folders):
            return rank, name
    return None


def resolve(header, including, pkg):
    """The file an `#include "header"` in `including` names (next to it first, then pkg/), or None."""
    for base in (os.path.dirname(including), pkg):
        candidate = os.path.normpath(os.path.join(base, header))
        if os.path.isfile(candidate):
            return candidate
    return None


def violations(pkg):
    """Lines 'file:line: text' for every include that looks up or sideways, or is unplaced."""
    found = []
    for folder, _, files in os.walk(pkg):
        for file in sorted(files):
            if not file.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(folder, file)
            name = os.path.relpath(path, pkg)
            own = layer_of(path, pkg)
            if own is None:
                found.append('%s: in no layer (add its folder to LAYERS in tests/py/package/test_layers.py)' % name)
                continue
            text = open(path, encoding='utf-8').read()
            for match in INCLUDE.finditer(text):
                line = text.count('\n', 0, match.start()) + 1
                target = resolve(match.group(1), path, pkg)
                if target is None:
                    found.append('%s:%d: "%s" not found' % (name, line, match.group(1)))
                    continue
                theirs = layer_of(target, pkg)
                if theirs is None:
                    found.append('%s:%d: "%s" is in no layer' % (name, line, match.group(1)))
                elif theirs[0] > own[0] or (theirs[0] == own[0] and theirs[1] != own[1]):
                    found.append('%s:%d: %s includes "%s" of %s (rank %d above or beside its %d)'
                                 % (name, line, own[1], match.group(1), theirs[1], theirs[0], own[0]))
    return found


def test_core_includes_only_look_down():
    assert violations(os.path.join(REPO, 'pkg')) == []


def test_the_check_sees_an_upward_and_a_sideways_include(tmp_path):
    """The check itself: a geometry header including the solver, and the broad
    phase including the narrow phase, are reported; a downward include is not."""
    for folder, text in [('dda/core', ''), ('dda/solver', ''), ('dda/contact', ''),
                         ('dda/geometry', '#include "dda/solver/X.hpp"\n#include "dda/core/X.hpp"\n'),
                         ('dda/collider', '#include "dda/contact/X.hpp"\n')]:
        os.makedirs(tmp_path / folder)
        (tmp_path / folder / 'X.hpp').write_text(text)
    found = violations(str(tmp_path))
    assert len(found) == 2, found
    assert 'geometry includes "dda/solver/X.hpp" of solver' in found[0] + found[1]
    assert 'broad phase includes "dda/contact/X.hpp" of narrow phase' in found[0] + found[1]
