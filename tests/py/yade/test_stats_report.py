"""stats() says what every key of its report is: the keys a step returns are
exactly those its docstring lists (the core's rows of
pkg/dda/solver/Statistics.def with what the package adds), in every sub-dict,
each with a unit where it has one; a key added to the report without a line
in the declaration, or declared and never reported, fails here."""
import pytest

import yade_dda
from yade_dda import O, scene as ddaScene

from helpers import box, material

GROUPS = ('time', 'cpuTime', 'energy', 'memory', 'effects')


def _reported(report):
    keys = {('', key) for key, value in report.items() if key not in GROUPS}
    for group in GROUPS:
        keys |= {(group, key) for key in report[group]}
    return keys


def test_every_reported_key_is_declared_and_every_declared_key_reported(scene):
    rock = material(O, young=1e8)
    O.bodies.append(yade_dda.ddaBlock(box((-2, -2, -1), (2, 2, 0)), material=rock, fixed=True))
    O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (1, 1, 1)), material=rock))
    O.engines = [yade_dda.DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81))]
    O.run(3, True)
    report = yade_dda.stats()
    rows = ddaScene.statisticsRows()
    declared = {(group, key) for group, key, _, _ in rows}
    assert len(declared) == len(rows), 'a key is declared twice'
    assert _reported(report) == declared, (sorted(_reported(report) - declared), sorted(declared - _reported(report)))
    for group, key, unit, doc in rows:
        assert doc and ('``%s``' % key) in yade_dda.stats.__doc__, key
        if group in ('time', 'cpuTime'):
            assert unit == 's', (group, key, unit)
        if group == 'energy':
            assert unit == 'J', key


def test_the_core_table_follows_the_declaration():
    """Every row of _core.statisticsTable() names a C++ type and a group the report has."""
    table = yade_dda._core.statisticsTable()
    assert len(table) >= 60
    for row in table:
        assert row['kind'] in ('double', 'int', 'long', 'bool'), row
        assert row['group'] in ('',) + GROUPS, row
        assert row['doc'], row
