"""The documentation pages hold together and fit their reader.

README.md stays a front page (at most 200 lines; the manual is the guide in
doc/guide/, indexed by doc/user-guide.md), and every relative link in README.md,
doc/*.md and doc/guide/*.md, text or image, points to a
file that exists; a link's #anchor into a Markdown page (or within one) names a
heading of that page, by GitHub's rule for heading ids. Links to http(s) and
mailto addresses are not followed. Pure Python: no YADE scene is used.
"""
import glob
import os
import re

import pytest


def _repository():
    """The checkout's top folder: the nearest folder above this file with README.md and doc/
    (so the file may move within tests/)."""
    folder = os.path.dirname(os.path.abspath(__file__))
    while not (os.path.isfile(os.path.join(folder, 'README.md')) and os.path.isdir(os.path.join(folder, 'doc'))):
        parent = os.path.dirname(folder)
        assert parent != folder, 'no README.md with a doc/ folder above ' + __file__
        folder = parent
    return folder


REPO = _repository()
README_MAX_LINES = 200

PAGES = ['README.md'] + sorted(os.path.relpath(p, REPO) for pattern in (('doc', '*.md'), ('doc', 'guide', '*.md'))
                               for p in glob.glob(os.path.join(REPO, *pattern)))

# [text](target) and ![alt](target), with an optional "title"; text may hold
# one level of brackets (an image inside a link).
LINK = re.compile(r'!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+"[^"]*")?\s*\)')
FENCE = re.compile(r'^\s*(```|~~~)')
HEADING = re.compile(r'^(#{1,6})\s+(.*?)\s*#*\s*$')
EXTERNAL = re.compile(r'^[a-zA-Z][a-zA-Z0-9+.-]*:')   # http:, https:, mailto:, ...


def read(page):
    with open(os.path.join(REPO, page), encoding='utf-8') as f:
        return f.read()


def proseLines(text):
    """(line number, line) of the text outside fenced code blocks."""
    inFence = None
    for number, line in enumerate(text.split('\n'), 1):
        fence = FENCE.match(line)
        if fence:
            if inFence is None:
                inFence = fence.group(1)
            elif fence.group(1) == inFence:
                inFence = None
            continue
        if inFence is None:
            yield number, line


def withoutCodeSpans(line):
    return re.sub(r'(`+)(?:(?!\1).)+?\1', '', line)


def links(page):
    """(line number, target) of every link and image in a page."""
    for number, line in proseLines(read(page)):
        for match in LINK.finditer(withoutCodeSpans(line)):
            yield number, match.group(1)


def slug(heading):
    """GitHub's id of a heading: its rendered text in lower case, without
    punctuation other than '-' and '_', each space a '-'."""
    text = re.sub(r'!?\[((?:[^\[\]]|\[[^\[\]]*\])*)\]\([^)]*\)', r'\1', heading)   # links: their text
    text = re.sub(r'<[^>]+>', '', text)                                             # inline HTML
    text = text.replace('`', '').replace('*', '')
    text = re.sub(r'(?<![A-Za-z0-9])_+|_+(?![A-Za-z0-9])', '', text)              # _emphasis_, not snake_case
    text = text.strip().lower()
    text = re.sub(r'[^\w\- ]', '', text)
    return text.replace(' ', '-')


def anchors(page):
    """The ids of a page's headings, numbered as GitHub numbers repeats."""
    seen = {}
    ids = set()
    for _, line in proseLines(read(page)):
        match = HEADING.match(line)
        if not match:
            continue
        base = slug(match.group(2))
        count = seen.get(base, 0)
        ids.add(base if count == 0 else '%s-%d' % (base, count))
        seen[base] = count + 1
    return ids


def test_readme_is_a_front_page():
    lines = read('README.md').split('\n')
    if lines and lines[-1] == '':
        lines.pop()
    assert len(lines) <= README_MAX_LINES, (
        'README.md has %d lines, more than %d: move detail into doc/ (guide/, benchmarks.md, testing.md)'
        % (len(lines), README_MAX_LINES))


def test_pages_are_found():
    assert 'README.md' in PAGES and os.path.join('doc', 'user-guide.md') in PAGES, PAGES
    for part in ('tutorial', 'how-to', 'reference', 'explanation'):
        assert os.path.join('doc', 'guide', part + '.md') in PAGES, PAGES


@pytest.mark.parametrize('page', PAGES)
def test_relative_links_point_to_files(page):
    broken = []
    for number, target in links(page):
        if not target or target.startswith('#') or EXTERNAL.match(target):
            continue
        path = target.split('#', 1)[0].split('?', 1)[0]
        resolved = os.path.normpath(os.path.join(REPO, os.path.dirname(page), path))
        if not os.path.exists(resolved):
            broken.append('%s:%d: %s (no %s)' % (page, number, target, os.path.relpath(resolved, REPO)))
    assert not broken, 'links to missing files:\n' + '\n'.join(broken)


@pytest.mark.parametrize('page', PAGES)
def test_anchors_name_headings(page):
    broken = []
    for number, target in links(page):
        if '#' not in target or EXTERNAL.match(target):
            continue
        path, anchor = target.split('#', 1)
        resolved = os.path.normpath(os.path.join(REPO, os.path.dirname(page), path)) if path else \
            os.path.join(REPO, page)
        if not resolved.endswith('.md') or not os.path.exists(resolved):
            continue   # a missing file is test_relative_links_point_to_files's to report
        ids = anchors(os.path.relpath(resolved, REPO))
        if anchor not in ids:
            broken.append('%s:%d: %s (no heading of %s has the id "%s")'
                          % (page, number, target, os.path.relpath(resolved, REPO), anchor))
    assert not broken, 'anchors that name no heading:\n' + '\n'.join(broken)


def test_slug_follows_github():
    assert slug("The paper's scenes") == 'the-papers-scenes'
    assert slug('Blocks: `ddaBlock`') == 'blocks-ddablock'
    assert slug('Sync: the core is the source of truth') == 'sync-the-core-is-the-source-of-truth'
    assert slug('Time scheme (Newmark\'s family on beta = gamma/2)') == 'time-scheme-newmarks-family-on-beta--gamma2'
    assert slug('Energy of a dropped pile (200 cubes)') == 'energy-of-a-dropped-pile-200-cubes'
    assert slug('`openCloseTolerance` (gone)') == 'openclosetolerance-gone'
    assert slug('snake_case stays') == 'snake_case-stays'
