"""A loaded scene's yade_dda engines are engines of their classes again.

YADE writes a Python subclass of PyRunner as a plain PyRunner. A loaded
integrator must still answer ``O.engines[k].gravity`` and take a new value,
and that value must change the run (a plain PyRunner took any attribute and
ignored it: the run was identical to the unchanged one).
"""
import builtins
import math
import os
import sys

import pytest

import yade_dda
from yade_dda import O
from yade import wrapper

sys.path.insert(0, os.path.dirname(__file__))
import saveload_scene  # noqa: E402

TILT = math.radians(30)
GRAVITY = (9.81 * math.sin(TILT), 0, -9.81 * math.cos(TILT))
SLIDER = 2   # the block on the 20 deg slope: it slides under the tilted gravity


def _engines(tmp_path):
    return [yade_dda.MSCCollider(criticalLength=0.7, segments=4, label='ddaCollider'),
            yade_dda.DDAIntegrator(dt=1e-3, gravity=GRAVITY, maxDisplacement=0.01, startFromRest=False,
                                   label='dda'),
            yade_dda.DDAVTKRecorder(fileName=str(tmp_path / 'vtk' / 'run-'), iterPeriod=7, label='vtk'),
            yade_dda.Checkpoint(period=13, directory=str(tmp_path / 'checkpoints'), keep=2, label='checkpoint')]


def _saved(tmp_path):
    saveload_scene.build()
    O.engines = _engines(tmp_path)
    O.run(20, True)
    path = str(tmp_path / 'scene.yade.gz')
    O.save(path)
    saved = [(type(e), e.command, e.iterLast, e.label) for e in O.engines]
    return path, saved


def _sliderX(steps):
    O.run(steps, True)   # the bodies are synced when a run stops
    return O.bodies[SLIDER].state.pos[0]


def test_loaded_engines_have_their_classes(tmp_path):
    pytest.importorskip('vtkmodules.vtkIOXML', reason='DDAVTKRecorder needs python3-vtk9 (make deps installs it)')
    path, saved = _saved(tmp_path)
    O.load(path)
    for engine, (cls, command, iterLast, label) in zip(O.engines, saved):
        assert type(engine) is cls, (type(engine), cls)
        assert engine.command == command and engine.iterLast == iterLast and engine.label == label
    collider, integrator, recorder, checkpoint = O.engines
    assert (collider.criticalLength, collider.segments) == (0.7, 4)
    assert tuple(integrator.gravity) == pytest.approx(GRAVITY, abs=0) and integrator.startFromRest is False
    assert (recorder.fileName, recorder.iterPeriod) == (str(tmp_path / 'vtk' / 'run-'), 7)
    assert (checkpoint.period, checkpoint.keep) == (13, 2)
    assert builtins.dda is integrator and builtins.checkpoint is checkpoint   # YADE's labels name the new engines
    with pytest.raises(AttributeError, match='did you mean'):
        integrator.gravty = (0, 0, 0)


def test_a_loaded_integrators_parameter_changes_the_run(tmp_path):
    """Gravity set to zero on the loaded integrator: the slider keeps its speed
    instead of gaining g (sin 30 - tan 20 cos 30) = 1.81 m/s^2, so it is behind
    the unchanged run by about 1.81 x 0.03^2 / 2 = 8.2e-4 m after 30 steps
    (measured 9.3e-4 m: the slider's compressed contacts also relax)."""
    path, _ = _saved(tmp_path)
    O.load(path)
    unchanged = _sliderX(30)
    O.load(path)
    O.engines[1].gravity = (0, 0, 0)
    assert isinstance(O.engines[1], yade_dda.DDAIntegrator) and tuple(O.engines[1].gravity) == (0, 0, 0)
    weightless = _sliderX(30)
    assert unchanged - weightless == pytest.approx(0.5 * 9.81 * (0.5 - math.tan(math.radians(20)) * math.cos(TILT))
                                                   * 0.03 ** 2, rel=0.25)


def test_a_foreign_pyrunner_stays_as_loaded(tmp_path):
    """A PyRunner whose command only looks like ours (another function of the module) is not replaced."""
    saveload_scene.build()
    O.engines = O.engines + [wrapper.PyRunner(command="import yade_dda.recorder as _ddaVtk; _ddaVtk.command('x')",
                                              iterPeriod=5, label='mine')]
    O.run(3, True)
    path = str(tmp_path / 'scene.yade')
    O.save(path)
    O.load(path)
    assert isinstance(O.engines[0], yade_dda.DDAIntegrator)
    assert type(O.engines[1]) is wrapper.PyRunner and O.engines[1].iterPeriod == 5 and O.engines[1].label == 'mine'
