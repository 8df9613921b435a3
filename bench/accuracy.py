"""Benchmark: what accuracy costs in time.

Sweeps DDA's accuracy knobs on scenes with closed forms and records, for every
run, the error against the closed form (SI units) and the wall time per
simulated second. The same incline is also run with YADE's explicit polyhedra
DEM at fractions of a P-wave time step, so both methods' cost of a given
accuracy sits on one plot.

Scenes (all: E = 10 GPa, nu = 0.25, rho = 2600 kg/m^3 except the bounce,
g = 9.81 m/s^2, simulated time tEnd = 1 s, --quick 0.3 s):

  freefall        1 x 2 x 3 m block thrown at (3, 0, 7.5) m/s. Error: |c - c_exact| [m]
                  of the centroid at tEnd (parabola; Shi's scheme is exact for it).
  incline_smooth  1 m cube on a fixed 6 x 3 x 1 m slab, gravity tilted 30 deg, no friction.
                  Error: |s - s_exact| [m], s the slide at tEnd, s_exact = g sin(a) t^2/2.
  incline_friction  the same with 20 deg friction: s_exact = g (sin a - tan phi cos a) t^2/2.
  wedge           tetrahedral wedge (keel 2 m, plunge 35 deg) in a 90 deg valley of two
                  fixed slabs, plane friction set for a factor of safety 0.8 (limit
                  equilibrium, Hoek & Bray). Error: |s - s_exact| [m] along the keel,
                  s_exact = g sin(psi) (1 - FS) t^2/2.
  bounce          1 m cube (E = 100 MPa: rigid contact time pi sqrt(m / 4 kn) = 1.3 ms) dropped flat
                  from h = 0.05 m onto a fixed floor, no friction. Physically elastic: the
                  block rebounds with all of m g h. Error: the energy the first impact
                  dissipated over the drop energy, (E0 - E_sep) / (m g h) [-], E_sep at
                  the first step after the impact with no closed contact (1 if the block
                  never leaves the floor), E = kinetic + gravity + strain + contact
                  springs, evaluated every step; the largest gain over E0 is recorded too
                  (DDA must never create energy), and the dissipation by tEnd.

Knobs (DDAIntegrator / MSCCollider parameters): dt [s], maxDisplacementRatio [-]
(with maxDisplacement = 0 and dt = 1e-2 s, so the displacement control sets the
step), contactPenaltyFactor [-], criticalLength [m] and
segments (MSC; accuracy must not change, detection work does). Each knob runs in
its own process, its points one after another, each with one core thread.

Cost: wallPerSimulatedSecond [s/s] = wall time of the run calls / tEnd (the
per-step monitor that reads stats() and the bounce's energy is timed apart and
taken out; it makes the integrator write the bodies every step, the same for
every point). YADE: wall time of O.run / tEnd.

Writes bench/out/accuracy.json (machine, settings, every point) and PNGs
bench/out/accuracy_<knob>.png (a panel per scene; lower left is better; Pareto-
optimal points filled). Run: make bench, or
  /usr/bin/python3 bench/accuracy.py [--quick] [--knobs dt,segments] [--scenes incline_friction]
(YADE_DDA_BUILD=<build>/py to use a build tree instead of the installed package).

Your own scene: a script defining build(), measure() (the error, a float or a dict
with 'error') and tEnd [s] (see yade_dda.tools.accuracy):
  /usr/bin/python3 bench/accuracy.py --scene my_scene.py --knob dt=1e-2,1e-3,1e-4
"""
import argparse
import json
import math
import os
import runpy
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import benchtasks  # noqa: E402  (bench/benchtasks.py: the child-process protocol)
G = 9.81
ROCK = dict(young=1e10, poisson=0.25, density=2600.0)

# knob -> values (full, quick), scenes, base settings of every run of that knob
PLAN = {
    'dt': dict(full=[1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4], quick=[1e-2, 3e-3, 1e-3],
               scenes=['freefall', 'incline_smooth', 'incline_friction', 'wedge', 'bounce'], base={}),
    'maxDisplacementRatio': dict(full=[0.18, 0.06, 0.018, 6e-3, 1.8e-3, 6e-4], quick=[0.06, 6e-3],
                                 scenes=['incline_friction', 'wedge', 'bounce'],
                                 base=dict(dt=1e-2, maxDisplacement=0.0)),
    'contactPenaltyFactor': dict(full=[1, 3, 10, 40, 100, 300, 1000], quick=[4, 40, 400],
                                 scenes=['incline_friction', 'wedge', 'bounce'], base={}),
    'criticalLength': dict(full=[0.0, 0.25, 0.5, 1.0, 2.0, 100.0], quick=[0.0, 0.5],
                           scenes=['incline_friction', 'wedge'], base={}),
    'segments': dict(full=[1, 2, 3, 6, 12], quick=[1, 6], scenes=['incline_friction', 'wedge'], base={}),
}
MSC_KNOBS = ('criticalLength', 'segments')
YADE_FRACTIONS = dict(full=[1.0, 0.5, 0.2, 0.1, 0.05], quick=[0.5, 0.2])
YADE_SCENES = dict(full=['incline_friction', 'incline_smooth'], quick=['incline_friction'])


def _importDDA():
    if os.environ.get('YADE_DDA_BUILD'):
        sys.path.insert(0, os.environ['YADE_DDA_BUILD'])
    import yade_dda
    return yade_dda


# ------------------------------------------------------------------ scenes

def box(lo, hi):
    """Corners of the axis-aligned box [lo, hi] [m]."""
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def _add(*terms):
    """Sum of scale * vector terms: _add((1, p), (2, q)) = p + 2 q."""
    return tuple(sum(s * v[i] for s, v in terms) for i in range(3))


def _dot(p, q):
    return sum(p[i] * q[i] for i in range(3))


class Scene:
    """A closed-form scene: build() makes it in O (already reset), measure() returns the
    error dict after the run, tEnd [s]. `context` holds ids and start positions."""

    def __init__(self, name, build, measure, errorMeasure, unit, maxDisplacement, monitor=None):
        self.name, self._build, self._measure = name, build, measure
        self.errorMeasure, self.unit, self.maxDisplacement = errorMeasure, unit, maxDisplacement
        self.monitorFactory = monitor
        self.context = {}

    def build(self):
        self.context.clear()
        self._build(self.context, self.maxDisplacement)

    def measure(self):
        return self._measure(self.context)

    def monitor(self):
        """A per-step callable for yade_dda.tools.accuracy.runPoint (None when the scene has none): it makes
        the scene's monitor in `context` at the first step after build() and calls it every step."""
        if self.monitorFactory is None:
            return None

        def step():
            mon = self.context.get('monitor')
            if mon is None:
                mon = self.context['monitor'] = self.monitorFactory(self.context)
            mon()
        return step


def _material(young=ROCK['young'], frictionDeg=0.0):
    from yade_dda import O
    from yade import wrapper
    return O.materials.append(wrapper.PolyhedraMat(young=young, poisson=ROCK['poisson'], density=ROCK['density'],
                                                   frictionAngle=math.radians(frictionDeg)))


def _freefallBuild(ctx, maxDisplacement):
    from yade_dda import O, ddaBlock, DDAIntegrator
    ctx['x0'], ctx['v0'] = (0.5, 1.0, 51.5), (3.0, 0.0, 7.5)
    ctx['id'] = O.bodies.append(ddaBlock(box((0, 0, 50), (1, 2, 53)), material=_material(), velocity=ctx['v0']))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=maxDisplacement, threads=1,
                               label='dda')]


def _freefallMeasure(ctx):
    from yade_dda import O, block
    t, c = O.time, block(ctx['id']).centroid
    exact = [ctx['x0'][i] + ctx['v0'][i] * t - (G if i == 2 else 0.0) * t * t / 2 for i in range(3)]
    return dict(error=math.sqrt(sum((c[i] - exact[i]) ** 2 for i in range(3))), exact=exact)


SLOPE_DEG = 30.0


def _inclineGravity():
    a = math.radians(SLOPE_DEG)
    return (G * math.sin(a), 0.0, -G * math.cos(a))


def _inclineExact(phiDeg, t):
    a = math.radians(SLOPE_DEG)
    return G * (math.sin(a) - math.tan(math.radians(phiDeg)) * math.cos(a)) * t * t / 2


def _inclineBuild(phiDeg):
    def build(ctx, maxDisplacement):
        from yade_dda import O, ddaBlock, DDAIntegrator, block
        mat = _material(frictionDeg=phiDeg)
        O.bodies.append(ddaBlock(box((-1, -1.5, -1), (5, 1.5, 0)), material=mat, fixed=True))
        ctx['id'] = O.bodies.append(ddaBlock(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=mat))
        ctx['x0'] = (0.0, 0.0, 0.5)
        O.engines = [DDAIntegrator(dt=1e-3, gravity=_inclineGravity(), maxDisplacement=maxDisplacement, threads=1,
                                   label='dda')]
    return build


def _inclineMeasure(phiDeg):
    def measure(ctx):
        from yade_dda import O, block
        blk = block(ctx['id'])
        c = blk.centroid
        s, exact = c[0] - ctx['x0'][0], _inclineExact(phiDeg, O.time)
        return dict(error=abs(s - exact), relativeError=(s - exact) / exact, slide=s, exact=exact,
                    normalDisplacement=c[2] - ctx['x0'][2], rotation=blk.rotation.toRotationVector().norm())
    return measure


WEDGE = dict(fs=0.8, plungeDeg=35.0)


def _wedgeGeometry():
    """Keel l, plane traces dA, dB, inward normals nA, nB and reactions per unit weight
    (RA, RB) of a 90 deg valley with a vertical bisector whose keel plunges psi."""
    psi = math.radians(WEDGE['plungeDeg'])
    keel = (math.cos(psi), 0.0, -math.sin(psi))
    across, up = (0.0, 1.0, 0.0), (math.sin(psi), 0.0, math.cos(psi))
    r = math.sqrt(0.5)
    dA, dB = _add((-r, across), (r, up)), _add((r, across), (r, up))
    nA, nB = _add((r, across), (r, up)), _add((-r, across), (r, up))
    c = _dot(nA, nB)
    RA = (nA[2] - c * nB[2]) / (1 - c * c)
    RB = (nB[2] - c * nA[2]) / (1 - c * c)
    return psi, keel, dA, dB, nA, nB, RA, RB


def _wedgeBuild(ctx, maxDisplacement):
    from yade_dda import O, ddaBlock, DDAIntegrator, block
    psi, keel, dA, dB, nA, nB, RA, RB = _wedgeGeometry()
    phi = math.atan(WEDGE['fs'] * math.sin(psi) / (RA + RB))   # FS = (RA + RB) tan(phi) / sin(psi)
    planes = _material(frictionDeg=math.degrees(phi))
    rock = _material(frictionDeg=60.0)       # the smaller angle of a pair counts: the planes'
    origin = (3.0, -2.0, 10.0)

    def slab(trace, normal):
        axes = (keel, trace, _add((-1.0, normal)))
        return [_add((1.0, origin), (x, axes[0]), (y, axes[1]), (z, axes[2]))
                for x in (-1.0, 4.5) for y in (-1.0, 2.0) for z in (0.0, 1.0)]
    O.bodies.append(ddaBlock(slab(dA, nA), material=planes, fixed=True))
    O.bodies.append(ddaBlock(slab(dB, nB), material=planes, fixed=True))
    ctx['id'] = O.bodies.append(ddaBlock([origin, _add((1.0, origin), (2.0, keel)),
                                          _add((1.0, origin), (1.0, keel), (1.0, dA)),
                                          _add((1.0, origin), (1.0, keel), (1.0, dB))], material=rock))
    ctx['keel'], ctx['psi'], ctx['phiDeg'] = keel, psi, math.degrees(phi)
    ctx['c0'] = tuple(sum(p[i] for p in [origin, _add((1.0, origin), (2.0, keel)),
                                          _add((1.0, origin), (1.0, keel), (1.0, dA)),
                                          _add((1.0, origin), (1.0, keel), (1.0, dB))]) / 4 for i in range(3))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=maxDisplacement, threads=1, label='dda')]


def _wedgeMeasure(ctx):
    from yade_dda import O, block
    c = block(ctx['id']).centroid
    d = [c[i] - ctx['c0'][i] for i in range(3)]
    s = _dot(d, ctx['keel'])
    exact = G * math.sin(ctx['psi']) * (1 - WEDGE['fs']) * O.time ** 2 / 2
    off = math.sqrt(max(_dot(d, d) - s * s, 0.0))
    return dict(error=abs(s - exact), relativeError=(s - exact) / exact, slide=s, exact=exact,
                offKeel=off, phiPlanesDeg=ctx['phiDeg'])


BOUNCE = dict(drop=0.05, young=1e8)


def _bounceBuild(ctx, maxDisplacement):
    from yade_dda import O, ddaBlock, DDAIntegrator
    mat = _material(young=BOUNCE['young'])
    ctx['floor'] = O.bodies.append(ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=mat, fixed=True))
    h = BOUNCE['drop']
    ctx['id'] = O.bodies.append(ddaBlock(box((-0.5, -0.5, h), (0.5, 0.5, 1 + h)), material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=maxDisplacement, threads=1, label='dda')]


class _EnergyMonitor:
    """Total mechanical energy of the bounce after every step [J]: kinetic (translation,
    rotation, strain rates) + gravity - m g.c + strain V/2 sigma C sigma + contact springs
    N^2/(2 kn) (+ |S|^2/(2 ks) when locked), kn = contactPenaltyFactor x min(E size)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.e0 = None
        self.maxGain = -math.inf
        self.kn = None
        self.phase, self.atSeparation, self.separationTime = 'falling', None, None

    def energy(self):
        import numpy
        import yade_dda
        from yade_dda import O
        if self.kn is None:                  # as the core: kn = contactPenaltyFactor x min(E size), size = V^(1/3)
            sys.path.insert(0, os.path.join(ROOT, 'tests', 'py'))
            import scenes
            import hardguards
            self.kinetic = scenes.kinetic_energy
            mat = O.bodies[self.ctx['id']].material
            self.compliance = hardguards.compliance(mat.young, mat.poisson)
            dda = [e for e in O.engines if type(e).__name__ == 'DDAIntegrator'][0]
            size = min(yade_dda.block(b).volume ** (1 / 3.0) for b in (self.ctx['id'], self.ctx['floor']))
            self.kn = dda.contactPenaltyFactor * mat.young * size
            self.ks = dda.shearStiffnessRatio * self.kn
        blk = yade_dda.block(self.ctx['id'])
        kinetic = self.kinetic(blk.mass, blk.volume, blk.secondMoment, blk.velocity)
        gravity = blk.mass * G * blk.centroid[2]
        sigma = numpy.asarray(tuple(blk.stress))
        strain = 0.5 * blk.volume * float(sigma @ self.compliance @ sigma)
        springs = 0.0
        for c in yade_dda.contacts():
            if c.state == 'open':
                continue
            springs += c.normalForce ** 2 / (2 * self.kn)
            if c.state == 'locked':
                springs += c.shearForce.squaredNorm() / (2 * self.ks)
        return kinetic + gravity + strain + springs

    def __call__(self):
        import yade_dda
        e = self.energy()
        if self.e0 is None:
            self.e0 = e
        self.maxGain = max(self.maxGain, e - self.e0)
        self.last = e
        closed = any(c.state != 'open' for c in yade_dda.contacts())
        if self.phase == 'falling' and closed:
            self.phase = 'impact'
        elif self.phase == 'impact' and not closed:      # the first separation: what the impact kept
            self.phase, self.atSeparation, self.separationTime = 'flight', e, yade_dda.O.time


def _bounceMeasure(ctx):
    from yade_dda import O, block
    mon = ctx['monitor']
    blk = block(ctx['id'])
    mgh = blk.mass * G * BOUNCE['drop']
    # e0 is the energy after the first step: in free flight the scheme conserves it exactly
    # (kinetic + potential of a constant-acceleration step), so it equals m g (h + 0.5).
    expected0 = blk.mass * G * (BOUNCE['drop'] + 0.5)
    slack = 1e-9 * mgh
    lost = mon.e0 - (mon.atSeparation if mon.atSeparation is not None else mon.last)
    return dict(error=lost / mgh, separated=mon.atSeparation is not None, separationTime=mon.separationTime,
                dissipatedAtEnd=(mon.e0 - mon.last) / mgh, maxGain=mon.maxGain,
                maxGainRelative=mon.maxGain / mgh, energyCreated=bool(mon.maxGain > slack), gainSlack=slack,
                dropEnergy=mgh, firstStepEnergyError=(mon.e0 - expected0) / mgh,
                finalHeight=blk.centroid[2] - 0.5, finalVerticalVelocity=blk.velocity[2])


SCENES = {
    'freefall': lambda: Scene('freefall', _freefallBuild, _freefallMeasure,
                              '|c - c_exact|: distance of the centroid from the parabola at tEnd', 'm', 0.05),
    'incline_smooth': lambda: Scene('incline_smooth', _inclineBuild(0.0), _inclineMeasure(0.0),
                                    '|s - s_exact|: slide along the slope at tEnd, s_exact = g sin(a) t^2/2',
                                    'm', 0.02),
    'incline_friction': lambda: Scene('incline_friction', _inclineBuild(20.0), _inclineMeasure(20.0),
                                      '|s - s_exact|: slide at tEnd, s_exact = g (sin a - tan phi cos a) t^2/2 '
                                      '(a = 30 deg, phi = 20 deg)', 'm', 0.02),
    'wedge': lambda: Scene('wedge', _wedgeBuild, _wedgeMeasure,
                           '|s - s_exact|: slide along the keel at tEnd, s_exact = g sin(psi) (1 - FS) t^2/2 '
                           '(psi = 35 deg, FS = 0.8)', 'm', 0.02),
    'bounce': lambda: Scene('bounce', _bounceBuild, _bounceMeasure,
                            '(E0 - E_sep) / (m g h): energy the first impact dissipated over the drop energy, '
                            'E_sep at the first step after it with no closed contact (elastic: 0; 1 when the '
                            'block never leaves the floor by tEnd, then E_sep = E(tEnd))', '-',
                            0.02, monitor=_EnergyMonitor),
}


# ------------------------------------------------------------------ YADE's explicit polyhedra DEM

def pWaveTimeStep(volume, young, density):
    """The P-wave time step [s] of a block: r / sqrt(E / rho), r [m] the radius of the sphere
    of the block's volume. YADE's utils.PWaveTimeStep() is this formula over spheres only
    (for polyhedra it returns 1.0 with a warning), so it is applied here to the cube."""
    return (3 * volume / (4 * math.pi)) ** (1 / 3.0) / math.sqrt(young / density)


class _YadeDiagnosis:
    """Per-step record of the YADE incline's contact (untimed diagnostic run): the normal
    force over m g cos(a), the shear force over tan(phi) x the normal force (1 = sliding),
    the block's tilt and the fraction of steps with no force."""

    def __init__(self, body, phiDeg):
        from yade_dda import O
        self.body, self.tanPhi = body, math.tan(math.radians(phiDeg))
        self.weightNormal = O.bodies[body].state.mass * G * math.cos(math.radians(SLOPE_DEG))
        self.n = self.zero = 0
        self.normal = self.shear = self.shearMax = 0.0
        self.normalMax, self.tiltMax = 0.0, 0.0

    def __call__(self):
        from yade_dda import O
        fn = fs = 0.0
        for i in O.interactions:
            if i.isReal and self.body in (i.id1, i.id2):
                fn += i.phys.normalForce.norm()
                fs += i.phys.shearForce.norm()
        self.n += 1
        self.zero += fn == 0.0
        self.normal += fn / self.weightNormal
        self.normalMax = max(self.normalMax, fn / self.weightNormal)
        if self.tanPhi > 0 and fn > 0:
            self.shear += fs / (self.tanPhi * fn)
        self.tiltMax = max(self.tiltMax, O.bodies[self.body].state.ori.toAxisAngle()[1])

    def summary(self):
        n = max(self.n, 1)
        return dict(meanNormalOverWeight=self.normal / n, maxNormalOverWeight=self.normalMax,
                    stepsWithoutForce=self.zero / n,
                    meanShearOverFriction=(self.shear / max(self.n - self.zero, 1)) if self.tanPhi > 0 else None,
                    maxTiltRad=self.tiltMax)


_yadeDiagnosis = {}


def yadeIncline(phiDeg, fraction, tEnd, diagnose=False):
    """The incline with YADE's own explicit DEM: Polyhedra bodies, InsertionSortCollider,
    Ig2_Polyhedra_Polyhedra_PolyhedraGeom, Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys,
    Law2_PolyhedraGeom_PolyhedraPhys_Volumetric, NewtonIntegrator(damping=0), one thread,
    O.dt = fraction x pWaveTimeStep. Same bodies, material and tilted gravity as DDA."""
    from yade_dda import O
    from yade import wrapper, utils, log
    O.reset()
    mat = _material(frictionDeg=phiDeg)
    O.bodies.append(utils.polyhedron(box((-1, -1.5, -1), (5, 1.5, 0)), fixed=True, material=mat))
    b = O.bodies.append(utils.polyhedron(box((-0.5, -0.5, 0), (0.5, 0.5, 1)), material=mat))
    O.engines = [wrapper.ForceResetter(),
                 wrapper.InsertionSortCollider([wrapper.Bo1_Polyhedra_Aabb()], verletDist=0),
                 wrapper.InteractionLoop([wrapper.Ig2_Polyhedra_Polyhedra_PolyhedraGeom()],
                                         [wrapper.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
                                         [wrapper.Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()]),
                 wrapper.NewtonIntegrator(damping=0, gravity=_inclineGravity())]
    for engine in O.engines:
        engine.ompThreads = 1
    try:
        log.setLevel('Polyhedra_support.cpp', log.ERROR)   # per-pair "Unhandled switch case" notices
    except Exception:
        pass
    dtP = pWaveTimeStep(1.0, ROCK['young'], ROCK['density'])
    O.dt = fraction * dtP
    x0 = O.bodies[b].state.pos[0]
    steps = int(round(tEnd / O.dt))
    O.dt = tEnd / steps                      # land on tEnd exactly
    if diagnose:
        _yadeDiagnosis['active'] = _YadeDiagnosis(b, phiDeg)
        command = 'import sys; sys.modules[%r]._yadeDiagnosis["active"]()' % __name__   # this module, also as __main__
        O.engines = O.engines + [wrapper.PyRunner(command=command, iterPeriod=1)]
    start = time.perf_counter()
    O.run(steps, True)
    wall = time.perf_counter() - start
    s, exact = O.bodies[b].state.pos[0] - x0, _inclineExact(phiDeg, O.time)
    return dict(method='YADE polyhedra DEM', scene='incline_friction' if phiDeg else 'incline_smooth',
                fraction=fraction, dt=O.dt, pWaveTimeStep=dtP, steps=steps, simulatedTime=O.time,
                error=abs(s - exact), relativeError=(s - exact) / exact, slide=s, exact=exact,
                normalDisplacement=O.bodies[b].state.pos[2] - 0.5,
                rotation=O.bodies[b].state.ori.toAxisAngle()[1],
                wallSeconds=wall, wallPerSimulatedSecond=wall / tEnd,
                diagnosis=_yadeDiagnosis.pop('active').summary() if diagnose else None)


# ------------------------------------------------------------------ workers

def runKnob(knob, values, sceneNames, base, tEnd, log=print):
    """Sweeps one knob over the named scenes in this process; returns {scene: [points]}."""
    from yade_dda.tools import accuracy
    out = {}
    for name in sceneNames:
        scene = SCENES[name]()
        points = []
        settings = dict(base)
        settings.setdefault('maxDisplacement', scene.maxDisplacement)
        if knob == 'maxDisplacementRatio':
            settings['maxDisplacement'] = 0.0
        if knob in MSC_KNOBS:        # the reference: the same scene with DESS (no collider engine)
            ref = accuracy.runPoint(scene.build, scene.measure, tEnd, settings, scene.monitor())
            ref.update(knob=knob, value=None, collider='DESS', scene=name)
            points.append(ref)
            log('%-16s %s reference (DESS)  error %.6e' % (name, knob, ref['error']))
        for value in values:
            s = dict(settings)
            s[knob] = value
            p = accuracy.runPoint(scene.build, scene.measure, tEnd, s, scene.monitor())
            p.update(knob=knob, value=value, scene=name, collider='MSC' if knob in MSC_KNOBS else 'DESS')
            points.append(p)
            log('%-16s %s = %-8.3g error %.6e %s, %.3f s wall per simulated s, %d steps, detection %.3f ms/step'
                % (name, knob, value, p['error'], scene.unit, p['wallPerSimulatedSecond'], p['steps'],
                   p['detectionMsPerStep']))
        out[name] = dict(points=points, errorMeasure=scene.errorMeasure, unit=scene.unit,
                         settings=settings)
    return out


def worker(task):
    _importDDA()
    if task['kind'] == 'yade':
        points = []
        for name in task['scenes']:
            phi = 20.0 if name == 'incline_friction' else 0.0
            for fraction in task['values']:
                p = yadeIncline(phi, fraction, task['tEnd'])
                points.append(p)
                print('%-16s YADE fraction %.2f (dt %.3g s) error %.6e m, %.3f s wall per simulated s'
                      % (name, fraction, p['dt'], p['error'], p['wallPerSimulatedSecond']), flush=True)
        diagnosis = {}
        for name in task['scenes']:        # an untimed run with a per-step record of the contact forces
            phi = 20.0 if name == 'incline_friction' else 0.0
            d = yadeIncline(phi, 0.5, task['tEnd'], diagnose=True)
            diagnosis[name] = dict(fraction=0.5, relativeError=d['relativeError'], **d['diagnosis'])
            print('%-16s YADE diagnosis %s' % (name, json.dumps(diagnosis[name])), flush=True)
        return dict(kind='yade', points=points, diagnosis=diagnosis)
    if task['kind'] == 'custom':
        return dict(kind='custom', result=runCustom(task['script'], task['knob'], task['values']))
    return dict(kind='knob', knob=task['knob'],
                scenes=runKnob(task['knob'], task['values'], task['scenes'], task['base'], task['tEnd'],
                               log=lambda m: print(m, flush=True)))


def runCustom(script, knob, values):
    """A user's scene: the script defines build(), measure() and tEnd."""
    from yade_dda.tools import accuracy
    namespace = runpy.run_path(script, run_name='accuracy_scene')
    for name in ('build', 'measure', 'tEnd'):
        if name not in namespace:
            raise ValueError('%s must define build(), measure() and tEnd [s]; %s is missing' % (script, name))
    points = accuracy.sweep(namespace['build'], namespace['measure'], knob, values, namespace['tEnd'],
                            base=namespace.get('base'), log=lambda m: print(m, flush=True))
    return dict(script=os.path.abspath(script), knob=knob, tEnd=namespace['tEnd'], points=points)


def spawn(task, taskDir, timeout):
    """Runs one task in its own process (OMP_NUM_THREADS=1); returns its result or raises."""
    name = task['kind'] + '_' + task.get('knob', 'yade')
    task['result'] = os.path.join(taskDir, name + '.result.json')
    proc, result = benchtasks.runWorker(__file__, task, os.path.join(taskDir, name + '.task.json'), timeout,
                                        captureStdout=False)
    if result is None:
        raise RuntimeError('%s failed (exit %d): %s' % (name, proc.returncode, proc.stderr.strip()[-3000:]))
    return result


# ------------------------------------------------------------------ checks, plots, table

def checks(result):
    """What the data must show, evaluated on the data: every value is a boolean or None."""
    out = {}
    knobs = result['knobs']
    if 'dt' in knobs and 'freefall' in knobs['dt']:
        worst = max(p['error'] for p in knobs['dt']['freefall']['points'])
        out['freefall exact to round-off for every dt (|error| < 1e-9 m)'] = dict(value=worst, passed=worst < 1e-9)
    for knob in MSC_KNOBS:
        if knob not in knobs:
            continue
        for scene, data in knobs[knob].items():
            pts = data['points']
            ref = pts[0]['error']
            diff = max(abs(p['error'] - ref) for p in pts)
            allowed = 1e-9 * max(abs(pts[0]['exact']), 1e-3)
            out['%s: %s leaves the error unchanged (to %.1e m)' % (scene, knob, allowed)] = dict(
                value=diff, passed=diff <= allowed)
    for knob, scenes in knobs.items():
        if 'bounce' in scenes:
            gains = [p['maxGainRelative'] for p in scenes['bounce']['points']]
            out['bounce, %s: no energy created (max gain / m g h <= 1e-9)' % knob] = dict(
                value=max(gains), passed=max(gains) <= 1e-9)
    return out


def _label(value):
    if value is None:
        return 'DESS'
    if isinstance(value, float) and value != 0 and (abs(value) < 1e-2 or abs(value) >= 1e3):
        return '%.0e' % value
    return '%g' % value


def plots(result, outDir):
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.figure import Figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from yade_dda.tools.accuracy import paretoFront
    files = []
    floor = 1e-16
    for knob, scenes in result['knobs'].items():
        names = list(scenes)
        msc = knob in MSC_KNOBS
        extra = msc or knob == 'contactPenaltyFactor'
        panels = len(names) + (1 if extra else 0)
        cols = min(3, panels)
        rows = int(math.ceil(panels / float(cols)))
        fig = Figure(figsize=(4.6 * cols, 3.6 * rows + 0.4))
        FigureCanvasAgg(fig)
        for k, name in enumerate(names):
            data = scenes[name]
            pts = data['points']
            ax = fig.add_subplot(rows, cols, k + 1)
            xs = [p['wallPerSimulatedSecond'] for p in pts]
            ys = [max(p['error'], floor) for p in pts]
            front = set(paretoFront([dict(wallPerSimulatedSecond=x, error=y) for x, y in zip(xs, ys)]))
            ax.plot(xs, ys, '-', color='C0', lw=0.8, alpha=0.6)
            for i, p in enumerate(pts):
                ax.plot(xs[i], ys[i], 'o', color='C0', mfc='C0' if i in front else 'white', ms=6)
                ax.annotate(_label(p['value']), (xs[i], ys[i]), fontsize=7, xytext=(3, 3), textcoords='offset points')
            yade = [p for p in result.get('yade', []) if p['scene'] == name] if knob == 'dt' else []
            if yade:
                yx = [p['wallPerSimulatedSecond'] for p in yade]
                yy = [max(p['error'], floor) for p in yade]
                ax.plot(yx, yy, 's-', color='C3', ms=6, lw=0.8, label='YADE polyhedra DEM')
                for p, x, y in zip(yade, yx, yy):
                    ax.annotate('%g dtP' % p['fraction'], (x, y), fontsize=7, color='C3', xytext=(3, -9),
                                textcoords='offset points')
                ax.plot([], [], 'o', color='C0', label='DDA')
                ax.legend(fontsize=7, loc='best')
            ax.set_xscale('log')
            allX = xs + [p['wallPerSimulatedSecond'] for p in yade]
            if max(allX) / min(allX) < 10:       # less than a decade: plain labels (the default overprints)
                from matplotlib.ticker import FormatStrFormatter
                ax.xaxis.set_major_formatter(FormatStrFormatter('%.2g'))
                ax.xaxis.set_minor_formatter(FormatStrFormatter('%.2g'))
            allY = ys + [max(p['error'], floor) for p in yade]     # YADE's points too, on the same axis
            if max(allY) / min(allY) > 20:
                ax.set_yscale('log')
            ax.set_xlabel('wall time per simulated second [s/s]', fontsize=8)
            ax.set_ylabel('error [%s]' % data['unit'], fontsize=8)
            ax.set_title('%s' % name, fontsize=9)
            ax.tick_params(labelsize=7)
            ax.grid(True, which='both', alpha=0.25)
        if msc:
            ax = fig.add_subplot(rows, cols, panels)
            for j, name in enumerate(names):
                pts = [p for p in scenes[name]['points'] if p['value'] is not None]
                ref = scenes[name]['points'][0]
                x = [p['value'] if knob == 'segments' else max(p['value'], 1e-2) for p in pts]
                ax.plot(x, [p['perStep'].get('subUnitTests', 0) for p in pts], 'o-', color='C%d' % j,
                        label='%s sub-unit tests' % name)
                ax.plot(x, [p['perStep'].get('candidatePairs', 0) * 100 for p in pts], 'x--', color='C%d' % j,
                        label='%s candidate pairs x 100' % name)
                ax.axhline(ref['perStep'].get('subUnitTests', 0), color='C%d' % j, lw=0.7, ls=':')
            ax.set_xscale('log')
            ax.set_xlabel('%s%s (0 plotted at 0.01: default 3 x size)' % (knob, ' [m]' if knob == 'criticalLength'
                                                                        else '') if knob == 'criticalLength'
                          else 'segments N', fontsize=8)
            ax.set_ylabel('per step', fontsize=8)
            ax.set_title('detection work (dotted: DESS sub-unit tests)', fontsize=9)
            ax.legend(fontsize=6)
            ax.tick_params(labelsize=7)
        if knob == 'contactPenaltyFactor':
            ax = fig.add_subplot(rows, cols, panels)
            for j, name in enumerate(names):
                pts = scenes[name]['points']
                ax.plot([p['value'] for p in pts], [max(p['maxPenetration'], floor) for p in pts], 'o-',
                        color='C%d' % j, label=name)
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_xlabel('contactPenaltyFactor', fontsize=8)
            ax.set_ylabel('deepest contact penetration of any step [m]', fontsize=8)
            ax.set_title('penetration (what the penalty buys)', fontsize=9)
            ax.legend(fontsize=7)
            ax.tick_params(labelsize=7)
            ax.grid(True, which='both', alpha=0.25)
        unit = {'dt': ' [s]', 'criticalLength': ' [m]'}.get(knob, '')
        fig.suptitle('%s%s: error against wall time (labels: %s value; filled: Pareto-optimal)%s'
                     % (knob, unit, knob, '; error identical for every value' if msc else ''), fontsize=10)
        fig.tight_layout()
        path = os.path.join(outDir, 'accuracy_%s.png' % knob)
        fig.savefig(path, dpi=100)
        files.append(path)
    return files


def table(result):
    lines = ['%-22s %-18s %10s %12s %10s %12s %8s %10s %10s' % (
        'knob', 'scene', 'value', 'error', 'unit', 'wall s/sim s', 'steps', 'pen. [m]', 'det ms/st')]
    for knob, scenes in result['knobs'].items():
        for name, data in scenes.items():
            for p in data['points']:
                lines.append('%-22s %-18s %10s %12.4e %10s %12.4f %8d %10.2e %10.4f' % (
                    knob, name, _label(p['value']), p['error'], data['unit'], p['wallPerSimulatedSecond'],
                    p['steps'], p['maxPenetration'], p['detectionMsPerStep']))
    for p in result.get('yade', []):
        lines.append('%-22s %-18s %10s %12.4e %10s %12.4f %8d' % (
            'YADE dt/dtP', p['scene'], '%g' % p['fraction'], p['error'], 'm', p['wallPerSimulatedSecond'],
            p['steps']))
    lines.append('')
    for name, c in result['checks'].items():
        lines.append('%-4s %s (value %.3g)' % ('ok' if c['passed'] else 'FAIL', name, c['value']))
    return '\n'.join(lines)


def machine():
    import colliders        # bench/colliders.py: the same machine record
    info = colliders.machine()
    try:
        import yade
        info['yade'] = str(yade.config.version)
    except Exception:
        pass
    return info


def parseValues(text):
    """'dt=1e-3,5e-4' -> ('dt', [0.001, 0.0005])."""
    knob, sep, rest = text.partition('=')
    if not sep or not rest:
        raise ValueError("--knob takes NAME=v1,v2,... (e.g. dt=1e-2,1e-3), got %r" % text)
    values = []
    for item in rest.split(','):
        value = float(item)
        values.append(int(value) if knob == 'segments' else value)
    return knob, values


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--quick', action='store_true', help='a few points per knob, tEnd 0.3 s (about 2 minutes)')
    parser.add_argument('--knobs', default=','.join(PLAN), help='knobs to sweep (default all: %s)' % ', '.join(PLAN))
    parser.add_argument('--scenes', default=None, help='restrict to these scenes (default: each knob\'s own)')
    parser.add_argument('--no-yade', action='store_true', help="skip YADE's polyhedra DEM on the incline")
    parser.add_argument('--scene', default=None, help='your own scene script (defines build, measure, tEnd)')
    parser.add_argument('--knob', default=None, help='with --scene: NAME=v1,v2,... e.g. dt=1e-2,1e-3,1e-4')
    parser.add_argument('--timeout', type=float, default=3600, help='seconds per worker process')
    parser.add_argument('--out', default=os.path.join(HERE, 'out', 'accuracy.json'))
    parser.add_argument('--worker', default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        benchtasks.serveWorker(args.worker, worker)
        return

    outDir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(outDir, exist_ok=True)
    taskDir = os.path.join(outDir, 'accuracy_runs')
    os.makedirs(taskDir, exist_ok=True)
    started = time.time()
    _importDDA()
    if args.scene or args.knob:
        if not (args.scene and args.knob):
            parser.error('--scene and --knob go together')
        knob, values = parseValues(args.knob)
        from_ = dict(kind='custom', script=os.path.abspath(args.scene), knob=knob, values=values)
        result = spawn(from_, taskDir, args.timeout)['result']
        result['machine'] = machine()
        with open(args.out, 'w') as f:
            json.dump(result, f, indent=1)
        print('wrote', args.out)
        return

    mode = 'quick' if args.quick else 'full'
    tEnd = 0.3 if args.quick else 1.0
    knobs = [k for k in args.knobs.split(',') if k]
    for k in knobs:
        if k not in PLAN:
            parser.error('unknown knob %r (knobs: %s)' % (k, ', '.join(PLAN)))
    only = [s for s in args.scenes.split(',') if s] if args.scenes else None
    for s in only or []:
        if s not in SCENES:
            parser.error('unknown scene %r (scenes: %s)' % (s, ', '.join(SCENES)))
    result = dict(benchmark='accuracy against time', mode=mode, tEnd=tEnd, machine=machine(),
                  settings=dict(plan={k: dict(values=PLAN[k][mode], scenes=PLAN[k]['scenes'], base=PLAN[k]['base'])
                                      for k in knobs},
                                rock=ROCK, bounce=BOUNCE, wedge=WEDGE, slopeDeg=SLOPE_DEG, g=G,
                                yadeFractions=YADE_FRACTIONS[mode], yadeScenes=YADE_SCENES[mode],
                                threads='one per run: OMP_NUM_THREADS=1, DDAIntegrator(threads=1), ompThreads=1 '
                                        'on every YADE engine; one process per knob, runs one after another'),
                  errorMeasures={name: SCENES[name]().errorMeasure for name in SCENES},
                  costMeasure='wallPerSimulatedSecond [s/s]: wall time of the calls that advanced the run '
                              '(O.run) divided by the simulated time tEnd; the per-step monitor (stats(), the '
                              'bounce\'s energy) is timed apart and subtracted',
                  knobs={}, failed={})
    for knob in knobs:
        plan = PLAN[knob]
        scenes = [s for s in plan['scenes'] if only is None or s in only]
        if not scenes:
            continue
        print('--- %s: %s on %s' % (knob, plan[mode], ', '.join(scenes)), flush=True)
        task = dict(kind='knob', knob=knob, values=plan[mode], scenes=scenes, base=plan['base'], tEnd=tEnd)
        try:
            result['knobs'][knob] = spawn(task, taskDir, args.timeout)['scenes']
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            result['failed'][knob] = str(e)
            print('FAILED', knob, e, flush=True)
    yadeScenes = [s for s in YADE_SCENES[mode] if only is None or s in only]
    result['yade'] = []
    if not args.no_yade and yadeScenes:
        print('--- YADE polyhedra DEM: fractions %s of the P-wave step on %s' % (YADE_FRACTIONS[mode],
                                                                              ', '.join(yadeScenes)), flush=True)
        try:
            yade = spawn(dict(kind='yade', scenes=yadeScenes, values=YADE_FRACTIONS[mode], tEnd=tEnd),
                         taskDir, args.timeout)
            result['yade'], result['yadeDiagnosis'] = yade['points'], yade['diagnosis']
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            result['failed']['yade'] = str(e)
            print('FAILED yade', e, flush=True)
    result['checks'] = checks(result)
    result['wallSeconds'] = time.time() - started
    result['machine']['loadAverageAtEnd'] = os.getloadavg()
    result['files'] = [args.out] + plots(result, outDir)
    with open(args.out, 'w') as f:
        json.dump(result, f, indent=1)
    print()
    print(table(result))
    print('wrote %s (%.0f s)' % (', '.join(result['files']), result['wallSeconds']))
    if result['failed'] or not all(c['passed'] for c in result['checks'].values()):
        sys.exit(1)


if __name__ == '__main__':
    main()
