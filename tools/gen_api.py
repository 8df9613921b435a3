"""Writes doc/api.md, the reference of yade_dda's public Python names, from
their docstrings: every name of ``yade_dda.__all__``, the objects they return
that a script handles (BlockView, ContactView, RockMass, ...), and the
workflow tools of the subpackage yade_dda.tools (compareColliders,
accuracySweep, the module regression, ``python3 -m yade_dda.tools.sweep``).

Run:  make docs
      YADE_DDA_BUILD=build/py /usr/bin/python3 tools/gen_api.py [--check]
--check writes nothing and exits 1 when doc/api.md is stale.
tests/py/package/test_api_reference.py makes the same check in the test run.

The page is Markdown, as the rest of doc/, read on the forge: no Sphinx. The
docstrings' reStructuredText is rendered simply: paragraphs as they are,
``literal`` as `literal`, ``:param x:`` fields as a list, a block after ``::``
(or an indented block) as a code block. The output depends only on the
docstrings and the build (no dates, no addresses, a fixed order).
"""
import argparse
import ast
import contextlib
import inspect
import io
import os
import re
import sys
import textwrap

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.path.join(REPO, 'doc', 'api.md')
WIDTH = 100
"""Longest line of a signature before it is wrapped, and the width of the sweep's --help."""

GROUPS = (
    ('Blocks', ('yade_dda.blocks', 'yade_dda.rockmass'),
     'Making DDA blocks (YADE bodies with a `Polyhedra` shape backed by the DDA core), and rock masses cut by '
     'joint sets.'),
    ('Engines', ('yade_dda.engines', 'yade_dda.colliders', 'yade_dda.recorder'),
     'Entries of `O.engines`. Each is a `PyRunner` subclass whose command carries every parameter, so it comes '
     'back from `O.save`/`O.load`; keyword arguments only, as every YADE engine takes them.'),
    ('Scene functions', ('yade_dda.scene', 'yade.wrapper'),
     'The DDA state of the current YADE scene: diagnostics, block views, velocities, loads, contacts.'),
    ('Ground shaking', ('yade_dda.shaking',),
     'Prescribed motion of fixed blocks: an acceleration or velocity history (a table, a function or a '
     'recorded accelerogram) that the contacts carry to the moving blocks.'),
    ('Save and load', ('yade_dda.saveload',),
     "YADE's own `O.save`/`O.load` carry the DDA state (see `O` above); these add crash-safe checkpoints."),
)
"""(title, modules whose names it holds, introduction): a name of __all__ goes to the group of its module."""

RETURNED = {
    'cutRockMass': (('RockMass', 'What `cutRockMass()` returns.'),
                    ('RockBlock', 'The items of a `RockMass` (and of its `slivers`).'),
                    ('RockPlane', 'The items of `RockMass.planes`.')),
    'block': (('BlockView', 'What `block()` returns for a convex block.'),
              ('ConcaveBlockView', 'What `block()` returns for a concave block (`concaveBlock`), a subclass of '
                                   '`BlockView`.')),
    'contacts': (('ContactView', 'The items of the list `contacts()` returns.'),),
}
"""(class, what it is) of the objects a function returns, documented after it (the classes are looked up in
the function's module; a script does not make them)."""


# ------------------------------------------------------------------ Markdown of a docstring

_FIELD = re.compile(r'^:(param|parameter|arg|returns?|raises?)\b\s*([^:]*):\s?(.*)$')
_CODE = re.compile(r'``(.+?)``|`([^`\n]+)`', re.S)
_LINE_START = re.compile(r'^(\d+[.)](?: |$)|[+#](?: |$)|>|=+$|-+$)')


def _indent(line):
    return len(line) - len(line.lstrip(' '))


def _codeSpan(text):
    text = ' '.join(text.split('\n'))
    fence = '``' if '`' in text else '`'
    pad = ' ' if fence == '``' or text.startswith('`') or text.endswith('`') else ''
    return '%s%s%s%s%s' % (fence, pad, text, pad, fence)


def _escape(text):
    """Prose for Markdown: the characters that would start emphasis or an HTML tag, escaped."""
    text = text.replace('\\', '\\\\').replace('*', '\\*').replace('<', '\\<')
    return re.sub(r'(?<![A-Za-z0-9])_|_(?![A-Za-z0-9])', r'\\_', text)


def inline(text):
    """reST inline markup to Markdown: ``literal`` and `interpreted` as code spans, the rest escaped."""
    out, position = [], 0
    for match in _CODE.finditer(text):
        out.append(_escape(text[position:match.start()]))
        out.append(_codeSpan(match.group(1) if match.group(1) is not None else match.group(2)))
        position = match.end()
    out.append(_escape(text[position:]))
    lines = ''.join(out).split('\n')
    return '\n'.join('\\' + line if _LINE_START.match(line) else line for line in lines)


def _field(line):
    """':param a, b: text' -> '- `a`, `b`: text'; ':returns: text' -> '- Returns: text'."""
    match = _FIELD.match(line)
    if not match:
        return None
    kind, names, text = match.groups()
    if kind.startswith('return'):
        return '- Returns: ' + text
    if kind.startswith('raise'):
        return '- Raises %s: %s' % (_codeSpan(names.strip()), text)
    return '- %s: %s' % (', '.join(_codeSpan(n.strip()) for n in names.split(',')), text)


def _itemLines(paragraph):
    """Markdown lines of a paragraph of list items and fields: an item's later lines under its text, and
    an item indented in the docstring (a list inside a field) nested under the item before it."""
    items = []
    for line in paragraph:
        text = line.strip()
        openField = items and items[-1][1][0].startswith(':') and _field(' '.join(items[-1][1])) is None
        if text.startswith(('- ', '* ', ':')) and not openField or not items:
            items.append((_indent(line), [text]))
        elif openField and len(items[-1][1]) == 1 and _field(items[-1][1][0]) is None:
            items[-1][1][0] += ' ' + text   # a field whose names run over two lines
        else:
            items[-1][1].append(text)
    out = []
    for indent, texts in items:
        first = texts[0]
        first = _field(first) or ('- ' + first[2:] if first.startswith('* ') else first)
        lines = inline('\n'.join([first] + texts[1:])).split('\n')
        prefix = '  ' if indent > 0 else ''
        out += [prefix + ('' if k == 0 else '  ') + line for k, line in enumerate(lines)]
    return out


def _fence(lines, language=''):
    """A fenced code block of `lines` (dedented, without blank lines at either end)."""
    while lines and not lines[-1].strip():
        lines = lines[:-1]
    while lines and not lines[0].strip():
        lines = lines[1:]
    cut = min((_indent(l) for l in lines if l.strip()), default=0)
    body = [l[cut:].rstrip() for l in lines]
    fence = '~~~' if any(l.lstrip().startswith('```') for l in body) else '```'
    return '\n'.join([fence + language] + body + [fence])


def markdown(doc):
    """A docstring (reStructuredText as the package writes it) as Markdown blocks joined by blank lines.

    Paragraphs keep their lines; ``:param x:`` fields become list items; a paragraph ending in ``::``
    is followed by a code block (the ``::`` becomes ':' or goes); an indented paragraph is a list
    item's next paragraph when it follows one, else (a reST block quote) a code block."""
    lines = inspect.cleandoc(doc).split('\n') if doc else []
    blocks, i, inItem = [], 0, False
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        start = i
        while i < len(lines) and lines[i].strip():
            i += 1
        paragraph = lines[start:i]
        base = _indent(paragraph[0])
        isItem = paragraph[0].strip().startswith(('- ', '* ', ':'))
        if base > 0 and not isItem and not inItem:
            blocks.append(_fence(paragraph))
            continue
        literal = paragraph[-1].rstrip().endswith('::')
        if literal:
            last = paragraph[-1].rstrip()[:-2]
            paragraph = paragraph[:-1] + ([last.rstrip() + ':'] if last.strip() and not last.endswith(' ') else
                                          [last.rstrip()] if last.strip() else [])
        if isItem:
            text = _itemLines(paragraph)
        else:
            text = inline('\n'.join(l.strip() for l in paragraph)).split('\n') if paragraph else []
            if inItem and base > 0:   # a later paragraph of the item before
                text = ['  ' + l for l in text]
        inItem = isItem or (inItem and base > 0)
        if text:
            blocks.append('\n'.join(text))
        if literal:
            start = i
            while i < len(lines) and (not lines[i].strip() or _indent(lines[i]) > base):
                i += 1
            if any(l.strip() for l in lines[start:i]):
                blocks.append(_fence(lines[start:i], 'python'))
    return '\n\n'.join(blocks)


# ------------------------------------------------------------------ signatures

def _splitTopLevel(text):
    """The comma-separated items of a parameter list, commas inside brackets and quotes kept."""
    items, depth, quote, current = [], 0, None, ''
    for char in text:
        if quote:
            quote = None if char == quote and not current.endswith('\\') else quote
        elif char in '\'"':
            quote = char
        elif char in '([{':
            depth += 1
        elif char in ')]}':
            depth -= 1
        elif char == ',' and depth == 0:
            items.append(current.strip())
            current = ''
            continue
        current += char
    if current.strip():
        items.append(current.strip())
    return items


def callText(name, parameters):
    """`name(p1, p2, ...)` from a list of parameter texts, wrapped at WIDTH under the opening bracket."""
    lines, line = [], name + '('
    indent = ' ' * len(line)
    for k, item in enumerate(parameters):
        piece = item + (', ' if k < len(parameters) - 1 else ')')
        if len(line) + len(piece.rstrip()) > WIDTH and line.strip() != name + '(':
            lines.append(line.rstrip())
            line = indent
        line += piece
    if not parameters:
        line += ')'
    lines.append(line.rstrip())
    return '\n'.join(lines)


def signature(name, obj, dropFirst=False):
    """The call of `obj` as text; None when inspect.signature cannot read it."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    parameters = list(sig.parameters.values())
    if dropFirst and parameters:
        sig = sig.replace(parameters=parameters[1:])
    return callText(name, _splitTopLevel(str(sig.replace(return_annotation=inspect.Signature.empty))[1:-1]))


def _engineParameters(cls):
    """(name, default, doc) of an engine class's typed parameters (yade_dda.params.Parameter), in the
    class's order, with a recorder's YADE periods after its own."""
    out = [(name, cls.__dict__[name].default, cls.__dict__[name].__doc__) for name in cls._names
           if name in cls.__dict__]
    periods = getattr(sys.modules[cls.__module__], '_PERIOD_PARAMETERS', {})
    out += [(name, p.default, p.__doc__) for name, p in periods.items()]
    return out


def _isEngine(cls):
    return inspect.isclass(cls) and hasattr(cls, '_names') and hasattr(cls, '_updateCommand')


# ------------------------------------------------------------------ sections

def slug(heading):
    """GitHub's id of a heading (as tests/py/package/test_docs.py computes it)."""
    text = heading.replace('`', '').replace('*', '')
    text = re.sub(r'(?<![A-Za-z0-9])_+|_+(?![A-Za-z0-9])', '', text).strip().lower()
    return re.sub(r'[^\w\- ]', '', text).replace(' ', '-')


class Page:
    """The page's lines, and the headings for its contents list."""

    def __init__(self):
        self.lines = []
        self.headings = []
        self.undocumented = []

    def add(self, *texts):
        for text in texts:
            self.lines.extend(text.split('\n') if text else [''])
            self.lines.append('')

    def heading(self, level, text):
        self.headings.append((level, text))
        self.add('#' * level + ' ' + text)

    def doc(self, what, docstring):
        text = markdown(docstring)
        if text:
            self.add(text)
        else:
            self.undocumented.append(what)
            self.add('(No docstring.)')

    def code(self, text, language='python'):
        self.add(_fence(text.split('\n'), language))


def _docOf(obj):
    return obj.__doc__ if isinstance(obj.__doc__, str) else None


def _integratorDoc(cls, settings):
    """DDAIntegrator's docstring with its generated parameter list (one item per row of the settings)
    replaced by a link to doc/parameters.md."""
    names = [row['name'] for row in settings]
    lines = inspect.cleandoc(cls.__doc__).split('\n')
    items = [k for k, line in enumerate(lines) if any(line.strip().startswith('- ``%s``' % n) for n in names)]
    if not items:
        return cls.__doc__
    end = items[-1] + 1
    while end < len(lines) and lines[end].strip():
        end += 1
    link = ('The %d parameters, each with its default, range, unit and meaning, are in '
            '[parameters.md](parameters.md#ddaintegrator) (made from the same declaration): %s.'
            % (len(names), ', '.join('``%s``' % n for n in names)))
    return '\n'.join(lines[:items[0]] + [link] + lines[end:])


def _members(cls):
    """(name, kind, object) of the public methods and properties a yade_dda class defines (its own and
    those of its yade_dda bases; not YADE's), sorted by name. Engine parameters are left out."""
    from yade_dda.params import Parameter
    found = {}
    for base in reversed(cls.__mro__):
        if not base.__module__.startswith('yade_dda') or base is object:
            continue
        for name, value in vars(base).items():
            if name.startswith('_') or isinstance(value, Parameter):
                continue
            if isinstance(value, property):
                found[name] = ('property', value)
            elif isinstance(value, (staticmethod, classmethod)):
                found[name] = ('method', value.__func__)
            elif inspect.isfunction(value):
                found[name] = ('method', value)
    return [(name,) + found[name] for name in sorted(found)]


def _inheritedDoc(cls, name):
    """The docstring of attribute `name` of the nearest class in cls's MRO that documents it."""
    for base in cls.__mro__:
        value = vars(base).get(name)
        doc = _docOf(value) if value is not None else None
        if doc:
            return doc
    return None


def _attributes(cls):
    """The public data attributes of a yade_dda class's instances: its ``__slots__`` and what its
    ``__init__`` assigns to ``self.<name>``, in order of appearance (engines' parameters excepted)."""
    names = []
    for base in reversed(cls.__mro__):
        if not base.__module__.startswith('yade_dda'):
            continue
        names += list(vars(base).get('__slots__', ()))
        init = vars(base).get('__init__')
        if init is None or _isEngine(base):
            continue
        for node in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(init)))):
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, ast.AugAssign) else []
            for target in targets:
                for item in target.elts if isinstance(target, ast.Tuple) else [target]:
                    if isinstance(item, ast.Attribute) and isinstance(item.value, ast.Name) \
                            and item.value.id == 'self':
                        names.append(item.attr)
    seen = set()
    return [n for n in names if not n.startswith('_') and not (n in seen or seen.add(n))]


def _classSection(page, level, title, cls, settings=None, returned=None):
    page.heading(level, '`%s`' % title)
    if returned:
        page.add(returned)
        page.doc(title, _docOf(cls))
    elif _isEngine(cls):
        parameters = _engineParameters(cls)
        if cls.__name__ == 'DDAIntegrator':
            page.code(callText(title, ['*', "label=''", '**parameters']))
            page.doc(title, _integratorDoc(cls, settings))
        else:
            page.code(callText(title, ['*'] + ['%s=%r' % (n, d) for n, d, _ in parameters] + ["label=''"]))
            page.doc(title, _docOf(cls))
            if parameters:
                page.add('Parameters, as declared (`%s.<name>` reads and sets them, checked):' % title)
                page.add('\n'.join('- `%s` (default `%r`): %s' % (n, d, inline(doc or '')) for n, d, doc in parameters))
    else:
        text = signature(title, cls)
        if text:
            page.code(text)
        page.doc(title, _docOf(cls))
    attributes = _attributes(cls)
    if attributes:
        page.add('Attributes: %s.' % ', '.join('`%s`' % a for a in attributes))
    members = _members(cls)
    properties = [(n, o) for n, kind, o in members if kind == 'property']
    if properties:
        page.add('Properties (read-only):')
        items = []
        for name, prop in properties:
            doc = _inheritedDoc(cls, name)
            if not doc:
                page.undocumented.append('%s.%s' % (title, name))
            items.append('- `%s`: %s' % (name, inline(' '.join(inspect.cleandoc(doc).split())) if doc
                                          else '(no docstring)'))
        page.add('\n'.join(items))
    for name, kind, function in members:
        if kind != 'method':
            continue
        page.heading(level + 1, '`%s.%s`' % (title, name))
        text = signature(name, function, dropFirst=True)
        if text:
            page.code(text)
        page.doc('%s.%s' % (title, name), _docOf(function))


def _functionSection(page, level, title, function, call=None):
    page.heading(level, '`%s`' % title)
    text = signature(call or title, function)
    if text:
        page.code(text)
    page.doc(title, _docOf(function))


def _statsKeys(doc):
    """The stats() keys its docstring names (``key`` literals that are bare names), sorted."""
    keys = set()
    for match in re.finditer(r'``([A-Za-z][A-Za-z0-9]*)``', doc):
        keys.add(match.group(1))
    return sorted(keys, key=lambda k: (k.lower(), k))


def _omegaSection(page, hooks):
    page.heading(3, '`O`')
    page.add("YADE's `Omega` (`yade.wrapper.Omega()`): the current YADE scene, the same object as YADE's own `O`, "
             "exported so that `from yade_dda import *` gives a script everything it uses. It is YADE's class and "
             "has no docstring of yade_dda's; YADE's documentation describes it. What importing yade_dda changes "
             "on it and on YADE's containers (`yade_dda.hooks.installHooks`, run once on import):")
    page.doc('installHooks', hooks.installHooks.__doc__)


def _names(module):
    """The public names a module defines itself (functions, classes, constants), in source order."""
    tree = ast.parse(inspect.getsource(module))
    names = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [t.id for t in node.targets if isinstance(t, ast.Name)]
    return [n for n in names if not n.startswith('_')]


def _sweepHelp(sweep):
    """The text of ``python3 -m yade_dda.tools.sweep --help`` at WIDTH columns, without this machine's core count
    (the default of --workers)."""
    columns, cpuCount = os.environ.get('COLUMNS'), os.cpu_count
    os.environ['COLUMNS'] = str(WIDTH)
    os.cpu_count = lambda: 1   # so that the text, and where argparse wraps it, is the same on every machine
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            try:
                sweep.main(['--help'])
            except SystemExit:
                pass
    finally:
        os.cpu_count = cpuCount
        if columns is None:
            del os.environ['COLUMNS']
        else:
            os.environ['COLUMNS'] = columns
    return re.sub(r'(the\s+cores), 1\)', r'\1)', out.getvalue())


def _tools(page, yade_dda):
    from yade_dda import tools
    from yade_dda.tools import accuracy, compare, regression, sweep
    page.heading(2, 'Workflow tools')
    page.add('The subpackage `yade_dda.tools`, out of `from yade_dda import *`:')
    page.doc('yade_dda.tools', tools.__doc__)
    _functionSection(page, 3, 'compareColliders', yade_dda.compareColliders, 'yade_dda.compareColliders')
    page.add('`yade_dda.compareColliders` is `yade_dda.tools.compare.compareColliders`, loaded on first use. '
             'From the module `yade_dda.tools.compare`:')
    page.doc('yade_dda.tools.compare', compare.__doc__)

    _functionSection(page, 3, 'accuracySweep', yade_dda.accuracySweep, 'yade_dda.accuracySweep')
    page.add('`yade_dda.accuracySweep` is `yade_dda.tools.accuracy.sweep`, loaded on first use. '
             'From the module `yade_dda.tools.accuracy`:')
    page.doc('yade_dda.tools.accuracy', accuracy.__doc__)

    page.heading(3, '`regression`')
    page.add('`from yade_dda.tools import regression`: the module `yade_dda.tools.regression`.')
    page.doc('yade_dda.tools.regression', regression.__doc__)
    for name in _names(regression):
        obj = getattr(regression, name)
        title = 'regression.' + name
        if inspect.isclass(obj):
            _classSection(page, 4, title, obj)
        elif callable(obj):
            _functionSection(page, 4, title, obj)
        else:
            page.heading(4, '`%s`' % title)
            page.code('%s = %r' % (title, obj))
            page.undocumented.append(title)
            page.add('(A constant; no docstring. Named in the module docstring above.)'
                     if name in (regression.__doc__ or '') else '(A constant; no docstring.)')

    page.heading(3, '`python3 -m yade_dda.tools.sweep`')
    page.doc('yade_dda.tools.sweep', sweep.__doc__)
    page.add('`--help`:')
    page.code(_sweepHelp(sweep).rstrip('\n'), '')
    _functionSection(page, 4, 'sweep.run', sweep.run, 'yade_dda.tools.sweep.run')


def render():
    """The text of doc/api.md for the yade_dda that Python imports."""
    import yade_dda
    from yade_dda import hooks, params
    page = Page()
    groups = {title: [] for title, _, _ in GROUPS}
    other = []
    for name in yade_dda.__all__:
        obj = getattr(yade_dda, name)
        module = getattr(obj, '__module__', None) if (inspect.isclass(obj) or inspect.isfunction(obj)) \
            else type(obj).__module__
        title = next((t for t, modules, _ in GROUPS if module in modules), None)
        (groups[title] if title else other).append(name)

    body = Page()
    body.heading(2, 'The package')
    body.doc('yade_dda', yade_dda.__doc__)
    for title, _, introduction in GROUPS + (('Other names', (), ''),):
        names = groups.get(title, other)
        if not names:
            continue
        body.heading(2, title)
        if introduction:
            body.add(introduction)
        if title == 'Scene functions' and 'O' in names:   # O first: the others act on its scene
            names = ['O'] + [n for n in names if n != 'O']
        for name in names:
            obj = getattr(yade_dda, name)
            if name == 'O':
                _omegaSection(body, hooks)
            elif inspect.isclass(obj):
                _classSection(body, 3, name, obj, params.SETTINGS)
            elif callable(obj):
                _functionSection(body, 3, name, obj)
                if name == 'stats':
                    body.add('Index of the names the docstring marks as keys, of the dict and of its dicts `energy` '
                             'and `memory`, sorted: %s.'
                             % ', '.join('`%s`' % k for k in _statsKeys(obj.__doc__)))
            else:
                body.heading(3, '`%s`' % name)
                body.code('%s = %r' % (name, obj))
            module = sys.modules.get(getattr(obj, '__module__', ''), None)
            for returned, what in RETURNED.get(name, ()):
                _classSection(body, 3, returned, getattr(module, returned), returned=what)
    _tools(body, yade_dda)

    page.add('# Python API reference')
    page.add('This page is generated by `tools/gen_api.py` (`make docs`) from the docstrings of the yade_dda '
             'package: edit a docstring and run `make docs`, not this page '
             '(`tests/py/package/test_api_reference.py` fails when it is stale). It lists every name of '
             '`yade_dda.__all__` (%d), the objects they return that a script handles, and the workflow tools of '
             '`yade_dda.tools`. Parameters of `DDAIntegrator` are in [parameters.md](parameters.md); how '
             'to use all this is in the [user guide](user-guide.md).' % len(yade_dda.__all__))
    page.add('Signatures are those `inspect.signature` reads; an engine shows its parameters (keyword arguments '
             'only). The docstrings are reStructuredText rendered simply as Markdown. SI units throughout.')
    page.add('\n'.join('%s- [%s](#%s)' % ('  ' * (level - 2), text, slug(text))
                       for level, text in body.headings if level <= 3))
    page.lines += body.lines
    page.undocumented += body.undocumented
    while page.lines and page.lines[-1] == '':
        page.lines.pop()
    text = '\n'.join(page.lines) + '\n'
    address = re.search(r'\bat 0x[0-9a-fA-F]+|\b0x[0-9a-fA-F]{8,}', text)
    if address:
        raise ValueError('doc/api.md would hold an address (%s): the output must not depend on the run'
                         % address.group(0))
    render.undocumented = sorted(set(page.undocumented), key=page.undocumented.index)
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--check', action='store_true', help='exit 1 if doc/api.md is stale, write nothing')
    args = parser.parse_args()
    if os.environ.get('YADE_DDA_BUILD'):
        sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
    text = render()
    if render.undocumented:
        print('no docstring: %s' % ', '.join(render.undocumented), file=sys.stderr)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from docpage import writeOrCheck
    writeOrCheck(TARGET, text, args.check, REPO)


if __name__ == '__main__':
    main()
