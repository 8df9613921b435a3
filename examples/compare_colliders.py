# -*- coding: utf-8 -*-
"""Contact detection on slender blocks: the DDA broad phases against YADE's colliders.

A pile of slender hexahedra (1 x 1 x L m logs, laid in crossing layers, each
layer turned 15 degrees off the axes, 2 cm apart) drops onto a fixed layer of
the same logs, as in Wu et al. (2014), Sec. 5.1 (Figs. 10-12). The same blocks are run with each
of the DDA core's broad phases (MSC when built, DESS, NBS, AllPairs) and as
plain YADE Polyhedra under InsertionSortCollider and SpatialQuickSortCollider.
Prints a table, writes bench/out/compare_colliders.json and two plots beside it.

`--scene` picks one of the paper's scenes instead (examples/paper:
hexahedra_drop, slanted_slide, single_block_slide), with the paper's
material, time step and allowed step displacement.

Run with `yade -n -x examples/compare_colliders.py [--blocks 50] [--length 20] [--steps 100]`,
`yade -n -x examples/compare_colliders.py --scene hexahedra_drop --steps 300`,
or `/usr/bin/python3 examples/compare_colliders.py ...`. SI units throughout.
"""
import argparse
import math
import os
import sys

from yade_dda import compareColliders

# Under `yade -x` __file__ is YADE's launcher: find examples/paper from argv[0].
_here = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith('.py') else __file__))
sys.path.insert(0, os.path.join(_here, 'paper'))
import paper_scenes  # noqa: E402


def log(centre, length, angle):
    """Corners of a 1 x 1 m log of `length` [m] along the horizontal direction `angle` [rad], centred at `centre`."""
    c, s = math.cos(angle), math.sin(angle)
    corners = []
    for i in range(8):
        u = (length / 2) * (1 if i & 1 else -1)
        v = 0.5 * (1 if i & 2 else -1)
        w = 0.5 * (1 if i & 4 else -1)
        corners.append((centre[0] + u * c - v * s, centre[1] + u * s + v * c, centre[2] + w))
    return corners


def slenderPile(blocks=50, length=20.0, perLayer=7, spacing=1.5, gap=0.02, turn=math.radians(15)):
    """Slender logs in crossing layers, the first layer fixed: a list of (vertices, fixed), `blocks` long.

    The base is a layer of fixed logs rather than one large slab: YADE's
    Ig2_Polyhedra_Polyhedra_PolyhedraGeom (2023.02a) finds no overlap between a
    20 m log and a 24 m slab it sinks into (it does for logs up to 14 m, and
    for log on log), so YADE's logs would fall through a slab.
    """
    scene = []
    for k in range(blocks):
        layer, i = divmod(k, perLayer)
        angle = turn + (math.pi / 2 if layer % 2 else 0.0)
        offset = (i - (perLayer - 1) / 2) * spacing          # across the log
        z = -0.5 if layer == 0 else 0.5 + gap + (layer - 1) * (1 + gap)
        scene.append((log((-offset * math.sin(angle), offset * math.cos(angle), z), length, angle), layer == 0))
    return scene


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--scene', default='slender', choices=['slender'] + sorted(paper_scenes.SCENES),
                        help="'slender' (the log pile below) or one of the paper's scenes")
    parser.add_argument('--blocks', type=int, default=50, help='blocks including the fixed bottom layer')
    parser.add_argument('--length', type=float, default=20.0, help='log length [m] (slenderness)')
    parser.add_argument('--steps', type=int, default=100)
    parser.add_argument('--dt', type=float, default=1e-3, help='time step [s], the same for DDA and YADE')
    parser.add_argument('--young', type=float, default=1e9, help="Young's modulus [Pa]")
    # Relative to the current directory: under `yade -x` __file__ is YADE's own
    # launcher, not this script.
    parser.add_argument('--out', default=os.path.join('bench', 'out', 'compare_colliders.json'),
                        help='JSON path (plots beside it), relative to the current directory')
    args, _ = parser.parse_known_args(argv)
    if args.scene != 'slender':
        blocks, mat = paper_scenes.SCENES[args.scene]()
        out = args.out if args.out != parser.get_default('out') else \
            os.path.join('bench', 'out', 'compare_colliders_%s.json' % args.scene)
        return compareColliders(blocks, steps=args.steps, dt=paper_scenes.STEP['dt'], gravity=(0, 0, -paper_scenes.G),
                                young=mat['young'], poisson=mat['poisson'], density=mat['density'],
                                frictionAngle=mat['frictionAngle'],
                                integrator=dict(maxDisplacement=paper_scenes.STEP['maxDisplacement']),
                                out=os.path.normpath(out))
    return compareColliders(lambda: slenderPile(args.blocks, args.length), steps=args.steps, dt=args.dt,
                            gravity=(0, 0, -9.81), young=args.young, poisson=0.25, density=2600,
                            frictionAngle=math.radians(30), integrator=dict(maxDisplacement=0.01),
                            out=os.path.normpath(args.out))


result = main(sys.argv[1:])
