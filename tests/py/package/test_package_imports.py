"""The shape of the yade_dda package (doc/DESIGN.md, "The Python package"):
no import cycle between its modules, counting imports inside functions too,
and no bench tool in ``from yade_dda import *``."""
import ast
import os

import yade_dda

PACKAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'py', 'yade_dda')
COMPILED = ('_core',)   # the C++ module, built from pkg/dda: imports no Python sibling
TOOLS = ('compare', 'accuracy', 'regression', 'compareColliders', 'accuracySweep', 'sweep')


def modules():
    return sorted(name[:-3] for name in os.listdir(PACKAGE) if name.endswith('.py'))


def siblings(name, known):
    """The sibling modules `name` imports anywhere in its source (relative
    imports, and absolute ones of yade_dda; 'yade_dda' alone is __init__)."""
    with open(os.path.join(PACKAGE, name + '.py')) as f:
        tree = ast.parse(f.read())
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split('.')
                if parts[0] == 'yade_dda':
                    found.add(parts[1] if len(parts) > 1 else '__init__')
        elif isinstance(node, ast.ImportFrom):
            if node.level > 1:
                continue   # outside the package
            if node.level == 1:
                base = node.module
            elif node.module and node.module.split('.')[0] == 'yade_dda':
                base = node.module.split('.')[1] if '.' in node.module else None
            else:
                continue
            if base:
                found.add(base.split('.')[0])
            else:   # from . import a, b / from yade_dda import a, b
                for alias in node.names:
                    if alias.name not in COMPILED:
                        found.add(alias.name if alias.name in known else '__init__')
    return {module for module in found if module in known and module != name}


def graph():
    known = set(modules())
    return {name: siblings(name, known) for name in known}


def cycle(edges):
    """One import cycle as a list of modules, or None."""
    state = {}

    def visit(node, path):
        state[node] = 'open'
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 'open':
                return path[path.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt, path + [nxt])
                if found:
                    return found
        state[node] = 'done'
        return None

    for start in sorted(edges):
        if start not in state:
            found = visit(start, [start])
            if found:
                return found
    return None


def test_the_package_has_no_import_cycle():
    edges = graph()
    assert {'params', 'scene', 'engines', 'colliders'} <= set(edges)
    found = cycle(edges)
    assert found is None, 'import cycle in py/yade_dda: %s' % ' -> '.join(found)


def test_the_cycle_finder_sees_function_level_imports():
    assert cycle({'a': {'b'}, 'b': {'a'}}) == ['a', 'b', 'a']
    tree = {'a': set(), 'b': {'a'}, 'c': {'a', 'b'}}
    assert cycle(tree) is None
    assert 'params' in graph()['engines']


def test_the_leaf_module_imports_no_sibling():
    assert graph()['params'] == set()


def test_import_star_exports_no_bench_tool():
    namespace = {}
    exec('from yade_dda import *', namespace)
    assert not set(TOOLS) & set(namespace)
    assert not set(TOOLS) & set(yade_dda.__all__)
    assert {'ddaBlock', 'DDAIntegrator', 'DESSCollider', 'Checkpoint', 'stats', 'O'} <= set(namespace)


def test_bench_tools_stay_importable():
    from yade_dda import regression, compareColliders
    assert callable(yade_dda.accuracySweep) and callable(compareColliders)
    assert yade_dda.compare.compareColliders is compareColliders
    assert yade_dda.accuracy.sweep is yade_dda.accuracySweep
    assert regression.__name__ == 'yade_dda.regression'


def test_the_sweep_module_wins_over_the_accuracy_sweep():
    """`yade_dda.sweep` is the module of `python3 -m yade_dda.sweep` (Dask), however it is
    reached; the accuracy tool is `yade_dda.accuracy.sweep` (= `yade_dda.accuracySweep`)."""
    import importlib
    import types
    from yade_dda import sweep
    assert isinstance(sweep, types.ModuleType) and sweep.__name__ == 'yade_dda.sweep'
    assert yade_dda.sweep is sweep is importlib.import_module('yade_dda.sweep')
    assert callable(sweep.main) and callable(sweep.runRows)
    assert yade_dda.accuracySweep is not sweep


def test_install_hooks_is_idempotent():
    from yade import wrapper
    methods = [(wrapper.BodyContainer, name) for name in ('erase', 'clear', 'replace')]
    methods += [(wrapper.Omega, name) for name in ('save', 'saveTmp', 'load', 'loadTmp', 'reload')]
    originals = [getattr(cls, name)._yadeDDA for cls, name in methods]
    yade_dda.installHooks()
    yade_dda.installHooks()
    for (cls, name), original in zip(methods, originals):
        assert getattr(cls, name)._yadeDDA is original, name
        assert not hasattr(original, '_yadeDDA'), name
