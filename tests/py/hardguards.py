"""Guards shared by the hard-case suite (test_hard_cases.py): what every hard
scene must satisfy, checked after every step.

- finite: every block's vertices, 12 rates, stress and strain are finite;
- penetration: no two blocks overlap by more than the documented tolerance
  (doc/testing.md, "Penetration tolerance"), measured two ways: the core's deepest
  closed contact (stats()['maxPenetration'], the linearised gap at the end of
  the step) and the true overlap of the blocks' current shapes, computed here
  independently of the core's narrow phase (separating axes over all face
  normals and all edge-pair cross products, see `overlap_depth`);
- energy: kinetic + gravitational + elastic strain + contact spring energy
  never exceeds its initial value by more than round-off (DDA's time scheme
  dissipates, see doc/DESIGN.md; it must never create energy);
- open-close iteration: no step accepted unconverged
  (stats()['openCloseFailures'] stays 0) and the dt cuts it causes stay
  within a bound per step and in total;
- determinism: `fingerprint` of the scene, compared exactly between runs.

Energy terms (SI units; E, nu, size of each block from its material and
initial volume):
    kinetic      scenes.kinetic_energy (translation, rotation and strain rates)
    gravity      -m g . c
    strain       V/2 sigma^T C sigma, C the compliance (engineering shears), i.e.
                 V/2 eps^T E eps for the strain that carries the stress
    normal       N^2 / (2 kn) per closed contact (N = kn x its compression)
    shear        |S|^2 / (2 ks) per locked contact (S = ks x its stretch)
with kn = contactPenaltyFactor x min(E size) of the pair and ks =
shearStiffnessRatio x kn, as the core sets them (ContactEquations.cpp).
"""
import math

import numpy

import yade_dda
from yade_dda import O

import scenes as S


def compliance(young, poisson):
    """6x6 compliance matrix (Voigt order xx, yy, zz, xy, yz, zx, engineering shears)."""
    lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = young / (2 * (1 + poisson))
    E = numpy.zeros((6, 6))
    E[:3, :3] = lam
    for i in range(3):
        E[i, i] = lam + 2 * mu
        E[i + 3, i + 3] = mu
    return numpy.linalg.inv(E)


def _cross(a, b):
    """Row-wise cross products of broadcastable (..., 3) arrays (numpy.cross is slow on small arrays)."""
    return numpy.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                        a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                        a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


class Topology:
    """Index arrays of a block's faces (first three corners) and edges, for `overlap_depth`."""

    def __init__(self, faces, edges):
        self.faces = numpy.array([f[:3] for f in faces], dtype=int)
        self.edges = numpy.array(edges, dtype=int)


def overlap_depth(A, topologyA, B, topologyB):
    """Penetration depth [m] of two convex polyhedra (> 0 overlapping, <= 0 apart).

    A, B: (n, 3) arrays of corners. For convex sets the depth is the smallest
    overlap of their projections over all directions, attained at a face
    normal of the Minkowski difference: a face normal of either block or the
    cross product of an edge of each. Taking every such axis (a superset of
    the Minkowski faces) gives exactly the depth. Blocks whose bounding boxes
    are apart return minus the boxes' gap (the depth is below it). Pure numpy,
    independent of the core's narrow phase.
    """
    boxGap = numpy.max(numpy.maximum(A.min(axis=0) - B.max(axis=0), B.min(axis=0) - A.max(axis=0)))
    if boxGap > 0:
        return -float(boxGap)
    axes = [_cross(V[t.faces[:, 1]] - V[t.faces[:, 0]], V[t.faces[:, 2]] - V[t.faces[:, 0]])
            for V, t in ((A, topologyA), (B, topologyB))]
    ea = A[topologyA.edges[:, 1]] - A[topologyA.edges[:, 0]]
    eb = B[topologyB.edges[:, 1]] - B[topologyB.edges[:, 0]]
    edgeAxes = _cross(ea[:, None, :], eb[None, :, :]).reshape(-1, 3)
    lengths = (numpy.sqrt((ea * ea).sum(axis=1))[:, None] * numpy.sqrt((eb * eb).sum(axis=1))[None, :]).reshape(-1)
    norms = numpy.sqrt((edgeAxes * edgeAxes).sum(axis=1))
    axes.append(edgeAxes[norms > 1e-12 * lengths])   # parallel edges: no axis of their own
    axes = numpy.vstack(axes)
    axes /= numpy.sqrt((axes * axes).sum(axis=1))[:, None]
    pa, pb = A @ axes.T, B @ axes.T
    overlap = numpy.minimum(pa.max(axis=0) - pb.min(axis=0), pb.max(axis=0) - pa.min(axis=0))
    return float(overlap.min())


def spring_stiffness(integrator, a, b, info):
    """(kn, ks) [N/m] of a contact between bodies a and b, as the core computes them."""
    factor = integrator.contactPenaltyFactor
    kn = factor * min(info[a]['young'] * info[a]['size'], info[b]['young'] * info[b]['size'])
    return kn, integrator.shearStiffnessRatio * kn


def fingerprint():
    """Everything that could differ between two runs of one scene: time, and per
    block its vertices, 12 rates and stress, as exact floats."""
    out = [O.time, O.iter]
    for b in yade_dda.scene.current(create=False).bodyOfBlock:
        blk = yade_dda.block(b)
        out.append((b, tuple(tuple(v) for v in blk.vertices), tuple(blk.velocity), tuple(blk.stress)))
    out.append(tuple((c.id1, c.id2, c.kind, c.state, c.normalForce, tuple(c.shearForce))
                     for c in yade_dda.contacts()))
    return out


class Guard:
    """Checks a running scene after every step (call `check()` after O.step(), or `run(n)`).

    bodies: the scene's DDA body ids (moving and fixed); gravity [m/s^2];
    extraPenetration [m]: added to the penetration tolerance where a case
    says why; maxCutsPerStep / maxCutFraction: open-close dt cuts allowed in
    one step (5: dt never below 0.3^5 = 1/400 of the step tried) and over
    the run per step taken (5%); `pairs` limits the geometric overlap check
    to these body pairs (default: every pair with a moving block).
    """

    def __init__(self, bodies, gravity, extraPenetration=0.0, maxCutsPerStep=5, maxCutFraction=0.05, pairs=None):
        self.bodies = list(bodies)
        self.g = numpy.asarray(gravity, float)
        self.extraPenetration = extraPenetration
        self.maxCutsPerStep = maxCutsPerStep
        self.maxCutFraction = maxCutFraction
        # A concave block enters as its members: each member's geometry is its own part's (`shapes`), its
        # state the block's (`views`, shared by the members; its energy counted once, by `owner`).
        scene = yade_dda.scene.current(create=False)
        part = {b: scene.core.partOfBody(b) for b in self.bodies}
        self.owner = {b: scene.core.bodyOf(part[b]) for b in self.bodies}
        self.shapes = {b: yade_dda.scene.BlockView(scene, part[b]) for b in self.bodies}
        self.views = {b: yade_dda.block(b) for b in self.bodies}
        self.info = {}
        for b, blk in self.views.items():
            mat = O.bodies[b].material
            shape = self.shapes[b]
            self.info[b] = dict(fixed=blk.fixed, young=mat.young, size=blk.volume ** (1.0 / 3.0),
                                compliance=compliance(mat.young, mat.poisson),
                                topology=Topology([tuple(f) for f in shape.faces], [tuple(e) for e in shape.edges]))
        self.moving = [b for b in self.bodies if not self.info[b]['fixed']]
        first = {}
        for b in self.moving:
            first.setdefault(self.owner[b], b)
        self.movingBlocks = list(first.values())   # one member per moving DDA block
        if pairs is None:
            pairs = [(a, b) for i, a in enumerate(self.bodies) for b in self.bodies[i + 1:]
                     if not (self.info[a]['fixed'] and self.info[b]['fixed']) and self.owner[a] != self.owner[b]]
        self.pairs = list(pairs)
        self.fixedCorners = {b: self.corners(b) for b in self.bodies if self.info[b]['fixed']}
        self.integrator = O.engines[-1]
        self.mass = sum(self.views[b].mass for b in self.movingBlocks)
        self.size = max(self.info[b]['size'] for b in self.bodies)
        self.kn = self.integrator.contactPenaltyFactor * min(self.info[b]['young'] * self.info[b]['size']
                                                             for b in self.bodies)
        self.steps = 0
        self.cuts = 0
        self.worstPenetration = 0.0        # stats()['maxPenetration'], over the run [m]
        self.worstOverlap = -math.inf      # geometric overlap depth, over the run [m]
        self.worstGain = -math.inf         # energy minus initial energy, over the run [J]
        self.e0, parts = self.energy(parts=True)
        self.kineticMax = parts['kinetic']

    def corners(self, b):
        return numpy.array([tuple(v) for v in self.shapes[b].vertices])

    def energy(self, parts=False):
        """Total mechanical energy [J] (see the module docstring); `parts` gives the terms."""
        kinetic = gravity = strain = springs = 0.0
        for b in self.movingBlocks:
            blk = self.views[b]
            mass, volume = blk.mass, blk.volume
            kinetic += S.kinetic_energy(mass, volume, blk.secondMoment, blk.velocity)
            gravity -= mass * float(self.g @ numpy.asarray(tuple(blk.centroid)))
            sigma = numpy.asarray(tuple(blk.stress))
            strain += 0.5 * volume * float(sigma @ self.info[b]['compliance'] @ sigma)
        for c in yade_dda.contacts():
            if c.state == 'open':
                continue
            kn, ks = spring_stiffness(self.integrator, c.id1, c.id2, self.info)
            springs += c.normalForce ** 2 / (2 * kn)
            if c.state == 'locked':
                springs += c.shearForce.squaredNorm() / (2 * ks)
        total = kinetic + gravity + strain + springs
        return (total, dict(kinetic=kinetic, gravity=gravity, strain=strain, springs=springs)) if parts else total

    def penetration(self):
        """The documented penetration tolerance (doc/testing.md, "Penetration tolerance") [m]:

            d_tol = 2 W / kn + sqrt(2 K / kn) + 1e-6 L   (+ extraPenetration)

        W the weight of all moving blocks, K the largest kinetic energy they
        have had so far in the run, kn the softest contact stiffness of the
        scene, L the largest block size. The first two terms are how deep one
        single penalty spring sinks holding the whole weight applied suddenly
        and stopping the whole kinetic energy (kn d^2 / 2 = K): a correct
        penalty contact cannot sink deeper, however the load is shared. The
        last is the second-order geometry the linearised gap leaves out in one
        step (a rotation r per step: r^2 L / 2, 1e-6 L at r = 1.4e-3).
        """
        return (2 * self.mass * float(numpy.linalg.norm(self.g)) / self.kn
                + math.sqrt(2 * self.kineticMax / self.kn) + 1e-6 * self.size + self.extraPenetration)

    def energySlack(self):
        """Round-off allowance of the energy guard [J]: 1e-9 of the energy at
        stake, W L (the weight over one block size) plus K (as in `penetration`)."""
        return 1e-9 * (self.mass * float(numpy.linalg.norm(self.g)) * self.size + self.kineticMax)

    def overlap(self, corners=None):
        """Largest geometric overlap depth [m] over the guarded pairs, and the pair."""
        if corners is None:
            corners = {b: self.corners(b) for b in self.moving}
        worst, which = -math.inf, None
        for a, b in self.pairs:
            A = self.fixedCorners[a] if a in self.fixedCorners else corners[a]
            B = self.fixedCorners[b] if b in self.fixedCorners else corners[b]
            d = overlap_depth(A, self.info[a]['topology'], B, self.info[b]['topology'])
            if d > worst:
                worst, which = d, (a, b)
        return worst, which

    def check(self):
        """Asserts every guard for the step just taken."""
        self.steps += 1
        s = yade_dda.stats()
        where = 'step %d (t = %.6g s, dt = %.3g s)' % (O.iter, O.time, s['dt'])
        corners = {}
        for b in self.moving:
            blk = self.views[b]
            corners[b] = self.corners(b)
            finite = numpy.isfinite(corners[b]).all() and all(
                math.isfinite(x) for x in tuple(blk.velocity) + tuple(blk.stress) + tuple(blk.strain))
            assert finite, 'non-finite state of body %d at %s' % (b, where)
        assert s['openCloseFailures'] == 0, 'open-close iteration accepted unconverged at %s' % where
        assert s['openCloseCuts'] <= self.maxCutsPerStep, \
            '%d open-close dt cuts in one step at %s (bound %d)' % (s['openCloseCuts'], where, self.maxCutsPerStep)
        self.cuts += s['openCloseCuts']
        assert self.cuts <= max(self.maxCutsPerStep, self.maxCutFraction * self.steps), \
            '%d open-close dt cuts in %d steps at %s (bound %.3g per step)' % (self.cuts, self.steps, where,
                                                                            self.maxCutFraction)
        e, parts = self.energy(parts=True)
        assert math.isfinite(e), 'non-finite energy at %s' % where
        self.kineticMax = max(self.kineticMax, parts['kinetic'])
        tolerance = self.penetration()
        self.worstPenetration = max(self.worstPenetration, s['maxPenetration'])
        assert s['maxPenetration'] <= tolerance, \
            'contact penetration %.3e m at %s (tolerance %.3e m)' % (s['maxPenetration'], where, tolerance)
        depth, pair = self.overlap(corners)
        self.worstOverlap = max(self.worstOverlap, depth)
        assert depth <= tolerance, \
            'bodies %s overlap by %.3e m at %s (tolerance %.3e m)' % (pair, depth, where, tolerance)
        self.worstGain = max(self.worstGain, e - self.e0)
        assert e - self.e0 <= self.energySlack(), \
            'energy gain %.3e J at %s (initial %.6e J, slack %.3e J)' % (e - self.e0, where, self.e0,
                                                                        self.energySlack())

    def run(self, steps, every=None):
        """O.step() `steps` times, checking after each; `every(step)` is called too."""
        for k in range(steps):
            O.step()
            self.check()
            if every is not None:
                every(k)
