#!/usr/bin/python3
"""Writes the seed corpus of fuzz_kernels (tests/fuzz/corpus), deterministically.

Each seed is a recipe (see fuzz_kernels.cpp): byte 0 the mode (0 polyhedron,
1 pair, 2 world), byte 1 the first choice (point-set family, or the first
block's solid), then a tail. Three tails per leading pair: all zeros (every
later choice takes its first option: unit cubes, no rotation, exact
placements), small bytes 0..3 (exact quarter turns, corner on corner, edge on
edge, face on face, at d0 exactly) and pseudo-random bytes.
Run: /usr/bin/python3 tests/fuzz/make_corpus.py
"""
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    out = os.path.join(HERE, 'corpus')
    os.makedirs(out, exist_ok=True)
    rng = random.Random(20240601)
    for mode, name in enumerate(('polyhedron', 'pair', 'world')):
        for first in range(10):
            tails = {'zeros': bytes(96),
                     'small': bytes(rng.randrange(4) for _ in range(96)),
                     'random': bytes(rng.randrange(256) for _ in range(96))}
            for tail, data in tails.items():
                with open(os.path.join(out, '%s-%d-%s' % (name, first, tail)), 'wb') as f:
                    f.write(bytes((mode, first)) + data)


if __name__ == '__main__':
    main()
