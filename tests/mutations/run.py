"""Mutation checks of the hard-case suite: each case class fails
when the core mechanism that guards it is removed.

Every `*.patch` in this directory is one mutation: a unified diff against the
current sources that removes one protection, after a header of `Key: value`
lines (continuation lines indented) that git apply skips:

    Removes:    the mechanism, in a few words (the table's column)
    Mechanism:  where it is and what it does
    Tests:      the tests that must fail without it: pytest node ids, or
                `ctest:Suite.Name` for a GoogleTest case of dda_tests
    Why:        why those tests fail without it

The name of a mutation is its file name without the leading number and
`.patch` (the number orders the run). For the unmutated tree first, then for
each mutation, the tracked and untracked (not ignored) files of this checkout
are synchronised into <build-dir>/src (a file is rewritten only when its
content differs, so the one build tree <build-dir>/build recompiles only what
a mutation changed, and what the previous one changed back), the patch is
applied with `git apply`, the Python module is built (and dda_tests when a
`ctest:` case is named), and the named tests run against it
(YADE_DDA_BUILD=<build-dir>/build/py, slow cases included; `ctest:` cases as
`dda_tests --gtest_filter`). The
unmutated tree must pass every named test; a mutation is caught when at least
one of its tests fails (a crashed test run counts as a failure, a timeout or a
skip does not).

Writes a JSON report (bench/out/mutations.json unless --out), prints a table
and exits non-zero when the baseline fails or a mutation is not caught.

Run: /usr/bin/python3 tests/mutations/run.py [--only NAME ...] [--build-dir DIR]
(`make mutations`). Not part of `make test`: it builds the module once per
mutation. `--list` builds nothing: it prints each mutation's tests and checks
that pytest collects every one of them in this checkout (exit 1 if not).
"""
import argparse
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PYTHON = '/usr/bin/python3'
KEEP_IN_SOURCE_COPY = {'__pycache__', '.pytest_cache'}


# ---------------------------------------------------------------- mutations

def read_mutation(path):
    """The header fields of a patch file (lower-case keys) plus name and path."""
    fields, key = {}, None
    with open(path) as f:
        for line in f:
            if line.startswith(('diff --git', '--- ')):
                break
            if key and line[:1] in (' ', '\t') and line.strip():
                fields[key] += ' ' + line.strip()
                continue
            m = re.match(r'([A-Za-z]+):\s*(.*)$', line.rstrip('\n'))
            key = m.group(1).lower() if m else None
            if key:
                fields[key] = m.group(2).strip()
    name = re.sub(r'^\d+-', '', os.path.basename(path)[:-len('.patch')])
    missing = [k for k in ('removes', 'mechanism', 'tests', 'why') if not fields.get(k)]
    if missing:
        raise SystemExit('%s: header lacks %s' % (path, ', '.join(missing)))
    return dict(name=name, path=path, removes=fields['removes'], mechanism=fields['mechanism'],
                tests=fields['tests'].split(), why=fields['why'])


def mutations():
    return [read_mutation(os.path.join(HERE, f)) for f in sorted(os.listdir(HERE)) if f.endswith('.patch')]


# ---------------------------------------------------------------- source copy and build

def git(*args, cwd=REPO, env=None):
    return subprocess.run(('git',) + args, cwd=cwd, env=env, check=True, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True).stdout


def sync_sources(src):
    """Makes `src` hold exactly this checkout's tracked and untracked, not ignored,
    files, rewriting only those whose content differs (their mtimes drive the build)."""
    listed = [p for p in git('ls-files', '-z', '--cached', '--others', '--exclude-standard').split('\0') if p]
    wanted = set()
    for rel in listed:
        origin = os.path.join(REPO, rel)
        if not os.path.isfile(origin):
            continue   # deleted in the checkout, not yet in the index
        wanted.add(rel)
        target = os.path.join(src, rel)
        if os.path.isfile(target) and filecmp.cmp(origin, target, shallow=False):
            continue
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copy2(origin, target)
        os.utime(target)   # newer than any object built from the old content
    for root, dirs, files in os.walk(src):
        dirs[:] = [d for d in dirs if d not in KEEP_IN_SOURCE_COPY]
        for f in files:
            rel = os.path.relpath(os.path.join(root, f), src)
            if rel not in wanted:
                os.remove(os.path.join(root, f))


def apply_patch(src, patch):
    """git apply in `src`, which lies in no repository (GIT_CEILING_DIRECTORIES
    stops git from finding this checkout's repository above it)."""
    env = dict(os.environ, GIT_CEILING_DIRECTORIES=os.path.dirname(os.path.abspath(src)))
    for check in (True, False):
        args = ['apply', '--check', patch] if check else ['apply', patch]
        try:
            git(*args, cwd=src, env=env)
        except subprocess.CalledProcessError as e:
            raise SystemExit('%s does not apply to the current sources:\n%s' % (patch, e.stderr))


CTEST = 'ctest:'
"""Prefix of a GoogleTest case (`ctest:Suite.Name`) among a mutation's tests."""


def build(src, tree, jobs, log, cpp=False):
    """Builds the Python module, and dda_tests too when `cpp` (a `ctest:` case is named)."""
    if not os.path.exists(os.path.join(tree, 'CMakeCache.txt')):
        run_logged(['cmake', '-S', src, '-B', tree, '-DCMAKE_BUILD_TYPE=Release', '-DPYTHON_EXECUTABLE=' + PYTHON,
                    '-DPython3_EXECUTABLE=' + PYTHON], log)
    run_logged(['cmake', '--build', tree, '-j', str(jobs), '--target', '_core', 'yade_dda_py']
               + (['dda_tests'] if cpp else []), log)


def run_logged(cmd, log):
    with open(log, 'a') as out:
        out.write('$ %s\n' % ' '.join(cmd))
        out.flush()
        code = subprocess.call(cmd, stdout=out, stderr=subprocess.STDOUT)
    if code != 0:
        raise SystemExit('%s failed (exit %d), see %s' % (cmd[0] + ' ' + cmd[1], code, log))


# ---------------------------------------------------------------- tests

def junit_key(nodeid):
    """(classname, name) pytest's junit XML gives a test function's node id."""
    path, _, name = nodeid.partition('::')
    return path[:-len('.py')].replace('/', '.'), name


def run_tests(src, tree, nodeids, xml, log, timeout):
    """{test id: {outcome: passed|failed|crashed|skipped|timeout|not run, message}}: the pytest
    node ids through pytest, the `ctest:` cases through dda_tests."""
    cases = [n for n in nodeids if n.startswith(CTEST)]
    nodeids = [n for n in nodeids if not n.startswith(CTEST)]
    out = run_gtest(tree, cases, xml[:-len('.xml')] + '-cpp.xml', log, timeout) if cases else {}
    if nodeids:
        out.update(run_pytest(src, tree, nodeids, xml, log, timeout))
    return out


def read_junit(xml):
    """{(classname, name): {outcome, message}} of a JUnit XML file (pytest's and GoogleTest's)."""
    results = {}
    for case in ET.parse(xml).getroot().iter('testcase'):
        key = (case.get('classname'), case.get('name'))
        outcome, message = 'passed', ''
        for child in case:
            if child.tag in ('failure', 'error'):
                outcome = 'failed'
                message = (child.get('message') or child.text or '').strip()
                break
            if child.tag == 'skipped':
                outcome, message = 'skipped', (child.get('message') or '').strip()
        results[key] = dict(outcome=outcome, message=message)
    return results


def missing_result(code, timeout, runner):
    if code is None:
        return dict(outcome='timeout', message='no result within %d s' % timeout)
    if code < 0:
        return dict(outcome='crashed', message='the test process died with signal %d' % -code)
    return dict(outcome='not run', message='%s ran no such test (exit %d)' % (runner, code))


def run_gtest(tree, cases, xml, log, timeout):
    """{`ctest:Suite.Name`: result} from one run of dda_tests on those cases."""
    if os.path.exists(xml):
        os.remove(xml)
    names = [c[len(CTEST):] for c in cases]
    cmd = [os.path.join(tree, 'dda_tests'), '--gtest_filter=' + ':'.join(names), '--gtest_output=xml:' + xml]
    with open(log, 'a') as out:
        out.write('$ %s\n' % ' '.join(cmd))
        out.flush()
        try:
            code = subprocess.call(cmd, cwd=tree, stdout=out, stderr=subprocess.STDOUT, timeout=timeout)
        except subprocess.TimeoutExpired:
            code = None
    results = read_junit(xml) if os.path.exists(xml) else {}
    return {c: results.get(tuple(n.split('.', 1))) or missing_result(code, timeout, 'dda_tests')
            for c, n in zip(cases, names)}


def run_pytest(src, tree, nodeids, xml, log, timeout):
    if os.path.exists(xml):
        os.remove(xml)
    cmd = [PYTHON, '-m', 'pytest', '-q', '-p', 'no:cacheprovider', '-m', 'slow or not slow', '--junitxml=' + xml] \
        + list(nodeids)
    env = dict(os.environ, YADE_DDA_BUILD=os.path.join(tree, 'py'), PYTHONDONTWRITEBYTECODE='1')
    with open(log, 'a') as out:
        out.write('$ YADE_DDA_BUILD=%s %s\n' % (env['YADE_DDA_BUILD'], ' '.join(cmd)))
        out.flush()
        try:
            code = subprocess.call(cmd, cwd=src, env=env, stdout=out, stderr=subprocess.STDOUT, timeout=timeout)
        except subprocess.TimeoutExpired:
            code = None
    results = read_junit(xml) if os.path.exists(xml) else {}
    return {n: results.get(junit_key(n)) or missing_result(code, timeout, 'pytest') for n in nodeids}


def collected(nodeids):
    """The subset of `nodeids` that this checkout has: pytest ids that `pytest --collect-only`
    finds (slow cases included, with the yade_dda that YADE_DDA_BUILD or the installed package
    gives), `ctest:Suite.Name` cases defined by a TEST(Suite, Name) in tests/cpp."""
    cases = {n for n in nodeids if n.startswith(CTEST)}
    pytestIds = set(nodeids) - cases
    found = set()
    if pytestIds:
        cmd = [PYTHON, '-m', 'pytest', '--collect-only', '-q', '-p', 'no:cacheprovider', '-m', 'slow or not slow'] \
            + sorted({n.split('::', 1)[0] for n in pytestIds})
        out = subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout
        lines = {line.strip() for line in out.splitlines()}
        found |= {n for n in pytestIds if n in lines}
    if cases:
        defined = set()
        for folder, _, files in os.walk(os.path.join(REPO, 'tests', 'cpp')):
            for file in files:
                if file.endswith('.cpp'):
                    text = open(os.path.join(folder, file), encoding='utf-8').read()
                    defined |= {'%s.%s' % m for m in re.findall(r'\bTEST(?:_F)?\(\s*(\w+)\s*,\s*(\w+)\s*\)', text)}
        found |= {c for c in cases if c[len(CTEST):] in defined}
    return found


def list_mutations(chosen):
    """Prints each mutation's tests, marking those pytest does not collect, and the patches that no longer
    apply to this checkout (`git apply --check`: their target moved); True when all are collected and apply."""
    nodeids = {t for m in chosen for t in m['tests']}
    found = collected(nodeids)
    stale = 0
    for m in chosen:
        applies = subprocess.run(['git', 'apply', '--check', m['path']], cwd=REPO, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL).returncode == 0
        stale += not applies
        print('%s: %s%s' % (m['name'], m['removes'], '' if applies else '   <- DOES NOT APPLY'))
        for t in m['tests']:
            print('  %s%s' % (t, '' if t in found else '   <- NOT COLLECTED'))
    missing = len(nodeids - found)
    print('\n%d tests named by %d mutations; %s; %s' % (
        len(nodeids), len(chosen), 'all collected' if not missing else '%d NOT collected' % missing,
        'every patch applies' if not stale else '%d patches DO NOT APPLY' % stale))
    return not missing and not stale


def first_line(message, width=None):
    """The assertion's first line, with pytest's `assert ...` line after a custom message."""
    lines = message.strip().splitlines() or ['']
    line = re.sub(r'^AssertionError: ', '', lines[0])
    if len(lines) > 1 and lines[1].startswith('assert ') and not line.startswith('assert '):
        line += ' / ' + lines[1]
    return line if width is None or len(line) <= width else line[:width - 3] + '...'


def short_test(nodeid):
    return nodeid.split('::', 1)[-1]


# ---------------------------------------------------------------- main

def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--only', action='append', metavar='NAME', help='run this mutation only (repeatable)')
    parser.add_argument('--build-dir', default=os.path.join(REPO, 'build-mutations'),
                        help='source copy, build tree and logs (default build-mutations/)')
    parser.add_argument('--out', default=os.path.join(REPO, 'bench', 'out', 'mutations.json'))
    parser.add_argument('--jobs', type=int, default=int(os.environ.get('JOBS', 2)))
    parser.add_argument('--timeout', type=int, default=3600, help='seconds per pytest run')
    parser.add_argument('--list', action='store_true',
                        help='build and run nothing: print the tests of each mutation and check that pytest collects them')
    args = parser.parse_args()

    chosen = mutations()
    if args.only:
        unknown = set(args.only) - {m['name'] for m in chosen}
        if unknown:
            raise SystemExit('no mutation named %s (have: %s)' % (', '.join(sorted(unknown)),
                                                                  ', '.join(m['name'] for m in chosen)))
        chosen = [m for m in chosen if m['name'] in args.only]
    if args.list:
        sys.exit(0 if list_mutations(chosen) else 1)
    top = os.path.abspath(args.build_dir)
    src, tree, logs = (os.path.join(top, d) for d in ('src', 'build', 'logs'))
    for d in (src, tree, logs):
        os.makedirs(d, exist_ok=True)
    started = time.time()
    head = git('rev-parse', 'HEAD').strip()
    dirty = bool(git('status', '--porcelain', '--untracked-files=no').strip())

    def stage(name, patch, nodeids):
        log = os.path.join(logs, name + '.log')
        open(log, 'w').close()
        t0 = time.time()
        sync_sources(src)
        if patch:
            apply_patch(src, patch)
        build(src, tree, args.jobs, log, cpp=any(n.startswith(CTEST) for n in nodeids))
        t1 = time.time()
        results = run_tests(src, tree, nodeids, os.path.join(logs, name + '.xml'), log, args.timeout)
        t2 = time.time()
        print('  %s: built in %.0f s, tests in %.0f s (log %s)' % (name, t1 - t0, t2 - t1, log), flush=True)
        return results, dict(buildSeconds=round(t1 - t0, 1), testSeconds=round(t2 - t1, 1), log=log)

    nodeids = sorted({t for m in chosen for t in m['tests']})
    print('baseline: the unmutated tree, %d tests' % len(nodeids), flush=True)
    results, timing = stage('baseline', None, nodeids)
    bad = {t: r for t, r in results.items() if r['outcome'] != 'passed'}
    report = dict(commit=head, dirty=dirty, baseline=dict(tests=results, passed=not bad, **timing), mutations=[])
    for t, r in bad.items():
        print('  baseline %s: %s %s' % (t, r['outcome'], first_line(r['message'])))

    if not bad:
        for m in chosen:
            print('%s: %s' % (m['name'], m['removes']), flush=True)
            results, timing = stage(m['name'], m['path'], m['tests'])
            failed = [t for t in m['tests'] if results[t]['outcome'] in ('failed', 'crashed')]
            report['mutations'].append(dict(
                name=m['name'], patch=os.path.relpath(m['path'], REPO), removes=m['removes'],
                mechanism=m['mechanism'], why=m['why'], tests=results, caught=bool(failed),
                caughtBy=failed, message=results[failed[0]]['message'] if failed else '', **timing))
        # leave the source copy unmutated
        sync_sources(src)
    report['seconds'] = round(time.time() - started, 1)

    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(report, f, indent=1)

    print()
    rows = [('mutation', 'removes', 'failed', 'caught', 'first failing test: assertion message')]
    for r in report['mutations']:
        rows.append((r['name'], r['removes'], '%d/%d' % (len(r['caughtBy']), len(r['tests'])),
                     'yes' if r['caught'] else 'NO',
                     short_test(r['caughtBy'][0]) + ': ' + first_line(r['message'], 110) if r['caught'] else
                     '; '.join('%s %s' % (short_test(t), x['outcome']) for t, x in r['tests'].items())))
    widths = [max(len(row[k]) for row in rows) for k in range(4)]
    for row in rows:
        print('  '.join(c.ljust(w) for c, w in zip(row, widths)) + '  ' + row[4])
    print('\nbaseline %s; %d of %d mutations caught; %.0f s; report %s' % (
        'passed' if not bad else 'FAILED', sum(r['caught'] for r in report['mutations']), len(chosen),
        report['seconds'], args.out))
    if bad or not all(r['caught'] for r in report['mutations']):
        sys.exit(1)


if __name__ == '__main__':
    main()
