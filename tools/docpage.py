"""What gen_docs.py and gen_api.py share: writing a generated page, or checking that it is current."""
import os
import sys


def writeOrCheck(target, text, check, repo):
    """Writes `text` to `target` when it differs (says which); with `check`, writes nothing and exits 1
    when the page is stale."""
    name = os.path.relpath(target, repo)
    with open(target) if os.path.exists(target) else open(os.devnull) as f:
        current = f.read()
    if check:
        if current != text:
            print('%s is stale: run make docs' % name)
            sys.exit(1)
        return
    if current != text:
        with open(target, 'w') as f:
            f.write(text)
        print('wrote %s' % name)
    else:
        print('%s is up to date' % name)
