"""No function or file in the C++ core is longer than a reader can hold.

LIMIT below is the one definition of the bound: no function body in pkg/
(C++ sources and headers, the binding included) spans more than LIMIT lines,
counted from the first line of its signature to its closing brace, as
Universal Ctags counts them (`ctags --fields=+ne`; it is not a build
dependency, so this file measures them itself).

The measure reads the source as the compiler's brace structure, after comments,
string and character literals are blanked out: a `{` at namespace or class
scope whose head (the text since the last `;`, `{` or `}`) holds a `)` and is
no aggregate initialiser is a function body, and everything up to its matching
`}` (lambdas and local classes included) belongs to that function.

FILE_LIMIT bounds a source file's lines the same way (one concern per file:
a longer one is split by the rules it holds).
"""
import os
import re

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
PKG = os.path.join(REPO, 'pkg')
LIMIT = 80
FILE_LIMIT = 600
SOURCE_SUFFIXES = ('.hpp', '.cpp', '.h', '.cc')

_SCOPE = re.compile(r'((inline|export)\s+)*(namespace|class|struct|union|enum)\b|extern\b')
_CONSTRUCTOR_INIT = re.compile(r'\)\s*(noexcept\s*)?:(?!:)')  # Box(int n) : n_{n}, m_(n) {
_ACCESS = re.compile(r'\s*(public|private|protected)\s*:(?!:)')


def strip_template_clause(head):
    """`head` without a leading `template <...>` (angle brackets balanced)."""
    match = re.match(r'\s*template\s*<', head)
    if not match:
        return head
    depth, i = 1, match.end()
    while i < len(head) and depth:
        depth += {'<': 1, '>': -1}.get(head[i], 0)
        i += 1
    return head[i:]


def classify(head):
    """'scope' (namespace, class, extern "C"), 'function' or 'other' for the head of a `{` outside functions."""
    bare = strip_template_clause(_ACCESS.sub('', head, count=1)).lstrip()
    if _SCOPE.match(bare) and ')' not in bare:
        return 'scope'
    if _SCOPE.match(bare) and bare.startswith(('class', 'struct', 'union', 'enum')):
        return 'scope'  # a base with a call in its template arguments: struct X : Base<decltype(f())>
    if ')' in bare and not bare.rstrip().endswith('='):
        return 'function'
    return 'other'


def blank_comments_and_literals(text):
    """`text` with comments, string and character literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        two = text[i:i + 2]
        if c == '#' and text[text.rfind('\n', 0, i) + 1:i].strip() == '':  # a preprocessor line
            j = i
            while True:
                j = text.find('\n', j)
                if j < 0 or text[j - 1] != '\\':
                    break
                j += 1
            j = n if j < 0 else j
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif two == '//':
            j = text.find('\n', i)
            j = n if j < 0 else j
            out.append(' ' * (j - i))
            i = j
        elif two == '/*':
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c == 'R' and text[i + 1:i + 2] == '"':  # raw string R"delim( ... )delim"
            open_paren = text.find('(', i + 2)
            delim = text[i + 2:open_paren]
            j = text.find(')' + delim + '"', open_paren)
            j = n if j < 0 else j + len(delim) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c == "'" and i > 0 and text[i - 1].isdigit():  # a digit separator: 1'000'000
            out.append(c)
            i += 1
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(c + ' ' * (j - i - 2) + c if j - i >= 2 else text[i:j])
            i = j
        else:
            out.append(c)
            i += 1
    return ''.join(out)


def function_lengths(text):
    """[(first line, lines, head)] of every function body in C++ source `text`."""
    code = blank_comments_and_literals(text)
    found = []
    stack = []  # per open brace: 'scope' (namespace, class, extern "C"), 'function' or 'other'
    head_start = 0  # where the text since the last ';', '{' or '}' begins
    function_open = None  # (start offset of the signature, head) of the outermost open function
    for i, c in enumerate(code):
        if c == ';':
            head_start = i + 1
        elif c == '{':
            head = code[head_start:i]
            before = code[:i].rstrip()[-1:]
            if 'function' in stack:
                kind = 'other'
            elif (stack and stack[-1] == 'init') or head.count('(') > head.count(')') or (
                    _CONSTRUCTOR_INIT.search(head) and (before.isalnum() or before in '_>')):
                kind = 'init'  # a brace in a parameter list (f(Limits l = {})) or a member initialiser: the head goes on
            else:
                kind = classify(head)
            if kind == 'function':
                signature = _ACCESS.sub(lambda m: ' ' * len(m.group(0)), head, count=1)
                offset = len(signature) - len(signature.lstrip())
                function_open = (head_start + offset, ' '.join(head.split()))
            stack.append(kind)
            if kind != 'init':
                head_start = i + 1
        elif c == '}':
            kind = stack.pop() if stack else 'other'
            if kind == 'function' and 'function' not in stack and function_open is not None:
                start, head = function_open
                first = code.count('\n', 0, start) + 1
                last = code.count('\n', 0, i) + 1
                found.append((first, last - first + 1, head))
                function_open = None
            if kind != 'init':
                head_start = i + 1
    return found


def long_functions(pkg, limit=LIMIT):
    """'file:line: N lines: head' for every function in `pkg` longer than `limit` lines."""
    found = []
    for folder, _, files in os.walk(pkg):
        for file in sorted(files):
            if not file.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(folder, file)
            for first, lines, head in function_lengths(open(path, encoding='utf-8').read()):
                if lines > limit:
                    found.append('%s:%d: %d lines: %s' % (os.path.relpath(path, pkg), first, lines, head[:80]))
    return found


def test_no_function_in_the_core_is_longer_than_the_limit():
    found = long_functions(PKG)
    assert not found, 'functions over %d lines (split them):\n' % LIMIT + '\n'.join(found)


def test_no_file_in_the_core_is_longer_than_the_limit():
    long_files = []
    for root, _, names in os.walk(PKG):
        for name in sorted(names):
            if name.endswith(SOURCE_SUFFIXES):
                path = os.path.join(root, name)
                with open(path, encoding='utf-8') as f:
                    lines = sum(1 for _ in f)
                if lines > FILE_LIMIT:
                    long_files.append('%s: %d lines' % (os.path.relpath(path, PKG), lines))
    assert not long_files, 'files over %d lines (split them by the rules they hold):\n' % FILE_LIMIT + \
        '\n'.join(long_files)


def test_the_measure_counts_what_ctags_counts():
    source = '\n'.join([
        '#include "Box.hpp"  // {',                       # 1: preprocessor lines are no head
        'namespace dda {',                                # 2
        'struct Point { double x{0}; double y = 1; };',   # 3
        'template <class T, int N = sizeof(T)>',          # 4: a function's signature starts here
        'T twice(const T& value)',                        # 5
        '{',                                              # 6
        '\tauto add = [](T a, T b) { return a + b; };',   # 7: a lambda stays inside
        '\tif (value > T{0}) { return add(value, value); }',  # 8
        '\tconst char* text = "} { ;";  // } {',          # 9: literals and comments are blanked
        "\tconst long big = 1'000'000; const char brace = '{';",  # 10
        '\treturn T{};',                                  # 11
        '}',                                              # 12
        'class Box {',                                    # 13
        'public:',                                        # 14
        '\tBox(int n) : n_{n},',                          # 15: a brace initialiser is no body
        '\t\tm_(n) {',                                    # 16
        '\t\tn_ += 1;',                                   # 17
        '\t}',                                            # 18
        '\tint size(int extra = {},',                     # 19: a default argument's braces
        '\t         int more = int{1}) const {',          # 20
        '\t\treturn n_;',                                 # 21
        '\t}',                                            # 22
        'private:',                                       # 23
        '\tint n_, m_;',                                  # 24
        '};',                                             # 25
        'extern "C" {',                                   # 26
        'int plain(int a) { /* { */ return a; }',         # 27
        '}',                                              # 28
        '}  // namespace dda',                            # 29
    ])
    assert [(first, lines) for first, lines, _ in function_lengths(source)] == [(4, 9), (15, 4), (19, 4), (27, 1)]


def test_the_check_sees_a_function_over_the_limit(tmp_path):
    body = '\n'.join('\tx += %d;' % k for k in range(LIMIT))
    (tmp_path / 'Long.cpp').write_text('namespace dda {\nint grow(int x) {\n%s\n\treturn x;\n}\n}\n' % body)
    (tmp_path / 'Short.hpp').write_text('inline int one() { return 1; }\n')
    found = long_functions(str(tmp_path))
    assert len(found) == 1 and found[0].startswith('Long.cpp:2: %d lines' % (LIMIT + 3)), found
