"""The settings are declared once (pkg/dda/solver/Settings.def): DDAIntegrator
offers every core setting with the core's default, passes each to the core,
and doc/parameters.md is what tools/gen_docs.py makes of them now."""
import ast
import importlib.util
import os

import pytest

from yade_dda import _core, engines, params
from yade_dda import DDAIntegrator

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def _genDocs():
    spec = importlib.util.spec_from_file_location('gen_docs', os.path.join(REPO, 'tools', 'gen_docs.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_parameter_reference_is_current():
    with open(os.path.join(REPO, 'doc', 'parameters.md')) as f:
        assert f.read() == _genDocs().render(), 'doc/parameters.md is stale: run make docs'


def test_every_core_setting_is_a_parameter_of_the_integrator():
    members = {name for name in dir(_core.IntegratorSettings) if not name.startswith('_')}
    rows = {row['member']: row for row in params.SETTINGS if row['member'] is not None}
    assert set(rows) == members
    core = _core.IntegratorSettings()
    for member, row in rows.items():
        value = getattr(core, member)
        assert (tuple(value) if row['kind'] == 'vector' else value) == row['default'] == getattr(DDAIntegrator(),
                                                                                                 row['name'])


@pytest.mark.parametrize('name, value', [('timeStepSafety', 0.8), ('minTimeStepShrink', 0.2),
                                         ('maxTimeStepShrink', 0.8), ('contactDistanceFactor', 3.0),
                                         ('dt', 2e-3), ('threads', 2), ('startFromRest', False)])
def test_a_parameter_reaches_the_core(name, value):
    engine = DDAIntegrator(**{name: value})
    text = engine.command[engine.command.index('(') + 1:-1]
    _, settings = engines._parse(ast.literal_eval(text))
    member = next(row['member'] for row in params.SETTINGS if row['name'] == name)
    assert getattr(settings, member) == value


def test_the_docstring_lists_every_parameter():
    for row in params.SETTINGS:
        assert '``%s``' % row['name'] in DDAIntegrator.__doc__
        assert getattr(DDAIntegrator, row['name']).__doc__ == row['doc']
