"""DDAIntegrator(strainDamping=zeta): a Kelvin-Voigt viscosity on the blocks' strain rates,
against closed forms and the energy account (SI units).

- A free cube of side a released from an isotropic stress -p vibrates in its dilatational
  mode alone (by symmetry), about the volume at zero stress: the consistent mass of the mode is rho j V per strain
  component (j = a^2 / 12, the second moment per unit volume), its stiffness 3 K V
  (K the bulk modulus), so omega^2 = 3 K / (rho j). The viscosity's coefficient is
  eta = 2 zeta / omega_ref, omega_ref = sqrt(2 G / (rho j)), so the mode is damped at
  zeta_mode = eta omega / 2 = zeta sqrt(3 K / (2 G)) (1.58 zeta at Poisson 0.25). Under
  average acceleration (no numerical damping) at omega dt = 0.1 the volumetric strain's
  successive peaks fall by exp(-2 pi zeta_mode / sqrt(1 - zeta_mode^2)) within 1 % of
  zeta_mode, and without viscosity not at all (1e-3).
- The energy account (kinetic + strain + damping + ...) balances to round-off with the
  viscosity's work booked as damping, for that cube and for random deformable blocks
  thrown onto a floor.
- Rigid motion and steady strain feel nothing: a rigid cube and a deformable cube
  sliding down a slope at Coulomb's rate are unchanged by the viscosity.
- A pushed deformable block that rocks on its corners without the viscosity
  (friction-driven flutter, BlockEquations.hpp) does not rock with it: its base stays
  flat at dt = 1e-4 s, where Shi's numerical damping no longer hides the instability.
"""
import builtins
import math

import numpy as np
import pytest

import yade_dda
from yade_dda import O, DDAIntegrator
from yade import wrapper

from helpers import box
from test_dt_convergence import base_tilt, build, draw_pushed  # the sweep's pushed block

DENSITY = 2600.0
AVERAGE = dict(newmarkBeta=0.25, newmarkGamma=0.5)


def conserved(e):
    """The account's conserved sum [J]."""
    return (e['kinetic'] + e['gravity'] + e['strain'] + e['contact'] + e['friction'] + e['damping'] - e['loads']
            - e['contactChanges'])


def dilatation_run(zeta, periods=4):
    """A free 1 m cube (E 1e9 Pa, Poisson 0.25) released from -1e6 Pa isotropic stress under
    average acceleration; returns (peaks of its volume change [m^3], omega [rad/s], the
    largest drift of the account [J], the largest change of a term [J]). The volume oscillates
    about its value at zero stress."""
    O.reset()
    young, poisson, a, p = 1e9, 0.25, 1.0, 1e6
    rock = O.materials.append(wrapper.PolyhedraMat(density=DENSITY, young=young, poisson=poisson))
    cube = O.bodies.append(yade_dda.ddaBlock(box((0, 0, 0), (a, a, a)), material=rock, stress=(-p, -p, -p, 0, 0, 0)))
    bulk = young / (3 * (1 - 2 * poisson))
    omega = math.sqrt(3 * bulk / (DENSITY * a * a / 12))
    dt = 0.1 / omega
    O.engines = [DDAIntegrator(dt=dt, maxDisplacement=1.0, startFromRest=False, strainDamping=zeta, **AVERAGE)]
    steps = int(periods * 2 * math.pi / omega / dt)
    # At rest the stress is zero: a logarithmic strain p / (3 K) in each direction (Hencky's law).
    equilibrium = a ** 3 * math.exp(p / bulk)
    volumes, start = [], {}
    worst = dict(drift=0.0, change=0.0)

    def sample():
        e = yade_dda.stats()['energy']
        if not start:
            start.update(e)
        worst['drift'] = max(worst['drift'], abs(conserved(e) - conserved(start)))
        worst['change'] = max(worst['change'], max(abs(e[k] - start[k]) for k in e))
        volumes.append(yade_dda.block(cube).volume - equilibrium)

    # One O.run with a PyRunner sampling every step (each O.run(1, True) waits tens of ms).
    builtins._ddaViscositySample = sample
    try:
        O.engines = O.engines + [wrapper.PyRunner(iterPeriod=1, command='_ddaViscositySample()')]
        O.run(steps, True)
    finally:
        del builtins._ddaViscositySample
    drift, change = worst['drift'], worst['change']
    v = np.array(volumes)
    peaks = [v[i] for i in range(1, len(v) - 1) if v[i] > v[i - 1] and v[i] >= v[i + 1] and v[i] > 0]
    return peaks, omega, drift, change


@pytest.mark.parametrize('zeta', [0.02, 0.1])
def test_a_free_cube_s_dilatation_decays_at_the_closed_form_rate(scene, zeta):
    poisson = 0.25
    expected = zeta * math.sqrt(3 * (1 / (3 * (1 - 2 * poisson))) / (2 * (1 / (2 * (1 + poisson)))))
    peaks, omega, drift, change = dilatation_run(zeta)
    assert len(peaks) >= 3, peaks
    ratios = [b / a for a, b in zip(peaks, peaks[1:])]
    measured = [-math.log(r) / math.sqrt(4 * math.pi ** 2 + math.log(r) ** 2) for r in ratios]
    print('zeta %.3f: closed form %.5f, measured %s, account drift %.3g J of %.3g J'
          % (zeta, expected, ['%.5f' % m for m in measured], drift, change))
    for m in measured:
        assert m == pytest.approx(expected, rel=0.01)
    assert drift < 1e-9 * change


def test_without_viscosity_the_dilatation_keeps_its_amplitude(scene):
    peaks, omega, drift, change = dilatation_run(0.0, periods=3)
    assert len(peaks) >= 2, peaks
    assert peaks[-1] == pytest.approx(peaks[0], rel=1e-3)
    assert drift < 1e-9 * change


@pytest.mark.parametrize('seed', [1, 2])
def test_the_account_balances_with_viscosity_on_thrown_blocks(scene, seed):
    """Random deformable boxes (seeded) thrown spinning onto a fixed floor under Shi's scheme
    and under average acceleration with strainDamping 0.5: the account's sum stays at its
    start within 1e-9 of the largest change."""
    rng = np.random.default_rng(seed)
    for scheme in ({}, AVERAGE):
        O.reset()
        rock = O.materials.append(wrapper.PolyhedraMat(density=DENSITY, young=10 ** rng.uniform(7, 9),
                                                       poisson=rng.uniform(0.1, 0.4),
                                                       frictionAngle=math.radians(rng.uniform(10, 40))))
        O.bodies.append(yade_dda.ddaBlock(box((-5, -5, -1), (5, 5, 0)), material=rock, fixed=True))
        for k in range(3):
            lo = np.array([-3 + 2.2 * k, -0.5, 0.2 + 0.1 * k])
            hi = lo + rng.uniform(0.4, 1.2, size=3)
            O.bodies.append(yade_dda.ddaBlock(box(tuple(lo), tuple(hi)), material=rock,
                                              velocity=tuple(rng.uniform(-1, 1, size=2)) + (-1.0,),
                                              angularVelocity=tuple(rng.uniform(-2, 2, size=3))))
        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81), maxDisplacement=0.01, startFromRest=False,
                                   strainDamping=0.5, **scheme)]
        O.run(1, True)
        e0 = dict(yade_dda.stats()['energy'])
        O.run(400, True)
        e = yade_dda.stats()['energy']
        change = max(abs(e[k] - e0[k]) for k in e)
        print('seed %d %s: account drift %.3g J of %.3g J, damping %.4g J'
              % (seed, 'average' if scheme else 'Shi', conserved(e) - conserved(e0), change, e['damping']))
        assert abs(conserved(e) - conserved(e0)) < 1e-9 * change


def slide(rigid, zeta):
    """A 1 m cube sliding down a 30 deg slope (tilted gravity) with 20 deg of friction for 0.3 s;
    returns its centroid's displacement along the slope between 0.1 and 0.3 s [m]."""
    O.reset()
    rock = O.materials.append(wrapper.PolyhedraMat(density=DENSITY, young=1e9, poisson=0.25,
                                                   frictionAngle=math.radians(20)))
    O.bodies.append(yade_dda.ddaBlock(box((-2, -2, -1), (8, 2, 0)), material=rock, fixed=True))
    cube = O.bodies.append(yade_dda.ddaBlock(box((0, -0.5, 0), (1, 0.5, 1)), material=rock, rigid=rigid))
    s = math.radians(30)
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(9.81 * math.sin(s), 0, -9.81 * math.cos(s)), maxDisplacement=0.05,
                               strainDamping=zeta)]
    O.run(100, True)
    x1 = yade_dda.block(cube).centroid[0]
    O.run(200, True)
    return yade_dda.block(cube).centroid[0] - x1, O.time


def test_rigid_motion_and_steady_sliding_feel_no_viscosity(scene):
    rigid0, _ = slide(True, 0.0)
    rigid1, _ = slide(True, 0.5)
    assert rigid1 == rigid0   # a rigid block has no strain: bitwise the same
    deformable0, t = slide(False, 0.0)
    deformable1, _ = slide(False, 0.5)
    a = 9.81 * (math.sin(math.radians(30)) - math.tan(math.radians(20)) * math.cos(math.radians(30)))
    expected = 0.5 * a * (t ** 2 - 0.1 ** 2)
    print('slid %.6f m (no viscosity %.6f m, rigid %.6f m), Coulomb %.6f m' % (deformable1, deformable0, rigid0,
                                                                             expected))
    assert deformable1 == pytest.approx(expected, rel=0.01)
    assert deformable1 == pytest.approx(deformable0, rel=0.005)


def pushed_tilt(zeta, dt=1e-4, duration=0.15):
    """The pushed block of test_dt_convergence.py's seed 1 (1.268 x 1.926 x 0.716 m, E 1.77e8
    Pa, 38.97 deg of friction, pushed at 1.24 x its friction limit) with strainDamping zeta;
    returns the largest tilt of its base [rad] over `duration`, sampled every 5 ms."""
    block = build(draw_pushed(1), dt, strainDamping=zeta)
    blk = yade_dda.block(block)
    base = [i for i, v in enumerate(blk.vertices) if abs(v[2]) < 1e-9]
    tilt = 0.0
    for _ in range(int(round(duration / 0.005))):
        O.run(int(round(0.005 / dt)), True)
        tilt = max(tilt, base_tilt(blk, base))
    return tilt


def test_a_pushed_block_that_rocks_without_viscosity_stays_flat_with_it(scene):
    undamped = pushed_tilt(0.0)
    damped = pushed_tilt(0.5)
    print('largest base tilt: %.3g rad without viscosity, %.3g rad with zeta 0.5' % (undamped, damped))
    assert undamped > 1e-4      # the flutter: the base tilts and corners open
    assert damped < 1e-5        # the elastic shear alone: 1.2e-6 rad
