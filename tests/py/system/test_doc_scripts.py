"""The README's first script runs as the README says: run by `yade -n -x`, the
block thrown at (3, 0, 7.5) m/s from its 1 x 2 x 3 m box at z 10..13 m is,
after 1000 steps of 1 ms, where the closed form of a throw puts its centroid,
z0 + v0 t - g t^2 / 2 (the README says exactly; 1e-9 m here)."""
import os
import re
import subprocess

import yade_dda

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def first_script(page):
    """The first indented code block of `page` that starts with a '# <name>.py' line."""
    lines = open(os.path.join(ROOT, page)).read().splitlines()
    start = next(i for i, l in enumerate(lines) if re.match(r'^    # \w+\.py', l))
    block = []
    for line in lines[start:]:
        if line and not line.startswith('    '):
            break
        block.append(line[4:])
    return '\n'.join(block).rstrip() + '\n'


def test_the_readme_first_script_throws_the_block_by_the_closed_form(tmp_path):
    script = tmp_path / 'falling.py'
    script.write_text(first_script('README.md'))
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(yade_dda.__file__)) + os.pathsep
               + os.environ.get('PYTHONPATH', ''))
    result = subprocess.run(['yade', '-n', '-x', str(script)], capture_output=True, text=True, timeout=300,
                            env=env, cwd=str(tmp_path), stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    match = re.search(r'^([0-9.e+-]+) Vector3\(([^,]+),([^,]+),([^)]+)\)$', result.stdout, re.M)
    assert match, result.stdout[-2000:]
    t, x, y, z = (float(v) for v in match.groups())
    assert abs(t - 1.0) < 1e-12
    expected = (0.5 + 3 * t, 1.0, 11.5 + 7.5 * t - 9.81 * t * t / 2)
    assert max(abs(a - b) for a, b in zip((x, y, z), expected)) < 1e-9, ((x, y, z), expected)
    assert 'DDA step:' in result.stdout   # printStats()
