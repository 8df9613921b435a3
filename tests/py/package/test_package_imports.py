"""The shape of the yade_dda package (doc/DESIGN.md, "The Python package"):
its top level holds the scene API and the subpackage `tools` the workflow
tools, each a declared list of modules; no import cycle between its modules,
counting imports inside functions and those of `tools`; `import yade_dda`
loads no tool, and no tool is in ``from yade_dda import *``."""
import ast
import os
import subprocess
import sys

import yade_dda

PACKAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'py', 'yade_dda')
COMPILED = ('_core',)   # the C++ module, built from pkg/dda: imports no Python sibling
SCENE_API = ('__init__', '_yade', 'blocks', 'colliders', 'engines', 'guards', 'hooks', 'params', 'recorder',
             'rockmass', 'saveload', 'scene', 'shaking', 'state', 'typedengines', 'views')
"""The modules of the top level of py/yade_dda: what a scene script imports."""
TOOLS = ('__init__', 'accuracy', 'compare', 'regression', 'sweep')
"""The modules of py/yade_dda/tools: the workflow tools."""
LAZY = ('compareColliders', 'accuracySweep')
"""Tools that are also names of the package (loaded on first use, out of ``import *``)."""


def modules():
    """Every module of the package by its dotted name under yade_dda ('__init__' for the package,
    'tools' for the subpackage, 'tools.compare', ...)."""
    out = []
    for folder, prefix in (('', ''), ('tools', 'tools.')):
        for name in os.listdir(os.path.join(PACKAGE, folder)):
            if name.endswith('.py'):
                stem = name[:-3]
                out.append(prefix.rstrip('.') if stem == '__init__' and prefix else prefix + stem)
    return sorted(out)


def _source(name):
    if name == '__init__':
        return os.path.join(PACKAGE, '__init__.py')
    parts = name.split('.')
    path = os.path.join(PACKAGE, *parts)
    return os.path.join(path, '__init__.py') if os.path.isdir(path) else path + '.py'


def siblings(name, known):
    """The modules of the package that `name` imports anywhere in its source (relative imports, and
    absolute ones of yade_dda; 'yade_dda' alone is __init__)."""
    with open(_source(name)) as f:
        tree = ast.parse(f.read())
    package = [] if name == '__init__' else name.split('.') if _source(name).endswith('__init__.py') \
        else name.split('.')[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split('.')
                if parts[0] == 'yade_dda':
                    while len(parts) > 1 and '.'.join(parts[1:]) not in known:
                        parts = parts[:-1]
                    found.add('.'.join(parts[1:]) or '__init__')
            continue
        if not isinstance(node, ast.ImportFrom):
            continue
        module = node.module.split('.') if node.module else []
        if node.level:
            if node.level - 1 > len(package):
                continue   # outside the package
            target = package[:len(package) - (node.level - 1)] + module
        elif module and module[0] == 'yade_dda':
            target = module[1:]
        else:
            continue
        for alias in node.names:
            if alias.name in COMPILED:
                continue
            if '.'.join(target + [alias.name]) in known:   # a module: from . import a / from .tools import b
                found.add('.'.join(target + [alias.name]))
            elif not target:                                # a name of the package: from yade_dda import O
                found.add('__init__')
            else:                                           # a name of a module: from .scene import stats
                found.add('.'.join(target))
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
    assert {'params', 'scene', 'engines', 'colliders', 'tools', 'tools.compare', 'tools.sweep'} <= set(edges)
    found = cycle(edges)
    assert found is None, 'import cycle in py/yade_dda: %s' % ' -> '.join(found)


def test_the_cycle_finder_sees_function_level_imports():
    assert cycle({'a': {'b'}, 'b': {'a'}}) == ['a', 'b', 'a']
    tree = {'a': set(), 'b': {'a'}, 'c': {'a', 'b'}}
    assert cycle(tree) is None
    edges = graph()
    assert 'params' in edges['engines']
    assert edges['tools.sweep'] == {'_yade'}   # from .._yade import utils, inside readTable
    assert {'params', 'blocks', 'scene', '_yade'} <= edges['tools.compare']


def test_the_leaf_module_imports_no_sibling():
    assert graph()['params'] == set()


def _pyModules(folder):
    return sorted(name[:-3] for name in os.listdir(folder) if name.endswith('.py'))


def test_the_top_level_holds_the_scene_api_and_tools_the_workflow_tools():
    assert _pyModules(PACKAGE) == sorted(SCENE_API), 'py/yade_dda is the scene API (SCENE_API)'
    assert _pyModules(os.path.join(PACKAGE, 'tools')) == sorted(TOOLS), 'py/yade_dda/tools holds the tools (TOOLS)'
    folders = [name for name in os.listdir(PACKAGE)
               if os.path.isdir(os.path.join(PACKAGE, name)) and name != '__pycache__']
    assert folders == ['tools']
    assert set(modules()) == set(SCENE_API) | {'tools'} | {'tools.' + name for name in TOOLS if name != '__init__'}


def test_no_scene_module_imports_a_tool():
    """Only the package's __getattr__ (LAZY) reaches into tools, inside the function; tools/__init__
    imports nothing."""
    edges = graph()
    tools = {name for name in edges if name.split('.')[0] == 'tools'}
    for name in SCENE_API:
        if name != '__init__':
            assert not edges[name] & tools, name
    assert edges['__init__'] & tools == {'tools.compare', 'tools.accuracy'}
    with open(_source('__init__')) as f:
        topLevel = ast.parse(f.read()).body
    assert not [node for node in topLevel if isinstance(node, ast.ImportFrom) and 'tools' in (node.module or '')]
    with open(_source('tools')) as f:
        assert not [node for node in ast.walk(ast.parse(f.read())) if isinstance(node, (ast.Import, ast.ImportFrom))]
    assert 'tools.sweep' not in {m for name in edges for m in edges[name]}   # run as a command, imported by no module


def _loadedAfter(code):
    """The yade_dda modules a new interpreter holds after running `code` (with the yade_dda under test)."""
    top = os.path.dirname(os.path.dirname(os.path.abspath(yade_dda.__file__)))
    env = dict(os.environ, PYTHONPATH=top + os.pathsep + os.environ.get('PYTHONPATH', ''))
    env.pop('YADE_DDA_BUILD', None)
    script = ('import sys\n' + code + '\nprint("LOADED", " ".join(sorted(m for m in sys.modules '
              'if m.split(".")[0] == "yade_dda")))\n')
    result = subprocess.run([sys.executable, '-c', script], env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    line = [text for text in result.stdout.splitlines() if text.startswith('LOADED ')][-1]
    return set(line.split()[1:])


def test_import_yade_dda_loads_no_tool():
    """In a new interpreter (this one has loaded the tools): `import yade_dda` and ``import *`` load the
    scene API and the compiled core only; a lazy name then loads its own tool, and nothing else."""
    scene = {'yade_dda'} | {'yade_dda.' + name for name in SCENE_API + COMPILED if name != '__init__'}
    loaded = _loadedAfter('import yade_dda\nfrom yade_dda import *')
    assert loaded <= scene, 'import yade_dda loads %s' % ', '.join(sorted(loaded - scene))
    assert {'yade_dda.scene', 'yade_dda.engines', 'yade_dda._core'} <= loaded
    loaded = _loadedAfter('import yade_dda\nyade_dda.compareColliders')
    assert loaded - scene == {'yade_dda.tools', 'yade_dda.tools.compare'}


def test_import_star_exports_no_tool():
    namespace = {}
    exec('from yade_dda import *', namespace)
    assert not (set(LAZY) | set(TOOLS) | {'tools'}) & set(namespace)
    assert not (set(LAZY) | set(TOOLS) | {'tools'}) & set(yade_dda.__all__)
    assert {'ddaBlock', 'DDAIntegrator', 'DESSCollider', 'Checkpoint', 'stats', 'O'} <= set(namespace)


def test_the_tools_are_modules_of_tools_and_two_are_names_of_the_package():
    import importlib
    from yade_dda import compareColliders
    from yade_dda.tools import accuracy, compare, regression, sweep
    assert [m.__name__ for m in (accuracy, compare, regression, sweep)] == \
        ['yade_dda.tools.accuracy', 'yade_dda.tools.compare', 'yade_dda.tools.regression', 'yade_dda.tools.sweep']
    assert compare.compareColliders is compareColliders is yade_dda.compareColliders
    assert accuracy.sweep is yade_dda.accuracySweep and callable(accuracy.sweep)
    assert sweep is importlib.import_module('yade_dda.tools.sweep') and callable(sweep.main) and callable(sweep.runRows)
    for name in (name for name in TOOLS if name != '__init__'):
        assert not hasattr(yade_dda, name), 'yade_dda.%s: the tools are reached through yade_dda.tools' % name


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
