"""The product's files describe the product, not its development history.

No line of README.md, Makefile, or any text file under doc/, pkg/, py/,
examples/ or tests/ (the mutation patches included) names a work session or a
tracker issue by number, or a development branch by its helper- name: the
regular expression PATTERN below, matched without regard to case, finds
nothing. History belongs in CHANGELOG.md, which is not read. Each hit is
reported as file:line with the line's text. Binary files (a NUL byte, or not
UTF-8) and __pycache__ and hidden folders are skipped. Pure Python: no YADE
scene is used.
"""
import os
import re


# tests/py/package/ -> the checkout's top folder.
REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..', '..'))
assert os.path.isfile(os.path.join(REPO, 'README.md')), REPO

# Written in pieces so that this file does not match its own pattern.
PATTERN = re.compile('|'.join(['sess' + 'ion [0-9]', 'iss' + 'ue [0-9]', 'help' + 'er-[a-z]']), re.IGNORECASE)

FILES = ['README.md', 'Makefile']
FOLDERS = ['doc', 'pkg', 'py', 'examples', 'tests']
SKIPPED_FOLDERS = {'__pycache__'}


def text_lines(path):
    """The lines of a text file, or None for a binary one."""
    with open(path, 'rb') as f:
        data = f.read()
    if b'\0' in data:
        return None
    try:
        return data.decode('utf-8').splitlines()
    except UnicodeDecodeError:
        return None


def checked_files():
    """Every file the test reads, relative to the checkout."""
    files = [name for name in FILES if os.path.isfile(os.path.join(REPO, name))]
    for folder in FOLDERS:
        for root, dirs, names in os.walk(os.path.join(REPO, folder)):
            dirs[:] = sorted(d for d in dirs if d not in SKIPPED_FOLDERS and not d.startswith('.'))
            files += [os.path.relpath(os.path.join(root, name), REPO) for name in sorted(names)]
    return files


def test_the_files_are_found():
    files = checked_files()
    for expected in ('README.md', 'Makefile', os.path.join('doc', 'testing.md'),
                     os.path.join('tests', 'py', 'package', 'test_no_history.py')):
        assert expected in files, expected
    assert any(f.startswith('pkg' + os.sep) for f in files)


def test_pattern_finds_what_it_is_for():
    for line in ['(Sess' + 'ion 9)', 'iss' + 'ue 21', 'branch help' + 'er-narrow']:
        assert PATTERN.search(line), line
    for line in ['a pytest session fixture', 'the open issue', 'helpers.box']:
        assert not PATTERN.search(line), line


def test_no_file_names_a_session_an_issue_or_a_helper_branch():
    hits = []
    for relative in checked_files():
        lines = text_lines(os.path.join(REPO, relative))
        for number, line in enumerate(lines or [], 1):
            if PATTERN.search(line):
                hits.append('%s:%d: %s' % (relative, number, line.strip()))
    assert not hits, 'development history in the product\'s files (%d lines):\n%s' % (len(hits), '\n'.join(hits))
