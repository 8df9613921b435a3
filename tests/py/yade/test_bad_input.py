"""Bad input, everywhere a user can type (doc/guide/reference.md, "Bad input").

One test per case. Each asserts the exception and its message (which names
the problem and the body or parameter) and that the scene is unchanged: the
bodies, their positions, O.iter, O.time and the DDA step count. Cases that
are documented behaviour rather than errors assert that behaviour.
"""
import math
import random

import pytest
from yade import utils, wrapper

import yade_dda
from yade_dda import (O, ddaBlock, DDAIntegrator, MSCCollider, DESSCollider, NBSCollider, stats, block,
                      setVelocity, addPointLoad, addFixedPoint, Ig2_DDABlock_DDABlock_DDAContact)
from helpers import box, material

G = 9.81
UNIT = box((0, 0, 0), (1, 1, 1))
H = float.fromhex   # exact coordinates of fuzz findings


def snapshot():
    """What must not change when bad input is refused: the bodies, O.iter, O.time, the DDA
    step count and the blocks made by ddaBlock but not appended yet (a refused block leaves
    none waiting)."""
    dda = yade_dda.scene.current(create=False)
    return (len(O.bodies), [None if b is None else (b.id, tuple(b.state.pos), tuple(b.state.vel)) for b in O.bodies],
            O.iter, O.time,
            None if dda is None else (dda.core.steps(), sum(1 for body, _ in dda.pending if body.id < 0)))


def coreSnapshot():
    """The DDA core's state: steps and every block's centroid and velocity (the truth DDA bodies show)."""
    dda = yade_dda.scene.current()
    return dda.core.steps(), [(tuple(dda.core.centroid(i)), dda.core.velocity(i)) for i in range(dda.core.blockCount())]


def running(n=2, mask=1, **engine):
    """A small scene that has run a few steps: a free block 2 m above a fixed floor."""
    floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (3, 3, 0)), fixed=True, mask=mask))
    free = O.bodies.append(ddaBlock(box((0, 0, 2), (1, 1, 3)), mask=mask))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), label='dda', **engine)]
    if n > 0:   # O.run(0) would run without end
        O.run(n, True)
    return floor, free


def refused(error, match, action):
    """action() raises error matching match and leaves the scene as it was."""
    before = snapshot()
    with pytest.raises(error, match=match):
        action()
    assert snapshot() == before


# ------------------------------------------------------------------ block geometry

@pytest.mark.parametrize('points, match', [
    (UNIT[:3], r'at least 4 points, got 3'),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.2, 0)], r'all 5 points are coplanar'),
    ([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)], r'coplanar'),
    (UNIT + [(1, 1, 1)], r'points 7 and 8 coincide'),
    (UNIT[:7] + [(float('nan'), 1, 1)], r'point 7 has a non-finite coordinate'),
    (UNIT[:7] + [(1, float('-inf'), 1)], r'point 7 has a non-finite coordinate'),
    (UNIT[:7] + [(1, float('inf'), 1)], r'point 7 has a non-finite coordinate'),
    (UNIT + [(0.5, 0.5, 0.5)], r'point 8 .* strictly inside the hull .* not convex'),
    (UNIT + [(0.5, 0.5, 1)], r'point 8 .* on the hull surface but is not a corner: it is inside a face'),
    (UNIT + [(0.5, 0, 0)], r'point 8 .* not a corner: it is inside an edge'),
    (box((0, 0, 0), (1, 1, 1e-10)), r'too flat'),
], ids=['3 points', 'coplanar', 'collinear', 'duplicate', 'NaN', '-inf', '+inf', 'non-convex', 'point in a face',
        'point in an edge', 'zero volume'])
def test_bad_block_geometry(scene, points, match):
    refused(ValueError, match, lambda: ddaBlock(points))


L_PRISM = [(x, y, z) for (x, y) in [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)] for z in (0, 1)]


@pytest.mark.parametrize('points, match', [
    (L_PRISM, r'point 6 .* on the hull surface but is not a corner'),
    (UNIT + [(0.5, 0.5, 0.9)], r'point 8 .* strictly inside the hull'),
    (UNIT + [(0.5, 0.5, 1 - 1e-12)], r'point 8 .* not a corner: it is inside a face'),
], ids=['L prism', 'dent', 'dent within the tolerance'])
def test_concave_points_name_concave_block_and_hull(scene, points, match):
    """A concave point list (an L's corners) got "... the block is too flat there" without a word of
    the ways out: the message names concaveBlock(...) and hull=True."""
    refused(ValueError, match, lambda: ddaBlock(points))
    with pytest.raises(ValueError) as error:
        ddaBlock(points)
    message = str(error.value)
    assert 'not the corners of a convex polyhedron' in message, message
    assert 'concaveBlock(' in message and 'hull=True' in message, message


def test_flat_points_get_no_concave_hint(scene):
    """Points that are flat, not concave: hull=True or concaveBlock would not help, so neither is named."""
    with pytest.raises(ValueError) as error:
        ddaBlock(box((0, 0, 0), (1, 1, 1e-10)))
    assert 'too flat' in str(error.value) and 'concaveBlock' not in str(error.value)


def test_tiny_block_far_from_origin_is_rejected_not_an_internal_error(scene):
    """Fuzz finding: a 1e-16 m tetrahedron 6e-6 m from the origin raised buildConvexPolyhedron's
    internal error ('input point outside its own hull'); now a clear ValueError."""
    points = [(H('-0x1.816c5dbc65a64p-18'), H('-0x1.8475519644ecbp-18'), H('-0x1.8478576bb5e0dp-18')),
              (H('-0x1.816c5dbc67664p-18'), H('-0x1.84755196666fep-18'), H('-0x1.8478576b9071ap-18')),
              (H('-0x1.816c5dbc556fep-18'), H('-0x1.84755196548c1p-18'), H('-0x1.8478576bb5746p-18')),
              (H('-0x1.816c5dbc6eb39p-18'), H('-0x1.847551964df08p-18'), H('-0x1.8478576ba33a4p-18'))]
    refused(ValueError, r'too small for its distance from the origin', lambda: ddaBlock(points))


def test_sliver_of_nearly_collinear_points_is_rejected_not_an_internal_error(scene):
    """Fuzz finding: nearly collinear points whose hull triangle's double cross product is 0
    raised 'hull triangle with zero area' (internal error); now a clear ValueError."""
    points = [(H('0x1.1900c45af0eeep-44'), H('0x1.47e94864f3b43p-45'), H('0x1.1cc8383d66ecbp-44')),
              (H('0x1.bacc2991608e6p-46'), H('0x1.025b70e179b3fp-46'), H('0x1.c0c0a670b36fap-46')),
              (H('0x1.ea8825adfa311p-45'), H('0x1.1e356242947a2p-45'), H('0x1.f120fa3139b9p-45')),
              (H('-0x1.2d99db50efea9p-45'), H('-0x1.5ff29e146dbe1p-46'), H('-0x1.31a839af9955bp-45')),
              (H('-0x1.e4a9fa36181a3p-46'), H('-0x1.1ac8eb4e6f494p-46'), H('-0x1.eb2e9af87bb4bp-46')),
              (H('-0x1.b54ec4de09b84p-47'), H('-0x1.fe4ee24feba7dp-48'), H('-0x1.bb305b2c71df5p-47')),
              (H('-0x1.de38164cae314p-47'), H('-0x1.170643c093c16p-47'), H('-0x1.e4a686b9aa37fp-47'))]
    refused(ValueError, r'collinear to double precision', lambda: ddaBlock(points))


def test_block_yade_cannot_represent_is_rejected_before_it_is_added(scene):
    """A 1e9 m cube: YADE's Polyhedra merged two corners and the first step failed in the link; a
    random 30-point cloud 1e5 m across hangs YADE's hull or aborts the process. Both are refused by
    their size before YADE sees them (with or without hull=True); 1e4 m is still a block."""
    refused(ValueError, r"the block is 1e\+09 m across .* more than the 10000 m YADE's Polyhedra can carry",
            lambda: ddaBlock(box((0, 0, 0), (1e9, 1e9, 1e9))))
    rng = random.Random(5)
    cloud = [(1e5 * rng.random(), 1e5 * rng.random(), 1e5 * rng.random()) for _ in range(30)]
    refused(ValueError, r'the block is 9\d{4}\.\d m across', lambda: ddaBlock(cloud, hull=True))
    body = ddaBlock(box((0, 0, 0), (1e4, 1e4, 1e4)))
    assert len(body.shape.v) == 8


@pytest.mark.parametrize('vertices, error, match', [
    (None, TypeError, r'vertices must be a sequence of points, got None'),
    ('abcd', TypeError, r"point 0 must be a sequence of 3 numbers, got 'a'"),
    ([(0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], ValueError, r'point 0 must have 3 coordinates, got 2'),
], ids=['None', 'string', '2D point'])
def test_vertices_of_the_wrong_type(scene, vertices, error, match):
    refused(error, match, lambda: ddaBlock(vertices))


# ------------------------------------------------------------------ materials

@pytest.mark.parametrize('kw, match', [
    (dict(density=0), r'density must be positive and finite, got 0'),
    (dict(density=-2600), r'density must be positive and finite, got -2600'),
    (dict(young=0), r"Young's modulus must be positive and finite, got 0"),
    (dict(young=float('nan')), r"Young's modulus must be positive and finite, got nan"),
    (dict(poisson=0.5), r"Poisson's ratio must lie in \(-1, 0.5\), got 0.5"),
    (dict(poisson=-1), r"Poisson's ratio must lie in \(-1, 0.5\), got -1"),
    (dict(frictionAngle=-0.1), r'friction angle must lie in \[0, pi/2\) rad, got -0.1'),
    (dict(frictionAngle=math.pi / 2), r'friction angle must lie in \[0, pi/2\) rad'),
], ids=['zero density', 'negative density', 'zero Young', 'NaN Young', 'Poisson 0.5', 'Poisson -1',
        'negative friction', 'friction pi/2'])
def test_bad_material_constants(scene, kw, match):
    params = dict(young=4e6, poisson=0.25, density=2600, frictionAngle=0.3)
    params.update(kw)
    mat = O.materials.append(wrapper.PolyhedraMat(**params))
    refused(ValueError, match, lambda: ddaBlock(UNIT, material=mat))


@pytest.mark.parametrize('kw, error, match', [
    (dict(cohesion=-1), ValueError, r'cohesion must be finite and >= 0 Pa, got -1'),
    (dict(tensileStrength=float('nan')), ValueError, r'tensileStrength must be finite and >= 0 Pa, got nan'),
    (dict(cohesion='strong'), TypeError, r"cohesion must be a number \[Pa\], got 'strong'"),
], ids=['negative cohesion', 'NaN tensile strength', 'string cohesion'])
def test_bad_joint_strengths(scene, kw, error, match):
    refused(error, match, lambda: ddaBlock(UNIT, **kw))


@pytest.mark.parametrize('mat, error, match', [
    (5, IndexError, r'no material with id 5'),
    ('granite', KeyError, r'no material labelled .granite.'),
    (True, TypeError, r'material must be a YADE Material, its id or its label, got True'),
    (lambda: wrapper.Material(), TypeError, r'material Material has no young, poisson'),
], ids=['unknown id', 'unknown label', 'bool', 'not elastic'])
def test_unknown_or_unusable_material(scene, mat, error, match):
    refused(error, match, lambda: ddaBlock(UNIT, material=mat))


# ------------------------------------------------------------------ other block arguments

@pytest.mark.parametrize('kw, error, match', [
    (dict(fixed=True, velocity=(1, 0, 0)), ValueError, r'a fixed block cannot have an initial velocity'),
    (dict(fixed=True, loads=[((0, 0, 0), (1, 0, 0))]), ValueError, r'a fixed block cannot have fixed points or point loads'),
    (dict(fixed=True, fixedPoints=[(0, 0, 0)]), ValueError, r'a fixed block cannot have fixed points or point loads'),
    (dict(loads=[((0, 0, 0),)]), TypeError, r'load 0 must be a pair \(point \[m\], force \[N\]\)'),
    (dict(loads=[((0, 0, 0), (1, 0))]), ValueError, r'load 0 force must have 3 components, got 2'),
    (dict(fixedPoints=[((0, 0, 0), -5)]), ValueError, r'fixed point 0 stiffness must be finite and >= 0 N/m, got -5'),
    (dict(fixedPoints=[5]), TypeError, r'fixed point 0 must be a point or \(point, stiffness\), got 5'),
    (dict(stress=(1, 2, 3)), ValueError, r'stress must have 6 components, got 3'),
    (dict(velocity=(float('nan'), 0, 0)), ValueError, r'velocity has a non-finite component 0'),
    (dict(color='red'), TypeError, r"color must be a sequence of 3 numbers, got 'red'"),
    (dict(mask=1.5), TypeError, r'mask must be an int, got 1.5'),
], ids=['fixed with velocity', 'fixed with load', 'fixed with fixed point', 'load without force', 'short force',
        'negative fixed-point stiffness', 'fixed point not a point', 'short stress', 'NaN velocity', 'colour name',
        'float mask'])
def test_bad_block_arguments(scene, kw, error, match):
    refused(error, match, lambda: ddaBlock(UNIT, **kw))


# ------------------------------------------------------------------ engine parameters

@pytest.mark.parametrize('kw, error, match', [
    (dict(dt=0), ValueError, r'dt must be finite and in \(0, inf\), got 0.0 s'),
    (dict(dt=-1e-3), ValueError, r'dt must be finite and in \(0, inf\)'),
    (dict(dt=float('nan')), ValueError, r'dt must be finite'),
    (dict(dt='fast'), TypeError, r"dt must be a number, got 'fast'"),
    (dict(dt=None), TypeError, r'dt must be a number, got None'),
    (dict(gravity='down'), TypeError, r"gravity must be a sequence of 3 numbers, got 'down'"),
    (dict(gravity=(0, 0)), ValueError, r'gravity must have 3 components, got 2'),
    (dict(velocityRatio=1.5), ValueError, r'velocityRatio must be finite and in \[0, 1\]'),
    (dict(maxDisplacementRatio=0), ValueError, r'maxDisplacementRatio must be finite and in \(0, 1\]'),
    (dict(timeStepGrowth=0.5), ValueError, r'timeStepGrowth must be finite and in \[1, inf\)'),
    (dict(contactDistance=-1), ValueError, r'contactDistance must be finite and in \[0, inf\), got -1.0 m'),
    (dict(contactPenaltyFactor=0), ValueError, r'contactPenaltyFactor must be finite and in \(0, inf\)'),
    (dict(openCloseShrink=1), ValueError, r'openCloseShrink must be finite and in \(0, 1\)'),
    (dict(threads=1.5), TypeError, r'threads must be an integer, got 1.5'),
    (dict(threads=-1), ValueError, r'threads must be an integer in \[0, 2147483647\], got -1'),
    (dict(maxOpenCloseIterations=1e30), ValueError, r'maxOpenCloseIterations must be an integer in \[1, 2147483647\]'),
    (dict(maxStepCuts=True), TypeError, r'maxStepCuts must be an integer, got True'),
    (dict(syncPeriod='2'), TypeError, r"syncPeriod must be an integer, got '2'"),
    (dict(collider='Octree'), ValueError, r"collider must be one of DESS, NBS, AllPairs, MSC, got 'Octree'"),
    (dict(bogus=1), TypeError, r'DDAIntegrator has no parameter bogus'),
    (dict(label=5), TypeError, r'label must be a string, got 5'),
], ids=lambda v: str(v) if not isinstance(v, dict) else ','.join('%s=%r' % kv for kv in v.items()))
def test_bad_integrator_parameters(scene, kw, error, match):
    refused(error, match, lambda: DDAIntegrator(**kw))


def test_parameter_assigned_to_a_running_integrator_is_checked_and_kept(scene):
    """A bad value (inf, 0) is refused and the old one kept; a good one reaches the engine in
    O.engines (the same instance) and its command."""
    running()
    dda = O.engines[0]
    refused(ValueError, r'dt must be finite', lambda: setattr(dda, 'dt', float('inf')))
    refused(ValueError, r'dt must be finite and in \(0, inf\), got 0', lambda: setattr(dda, 'dt', 0))
    assert dda.dt == 1e-3 and "'dt'" not in dda.command
    dda.dt = 2e-3
    assert O.engines[0].dt == 2e-3
    assert "'dt': 0.002" in O.engines[0].command


@pytest.mark.parametrize('kw, error, match', [
    (dict(segments=0), ValueError, r'segments must be an integer in \[1, 64\], got 0'),
    (dict(segments=65), ValueError, r'segments must be an integer in \[1, 64\], got 65'),
    (dict(segments=2.5), ValueError, r'segments must be an integer >= 1, got 2.5'),
    (dict(segments=None), ValueError, r'segments must be an integer >= 1, got None'),
    (dict(criticalLength=-1), ValueError, r'criticalLength must be finite and in \[0, inf\), got -1.0 m'),
    (dict(criticalLength=float('inf')), ValueError, r'criticalLength must be finite'),
], ids=['0 segments', '65 segments', 'fractional segments', 'None segments', 'negative lambda', 'infinite lambda'])
def test_bad_msc_parameters(scene, kw, error, match):
    refused(error, match, lambda: MSCCollider(**kw))


def test_two_dda_integrators_are_refused(scene):
    """Before: each advanced the blocks once per iteration while O.time advanced once (a block fell
    as if for twice the time)."""
    running()
    O.engines = O.engines + [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    refused(RuntimeError, r'O.engines holds 2 DDA integrators \(at positions 0, 1\)', O.step)


def test_two_collider_engines_are_refused(scene):
    running()
    O.engines = [DESSCollider(), NBSCollider()] + list(O.engines)
    refused(RuntimeError, r'O.engines holds 2 DDA collider engines', O.step)


def test_collider_engine_after_the_integrator_is_refused(scene):
    """Refused by O.step and by O.run alike, the scene unchanged."""
    running()
    O.engines = list(O.engines) + [DESSCollider()]
    refused(RuntimeError, r'the DDA collider engine \(O.engines\[1\]\) must come before DDAIntegrator', O.step)
    refused(RuntimeError, r'the DDA collider engine \(O.engines\[1\]\) must come before DDAIntegrator',
            lambda: O.run(1, True))


def test_time_step_whose_solution_is_not_finite_stops_with_an_error(scene):
    """Before: dt = 1e-300 s wrote NaN into every block silently (a NaN solution passed the
    finiteness check: std::max drops NaN). Now the step raises and changes nothing."""
    running()
    O.engines[0].dt = 1e-300
    refused(RuntimeError, r'the DDA step produced a non-finite displacement \(dt = 1e-300 s\)', O.step)
    assert all(math.isfinite(x) for x in block(1).vertices[0])


# ------------------------------------------------------------------ body ids

@pytest.mark.parametrize('call, error, match', [
    (lambda s: block(12345), KeyError, r'body 12345 is not a DDA block'),
    (lambda s: block(-1), KeyError, r'body -1 is not a DDA block'),
    (lambda s: block('a'), TypeError, r"expected a YADE Body or a body id \(int\), got 'a'"),
    (lambda s: block(s), KeyError, r'body 2 is not a DDA block'),
    (lambda s: setVelocity(s, (1, 0, 0)), KeyError, r'body 2 is not a DDA block'),
    (lambda s: addPointLoad(s, (0, 0, 0), (1, 0, 0)), KeyError, r'body 2 is not a DDA block'),
    (lambda s: addFixedPoint(s, (0, 0, 0)), KeyError, r'body 2 is not a DDA block'),
    (lambda s: Ig2_DDABlock_DDABlock_DDAContact().go(0, s, 0.1), KeyError, r'body 2 is not a DDA block'),
], ids=['unknown id', 'negative id', 'string', 'sphere', 'setVelocity on sphere', 'point load on sphere',
        'fixed point on sphere', 'functor on sphere'])
def test_unknown_or_non_dda_body(scene, call, error, match):
    running(mask=2)
    sphere = O.bodies.append(utils.sphere((10, 10, 10), 0.5))
    refused(error, match, lambda: call(sphere))


@pytest.mark.parametrize('call, match', [
    (lambda floor, free: setVelocity(floor, (1, 0, 0)), r'a fixed block cannot be given a velocity'),
    (lambda floor, free: addPointLoad(floor, (0, 0, 0), (1, 0, 0)), r'block 0 is fixed: a point load would have no effect'),
    (lambda floor, free: addFixedPoint(floor, (0, 0, 0)), r'block 0 is fixed: a fixed point would have no effect'),
    (lambda floor, free: addFixedPoint(free, (0, 0, 2), -5), r'fixed point stiffness must be finite and >= 0 N/m'),
    (lambda floor, free: addPointLoad(free, (0, 0, 2), (0, 0, float('inf'))), r"a point load's force must be finite"),
    (lambda floor, free: setVelocity(free, (1, 0)), r'velocity must have 3 components'),
    (lambda floor, free: Ig2_DDABlock_DDABlock_DDAContact().go(free, free, 0.1), r'a block cannot contact itself'),
    (lambda floor, free: Ig2_DDABlock_DDABlock_DDAContact().go(floor, free, float('nan')),
     r'contact distance must be >= 0 and finite'),
], ids=['velocity of fixed', 'load on fixed', 'fixed point on fixed', 'negative stiffness', 'infinite load',
        'short velocity', 'functor on itself', 'functor NaN d0'])
def test_bad_calls_on_dda_blocks(scene, call, match):
    """Before: a point load or fixed point on a fixed block was accepted and silently ignored,
    and addFixedPoint took a negative stiffness as the default."""
    floor, free = running()
    refused(ValueError, match, lambda: call(floor, free))


# ------------------------------------------------------------------ the scene changing mid-run

def test_erasing_a_running_dda_block_is_refused(scene):
    """Before: the erased block went on acting on its neighbours until the next sync raised."""
    floor, free = running()
    refused(RuntimeError, r'body 1 is DDA block 1 of a running scene; the DDA core cannot remove blocks yet',
            lambda: O.bodies.erase(free))
    O.run(3, True)   # and the scene runs on
    assert stats()['steps'] == 5 and O.bodies[free] is not None


def test_erasing_a_dda_block_before_its_first_step_is_allowed(scene):
    """Documented: a block not yet in the core (no step since its append) may be erased."""
    floor, free = running()
    extra = O.bodies.append(ddaBlock(box((5, 5, 2), (6, 6, 3))))
    assert O.bodies.erase(extra)
    O.run(1, True)
    assert stats()['blocks'] == 2 and yade_dda.blockOf(extra) is None


def test_clearing_the_bodies_also_clears_the_dda_state(scene):
    """Documented: O.bodies.clear() starts a fresh, empty DDA scene (before: the next step
    failed with 'IndexError: Body id out of range')."""
    running()
    O.bodies.clear()
    O.step()
    assert stats()['blocks'] == 0 and stats()['steps'] == 1
    b = O.bodies.append(ddaBlock(UNIT))
    O.step()
    assert stats()['blocks'] == 1 and yade_dda.blockOf(b) == 0


def test_replacing_the_bodies_replaces_the_dda_scene(scene):
    """Documented: O.bodies.replace(bodies) starts a fresh DDA scene whose blocks are the DDA
    blocks among bodies; they enter at the next step and fall from rest (before: YADE's
    replace bypassed the clear guard and the next step failed with 'IndexError: Body id out
    of range' in the sync, the core still holding the old blocks)."""
    running()
    ids = O.bodies.replace([ddaBlock(box((5, 5, 2), (6, 6, 3))), ddaBlock(box((5, 5, -1), (6, 6, 0)), fixed=True)])
    assert list(ids) == [0, 1]
    O.run(10, True)
    assert stats()['blocks'] == 2 and stats()['movingBlocks'] == 1 and stats()['steps'] == 10
    assert yade_dda.blockOf(0) == 0 and yade_dda.blockOf(1) == 1
    t = 10 * 1e-3
    assert abs(O.bodies[0].state.pos[2] - (2.5 - G * t * t / 2)) < 1e-9


def test_a_block_made_before_clear_can_be_appended_after_it(scene):
    """Documented: a ddaBlock() not yet appended survives O.bodies.clear() (before: the fresh
    DDA scene forgot it, and once appended it was a YADE body the core never moved)."""
    running()
    made = ddaBlock(box((5, 5, 2), (6, 6, 3)))
    O.bodies.clear()
    b = O.bodies.append(made)
    O.run(10, True)
    assert stats()['blocks'] == 1 and yade_dda.blockOf(b) == 0
    t = 10 * 1e-3
    assert abs(O.bodies[b].state.pos[2] - (2.5 - G * t * t / 2)) < 1e-9


def test_dda_block_added_mid_run_enters_at_the_next_step(scene):
    """Documented: a block appended mid-run enters the core at the next step and falls from rest."""
    floor, free = running()
    added = O.bodies.append(ddaBlock(box((5, 5, 2), (6, 6, 3))))
    O.run(10, True)
    assert stats()['blocks'] == 3 and stats()['movingBlocks'] == 2
    t = 10 * 1e-3
    assert abs(O.bodies[added].state.pos[2] - (2.5 - G * t * t / 2)) < 1e-9


def test_dda_block_added_mid_run_into_another_is_refused(scene):
    """Before: a block appended 0.5 m deep into another was pushed out in one step."""
    floor, free = running()
    O.bodies.append(ddaBlock(box((0.5, 0, 2), (1.5, 1, 3))))
    before = snapshot()
    with pytest.raises(ValueError, match=r'DDA blocks body 1 and body 2 overlap by 0.5 m as they enter the scene'):
        O.step()
    assert snapshot() == before
    assert yade_dda.scene.current().core.blockCount() == 2   # nothing was added to the core


def test_initial_overlap_is_refused_with_bodies_and_depth(scene):
    """Before: a 1 m block (E = 1 GPa) placed 7.6 mm into a fixed floor had 7.6e4 J of kinetic
    energy after 50 steps of 1 ms (spurious spring energy); 10 GPa here."""
    mat = material(O, young=1e10, density=2600)
    floor = O.bodies.append(ddaBlock(box((-2, -2, -1), (3, 3, 0)), material=mat, fixed=True))
    free = O.bodies.append(ddaBlock(box((0, 0, -0.0076), (1, 1, 0.9924)), material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    before = snapshot()
    with pytest.raises(ValueError, match=r'DDA blocks body %d and body %d overlap by 0.0076 m as they enter the '
                                           r'scene, more than the 2.924e-06 m accepted' % (floor, free)):
        O.step()
    assert snapshot() == before and yade_dda.scene.current().core.blockCount() == 0
    # the user moves the block out and runs: nothing else was left behind
    O.bodies.erase(free)
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=mat))
    O.run(5, True)
    assert stats()['blocks'] == 2


def test_overlap_within_the_tolerance_is_accepted(scene):
    """Documented: an overlap below max(2 W / kn, 1e-6 x size), e.g. coordinates of a settled
    scene or rounded to a micrometre, is a closed contact and runs."""
    mat = material(O, young=1e10, density=2600)
    O.bodies.append(ddaBlock(box((-2, -2, -1), (3, 3, 0)), material=mat, fixed=True))
    free = O.bodies.append(ddaBlock(box((0, 0, -5e-7), (1, 1, 1 - 5e-7)), material=mat))
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(20, True)
    assert abs(O.bodies[free].state.pos[2] - 0.5) < 1e-5 and stats()['closedContacts'] > 0


def test_yade_contacts_with_dda_blocks_are_refused(scene):
    """A YADE polyhedron sharing a mask bit with DDA blocks, under an InteractionLoop with a
    Polyhedra functor: YADE would push it off the DDA block, which would never feel it."""
    running(n=0)
    poly = O.bodies.append(utils.polyhedron(box((0.2, 0.2, 3.5), (0.8, 0.8, 4))))
    O.engines = [wrapper.ForceResetter(), wrapper.InsertionSortCollider([wrapper.Bo1_Polyhedra_Aabb()]),
                 wrapper.InteractionLoop([wrapper.Ig2_Polyhedra_Polyhedra_PolyhedraGeom()],
                                         [wrapper.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
                                         [wrapper.Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()]),
                 DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    refused(RuntimeError, r'YADE body %d \(Polyhedra\) shares groupMask bit 0 with DDA block body 0' % poly, O.step)


def test_yade_body_overlapping_a_dda_block_with_disjoint_masks_passes_through(scene):
    """Documented: contact between YADE bodies and DDA blocks is not modelled; with disjoint
    masks each moves as if alone (the sphere falls through the block)."""
    floor, free = running(n=0, mask=2)
    sphere = O.bodies.append(utils.sphere((0.5, 0.5, 3.2), 0.5))   # overlapping the free block's top
    O.engines = [wrapper.ForceResetter(), wrapper.InsertionSortCollider([wrapper.Bo1_Sphere_Aabb(),
                                                                          wrapper.Bo1_Polyhedra_Aabb()]),
                 wrapper.InteractionLoop([wrapper.Ig2_Sphere_Sphere_ScGeom()], [wrapper.Ip2_FrictMat_FrictMat_FrictPhys()],
                                         [wrapper.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 wrapper.NewtonIntegrator(gravity=(0, 0, -G), mask=1), DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.dt = 1e-3
    O.run(20, True)
    assert len(O.interactions) == 0
    assert O.bodies[sphere].state.vel[2] < -0.1 and abs(O.bodies[free].state.pos[2] - (2.5 - G * O.time ** 2 / 2)) < 1e-9


def test_empty_scene_runs_and_counts_steps(scene):
    """Documented: DDAIntegrator with no blocks takes empty steps of dt."""
    O.engines = [DDAIntegrator(dt=2e-3)]
    O.run(5, True)
    s = stats()
    assert s['blocks'] == 0 and s['steps'] == 5 and abs(O.time - 5 * 2e-3) < 1e-15


def test_stats_before_any_step(scene):
    """Documented: without DDA blocks stats() raises; with blocks but before the first step it
    reports steps 0 and the blocks waiting in pendingBodies."""
    with pytest.raises(RuntimeError, match=r'this YADE scene has no DDA blocks'):
        stats()
    O.bodies.append(ddaBlock(UNIT))
    s = stats()
    assert s['steps'] == 0 and s['blocks'] == 0 and s['pendingBodies'] == 1 and s['dt'] == 0


def test_newton_integrator_sharing_the_dda_mask_is_refused(scene):
    """Newton runs before the DDA engine can object and moves the YADE bodies once; the DDA core,
    the blocks' true state, is unchanged (and rewrites the bodies at the next sync)."""
    running()
    before = coreSnapshot()
    O.engines = [wrapper.NewtonIntegrator(gravity=(0, 0, -G))] + list(O.engines)
    with pytest.raises(RuntimeError, match=r'NewtonIntegrator would also move DDA block body 1'):
        O.step()
    assert coreSnapshot() == before
