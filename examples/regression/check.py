#!/usr/bin/python3
# -*- coding: utf-8 -*-
"""Checks the records of a yade-batch regression run against closed forms and stored references.

    /usr/bin/python3 examples/regression/check.py TABLE RECORDS [--references DIR] [--logs DIR]
                                                   [--lines LIST] [--update]

TABLE is the yade-batch table that was run (quick.table, full.table), RECORDS
the directory the scenes wrote their records to ($YADE_DDA_RECORDS). Every
row of the table (or of --lines, yade-batch's syntax: 2,5-7) must have left
RECORDS/<description>.json; a row without one failed (crashed, or never ran)
and is reported with the end of its log (--logs: yade-batch's log directory,
logs named <description>.log). A record must carry the row's parameters
(else it is stale, from another table or an older run).

Each check of a record passes when, for every component,
    |measured - expected| <= abs + rel |expected|
with `abs` and `rel` the tolerance the scene states. `expected` is the
closed form the scene computed, or, for reference checks, the value stored
in references/<description>.json (--references to use another directory).
A reference made with other parameters than the record's fails: regenerate it.

--update writes the references from the records (reference checks only;
closed-form checks are still checked) -- after a deliberate change of
behaviour, review `git diff examples/regression/references` and commit.

Prints a table (one line per check) and exits 1 on any failure, 0 otherwise.
Plain Python: no YADE needed.
"""
import argparse
import datetime
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


# ---------------------------------------------------------------- the table, as YADE reads it

def readTable(path):
    """{line number: {column: text}} of a yade-batch table, as yade.utils.TableParamReader reads it.

    First non-empty line: column names; '#' starts a comment; '=' repeats the
    value of the previous row; without a 'description' column it is built
    from the columns marked with a trailing '!' (all columns if none is),
    made unique with '__line=N__'.
    """
    with open(path) as f:
        text = f.read()
    if text and not text.endswith('\n'):
        raise ValueError('%s must end with a newline (YADE drops the last character of every line)' % path)
    lines = [''] + [re.sub(r'\s*#.*', '', l) for l in text.split('\n')[:-1]]
    usable = [i for i in range(len(lines)) if not re.match(r'^\s*$', lines[i])]
    if not usable:
        raise ValueError('%s: empty table' % path)
    headings = lines[usable[0]].split()
    bangHeads = None
    if 'description' not in headings:
        bangHeads = [h[:-1] for h in headings if h.endswith('!')] or headings
        headings = [h[:-1] if h.endswith('!') else h for h in headings]
    rows = {}
    previous = None
    for i in usable[1:]:
        cells = lines[i].split()
        if len(cells) != len(headings):
            raise ValueError('%s line %d: %d values for %d columns' % (path, i, len(cells), len(headings)))
        row = dict(zip(headings, cells))
        for column, value in row.items():
            if value == '=':
                if previous is None:
                    raise ValueError('%s line %d: = with no previous row' % (path, i))
                row[column] = previous[column]
        rows[i] = row
        previous = row
    if bangHeads is not None:
        seen = set()
        for i in sorted(rows):
            d = ','.join(h.replace('!', '') + '=' + rows[i][h] for h in bangHeads).replace("'", '').replace('"', '')
            if d in seen:
                d += '__line=%d__' % i
            rows[i]['description'] = d
            seen.add(d)
    return rows


def lineList(text):
    """yade-batch's --lines syntax: '2,5-7' -> [2, 5, 6, 7]."""
    out = []
    for part in text.split(','):
        if '-' in part:
            lo, hi = (int(s) for s in part.split('-'))
            out += list(range(lo, hi + 1))
        else:
            out.append(int(part))
    return out


def rowParams(row):
    """The parameters a row sets: columns other than description and !..., values other than '*',
    evaluated as YADE does (Python expressions, math's names available)."""
    out = {}
    for column, text in row.items():
        if column == 'description' or column.startswith('!') or text == '*':
            continue
        out[column] = eval(text, dict(math.__dict__))
    return out


# ---------------------------------------------------------------- comparisons

def components(value):
    if isinstance(value, list):
        return [c for v in value for c in components(v)]
    return [value]


def shape(value):
    if isinstance(value, list):
        return [shape(v) for v in value]
    return None


def compare(measured, expected, absTol, relTol):
    """(passed, worst): worst = (index, measured, expected, |diff|, allowed) of the component
    closest to (or furthest past) its tolerance; a shape mismatch or a non-finite value fails."""
    if shape(measured) != shape(expected):
        return False, None
    worst, passed, worstRatio = None, True, -1.0
    for i, (m, e) in enumerate(zip(components(measured), components(expected))):
        m, e = float(m), float(e)
        allowed = absTol + relTol * abs(e)
        diff = abs(m - e)
        ok = math.isfinite(m) and math.isfinite(e) and diff <= allowed
        ratio = diff / allowed if allowed > 0 and math.isfinite(diff) else math.inf
        passed = passed and ok
        if ratio > worstRatio or worst is None:
            worst, worstRatio = (i, m, e, diff, allowed), ratio
    return passed, worst


def sameParams(a, b):
    return set(a) == set(b) and all(a[k] == b[k] for k in a)


# ---------------------------------------------------------------- the check

class Result:
    def __init__(self, scene, check, kind, passed, worst=None, n=1, note=''):
        self.scene, self.check, self.kind, self.passed = scene, check, kind, passed
        self.worst, self.n, self.note = worst, n, note


def logTail(logs, description, lines=6):
    if not logs:
        return ''
    path = os.path.join(logs, description + '.log')
    if not os.path.exists(path):
        return 'no log %s either' % path
    with open(path, errors='replace') as f:
        text = [l.rstrip() for l in f if l.strip() and not l.startswith(('=====', 'id      :', 'duration:', 'command :',
                                                                          'started :', 'finished:'))]
    return 'log %s ends:\n' % path + '\n'.join('      | ' + l for l in text[-lines:])


def referenceData(record, command):
    values = {c['name']: c['measured'] for c in record['checks'] if c['kind'] == 'reference'}
    return {
        'description': record['description'],
        'script': record['script'],
        'params': record['params'],
        'values': values,
        'generated': {'date': datetime.datetime.now().isoformat(timespec='seconds'),
                      'command': command, 'versions': record.get('versions'),
                      'run': record.get('run')},
    }


def checkRow(row, records, references, logs, update, command, out):
    description = row['description']
    script = os.path.basename(row.get('!SCRIPT', '')) or None
    path = os.path.join(records, description + '.json')
    if not os.path.exists(path):
        out.append(Result(description, '(record)', '-', False,
                          note='no record %s: the scene crashed or did not run. %s' % (path, logTail(logs, description))))
        return None
    try:
        with open(path) as f:
            record = json.load(f)
    except ValueError as e:
        out.append(Result(description, '(record)', '-', False, note='unreadable record %s: %s' % (path, e)))
        return None
    expectedParams = rowParams(row)
    problems = []
    if script and record.get('script') != script:
        problems.append('record is from %s, the row runs %s' % (record.get('script'), script))
    differing = {k: (record['params'].get(k), v) for k, v in expectedParams.items() if record['params'].get(k) != v}
    if differing:
        problems.append('stale record: parameters differ from the table row (%s)'
                        % ', '.join('%s: record %r, table %r' % (k, a, b) for k, (a, b) in sorted(differing.items())))
    if not record.get('checks'):
        problems.append('record has no checks')
    if problems:
        out.append(Result(description, '(record)', '-', False, note='; '.join(problems)))
        return record
    refChecks = [c for c in record['checks'] if c['kind'] == 'reference']
    reference = None
    refPath = os.path.join(references, description + '.json')
    if refChecks and update:
        os.makedirs(references, exist_ok=True)
        with open(refPath, 'w') as f:
            json.dump(referenceData(record, command), f, indent=1)
            f.write('\n')
        print('reference written: %s' % refPath)
    if refChecks:
        if os.path.exists(refPath):
            with open(refPath) as f:
                reference = json.load(f)
            if not sameParams(reference.get('params', {}), record['params']):
                out.append(Result(description, '(reference)', 'reference', False,
                                  note='%s was made with parameters %r, the record has %r: regenerate with --update'
                                  % (refPath, reference.get('params'), record['params'])))
                reference = None
        else:
            out.append(Result(description, '(reference)', 'reference', False,
                              note='no reference %s: create it with --update' % refPath))
    for c in record['checks']:
        if c['kind'] == 'closedForm':
            expected = c['expected']
        elif reference is None:
            continue
        elif c['name'] not in reference.get('values', {}):
            out.append(Result(description, c['name'], 'reference', False,
                              note='%s has no value %r: regenerate with --update' % (refPath, c['name'])))
            continue
        else:
            expected = reference['values'][c['name']]
        passed, worst = compare(c['measured'], expected, c['abs'], c['rel'])
        note = '' if worst is not None else 'shape differs: measured %s, expected %s' % (
            len(components(c['measured'])), len(components(expected)))
        out.append(Result(description, c['name'], 'closed form' if c['kind'] == 'closedForm' else 'reference',
                          passed, worst, len(components(c['measured'])), note))
    return record


def fmt(x):
    return '%.6g' % x


def printTable(results, stream=sys.stdout):
    header = ('scene', 'check', 'against', 'measured', 'expected', '|diff|', 'allowed', 'result')
    rows = []
    for r in results:
        if r.worst is not None:
            i, m, e, diff, allowed = r.worst
            where = '' if r.n == 1 else ' [%d/%d]' % (i, r.n)
            rows.append((r.scene, r.check + where, r.kind, fmt(m), fmt(e), fmt(diff), fmt(allowed),
                         'pass' if r.passed else 'FAIL'))
        else:
            rows.append((r.scene, r.check, r.kind, '-', '-', '-', '-', 'pass' if r.passed else 'FAIL'))
    widths = [max(len(h), *(len(row[k]) for row in rows)) if rows else len(h) for k, h in enumerate(header)]
    line = '  '.join('%%-%ds' % w for w in widths)
    print(line % header, file=stream)
    print('  '.join('-' * w for w in widths), file=stream)
    for row in rows:
        print(line % row, file=stream)
    notes = [r for r in results if r.note]
    for r in notes:
        print('%s %s: %s' % ('FAIL' if not r.passed else 'note', r.scene, r.note), file=stream)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('table', help='the yade-batch table that was run')
    parser.add_argument('records', help='directory of the records ($YADE_DDA_RECORDS of the run)')
    parser.add_argument('--references', default=os.path.join(HERE, 'references'),
                        help='directory of the stored references (default: %(default)s)')
    parser.add_argument('--logs', default=None, help="yade-batch's log directory (logs <description>.log); "
                        'default: the records directory')
    parser.add_argument('--lines', default=None, help="rows of the table to check, yade-batch's syntax (2,5-7)")
    parser.add_argument('--update', action='store_true', help='write the references from these records')
    args = parser.parse_args(argv)

    rows = readTable(args.table)
    lines = sorted(rows) if args.lines is None else lineList(args.lines)
    unknown = [l for l in lines if l not in rows]
    if unknown:
        parser.error('table %s has no rows on lines %s' % (args.table, ', '.join(map(str, unknown))))
    descriptions = [rows[l]['description'] for l in lines]
    duplicates = sorted(set(d for d in descriptions if descriptions.count(d) > 1))
    if duplicates:
        parser.error('table %s: descriptions must be unique (they name records and references): %s'
                     % (args.table, ', '.join(duplicates)))
    command = 'check.py %s RECORDS --update' % os.path.basename(args.table)
    results, records = [], {}
    for l in lines:
        records[rows[l]['description']] = checkRow(rows[l], args.records, args.references,
                                                   args.logs or args.records, args.update, command, results)
    print('regression check: table %s, %d scenes, records in %s, references in %s'
          % (args.table, len(lines), args.records, args.references))
    printTable(results)
    failedScenes = sorted(set(r.scene for r in results if not r.passed))
    wall = sum((rec or {}).get('run', {}).get('wallTime') or 0.0 for rec in records.values())
    print('%d checks in %d scenes: %d passed, %d failed; scenes failed: %s; scene wall time %.1f s'
          % (len(results), len(lines), sum(r.passed for r in results), sum(not r.passed for r in results),
             ', '.join(failedScenes) if failedScenes else 'none', wall))
    return 1 if failedScenes else 0


if __name__ == '__main__':
    sys.exit(main())
