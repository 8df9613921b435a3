"""DDAVTKRecorder (what YADE sees of the DDA in ParaView): the files it writes, read
back with VTK's own readers, against the core's state and closed forms.

- the blocks' .vtu: corners bitwise equal to block(i).vertices, one polyhedron
  per block with the core's faces, cell data equal to the core's values;
- von Mises stress against its closed form for uniaxial and pure shear stress;
- the contacts' .vtp under a block resting on a floor: normal forces that sum
  to its weight, arrays equal to contacts();
- the .pvd series: every output, its file and the time of the state written,
  wherever the engine stands, checked on a free fall (z0 - g t^2 / 2);
- a series continued across O.save/O.load; bad parameters refused by name;
  no VTK import without the engine.
"""
import math
import os
import subprocess
import sys

import numpy
import pytest

vtk = pytest.importorskip('vtkmodules.vtkIOXML', reason='python3-vtk9 (make deps) is not installed')
from vtkmodules.util import numpy_support  # noqa: E402

import yade_dda  # noqa: E402
from yade_dda import O, DDAIntegrator, DDAVTKRecorder, ddaBlock  # noqa: E402
from yade_dda import recorder  # noqa: E402

from helpers import box, material, rotate  # noqa: E402

G = 9.81


def _read(path):
    reader = (vtk.vtkXMLUnstructuredGridReader if path.endswith('.vtu') else vtk.vtkXMLPolyDataReader)()
    reader.SetFileName(path)
    reader.Update()
    assert reader.GetErrorCode() == 0, path
    return reader.GetOutput()


def _array(data, name):
    array = data.GetCellData().GetArray(name) if data.IsA('vtkUnstructuredGrid') else \
        data.GetPointData().GetArray(name)
    assert array is not None, 'no array %r' % name
    return numpy_support.vtk_to_numpy(array)


def _points(data):
    return numpy_support.vtk_to_numpy(data.GetPoints().GetData())


def _blockIds():
    return [b.id for b in O.bodies if yade_dda.blockOf(b.id) is not None]


def _full(voigt, shear=1.0):
    xx, yy, zz, xy, yz, zx = voigt
    xy, yz, zx = shear * xy, shear * yz, shear * zx
    return [xx, xy, zx, xy, yy, yz, zx, yz, zz]


def _last(prefix, what):
    return recorder.readSeries(prefix + what + '.pvd')[-1][1]


# ---- the blocks' file

def _mixedScene():
    """A fixed floor, a deformable rotated block falling with a spin and a prestress, a rigid block."""
    rock = material(O, young=1e7, frictionDeg=20)
    O.bodies.append(ddaBlock(box((-4, -4, -1), (4, 4, 0)), material=rock, fixed=True))
    O.bodies.append(ddaBlock(rotate(box((-0.5, -0.3, 2), (0.5, 0.3, 2.8)), (1, 2, 3), 0.4, about=(0, 0, 2.4)),
                             material=rock, velocity=(0.3, -0.2, 0), angularVelocity=(0.5, 1, -2),
                             stress=(1e4, -2e4, 3e3, 4e3, -5e3, 6e3)))
    O.bodies.append(yade_dda.rigidBlock([(2, 0, 0.001), (3, 0, 0.001), (2, 1, 0.001), (2, 0, 1.001)], material=rock))


def test_blocks_file_holds_the_cores_corners_bitwise_and_its_values(scene, tmp_path):
    _mixedScene()
    prefix = str(tmp_path / 'out' / 'mixed-')
    O.engines = [DDAVTKRecorder(fileName=prefix, iterPeriod=1), DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(40, True)
    recorder.record(prefix)   # from the script: the state between iterations
    grid = _read(_last(prefix, 'blocks'))
    ids = _blockIds()
    views = [yade_dda.block(i) for i in ids]
    corners = numpy.array([[c for c in v] for view in views for v in view.vertices])
    assert grid.GetPoints().GetData().GetDataType() == 11   # VTK_DOUBLE
    assert numpy.array_equal(_points(grid), corners)         # bitwise
    assert grid.GetNumberOfCells() == len(ids)
    first = 0
    for k, view in enumerate(views):
        cell = grid.GetCell(k)
        assert cell.GetCellType() == 42   # VTK_POLYHEDRON
        count = len(view.vertices)
        assert [cell.GetPointId(j) for j in range(count)] == list(range(first, first + count))
        assert cell.GetNumberOfFaces() == len(view.faces)
        for f, face in enumerate(view.faces):
            polygon = cell.GetFace(f)
            assert [polygon.GetPointId(j) for j in range(polygon.GetNumberOfPoints())] == [first + v for v in face]
        first += count
    assert list(_array(grid, 'id')) == ids
    assert list(_array(grid, 'fixed')) == [1, 0, 0]
    assert numpy.array_equal(_array(grid, 'velocity'), [view.velocity[0:3] for view in views])
    assert numpy.array_equal(_array(grid, 'angularVelocity'), [view.velocity[3:6] for view in views])
    assert numpy.array_equal(_array(grid, 'stress'), [_full(view.stress) for view in views])
    assert numpy.array_equal(_array(grid, 'strain'), [_full(view.strain, 0.5) for view in views])
    assert _array(grid, 'stress')[1].tolist() != [0.0] * 9 and _array(grid, 'strain')[1].tolist() != [0.0] * 9
    assert _array(grid, 'stress')[2].tolist() == [0.0] * 9   # rigid


def test_displacement_is_from_the_first_output(scene, tmp_path):
    rock = material(O)
    b = O.bodies.append(ddaBlock(box((0, 0, 10), (1, 2, 13)), material=rock, velocity=(3, 0, 7.5)))
    prefix = str(tmp_path / 'fall-')
    O.engines = [DDAVTKRecorder(fileName=prefix, iterPeriod=10), DDAIntegrator(dt=1e-3, gravity=(0, 0, -G))]
    O.run(101, True)
    series = recorder.readSeries(prefix + 'blocks.pvd')
    assert len(series) == 11 and series[0][0] == 0
    for time, path in series:
        displacement = _array(_read(path), 'displacement')[0]
        expected = (3 * time, 0, 7.5 * time - G * time ** 2 / 2)
        assert numpy.allclose(displacement, expected, rtol=0, atol=1e-9), (time, displacement, expected)
    assert yade_dda.blockOf(b) == 0


# ---- von Mises

@pytest.mark.parametrize('stress, expected', [
    ((-3e6, 0, 0, 0, 0, 0), 3e6),                        # uniaxial: |sxx|
    ((0, 0, 2.5e5, 0, 0, 0), 2.5e5),
    ((0, 0, 0, 0, 4e5, 0), math.sqrt(3) * 4e5),          # pure shear: sqrt(3) |tau|
    ((1e5, 1e5, 1e5, 0, 0, 0), 0.0),                     # hydrostatic
], ids=['uniaxial-x', 'uniaxial-z', 'shear-yz', 'hydrostatic'])
def test_von_mises_of_a_prestressed_block(scene, tmp_path, stress, expected):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O, young=1e9), stress=stress))
    prefix = str(tmp_path / 'vm-')
    O.engines = [DDAVTKRecorder(fileName=prefix, iterPeriod=1), DDAIntegrator(dt=1e-4)]
    O.step()   # the recorder sees the initial stress before the step
    grid = _read(_last(prefix, 'blocks'))
    assert _array(grid, 'vonMises')[0] == pytest.approx(expected, rel=1e-14, abs=1e-9)
    assert numpy.array_equal(_array(grid, 'stress')[0], _full(stress))


def test_von_mises_formula():
    s = numpy.array([[1.0, 2.0, 3.0, 0.5, -0.25, 0.75]])
    closed = math.sqrt(((1 - 2) ** 2 + (2 - 3) ** 2 + (3 - 1) ** 2) / 2 + 3 * (0.25 + 0.0625 + 0.5625))
    assert recorder.vonMises(s)[0] == pytest.approx(closed, rel=1e-15)


# ---- the contacts' file

def test_contacts_of_a_block_on_a_floor_carry_its_weight(scene, tmp_path):
    rock = material(O, young=1e8, frictionDeg=30)
    O.bodies.append(ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    b = O.bodies.append(ddaBlock(box((0, 0, 0), (1, 2, 1.5)), material=rock))   # touching: start from rest settles it
    prefix = str(tmp_path / 'rest-')
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G)), DDAVTKRecorder(fileName=prefix, iterPeriod=50)]
    O.run(101, True)
    poly = _read(_last(prefix, 'contacts'))
    found = yade_dda.contacts()
    assert poly.GetNumberOfPoints() == len(found) >= 4 and poly.GetNumberOfVerts() == len(found)
    state = _array(poly, 'state')
    normalForce = _array(poly, 'normalForce')
    normal = _array(poly, 'normal')
    closed = state > 0
    weight = yade_dda.block(b).mass * G
    assert numpy.sum(normalForce[closed] * normal[closed, 2]) == pytest.approx(weight, rel=0.02)
    assert set(state) <= {recorder.CONTACT_STATES['sliding'], recorder.CONTACT_STATES['locked']}
    assert numpy.allclose(_points(poly)[:, 2], 0.0, atol=2e-3)   # on the block's bottom face
    assert numpy.array_equal(_points(poly), [list(c.point) for c in found])
    assert numpy.array_equal(normal, [list(c.normal) for c in found])
    assert numpy.array_equal(normalForce, [c.normalForce for c in found])
    assert numpy.array_equal(_array(poly, 'shearForce'), [list(c.shearForce) for c in found])
    assert numpy.allclose(_array(poly, 'force'), [list(c.force) for c in found], rtol=0, atol=1e-9 * weight)
    assert numpy.array_equal(_array(poly, 'gap'), [c.gap for c in found])
    assert list(_array(poly, 'state')) == [recorder.CONTACT_STATES[c.state] for c in found]
    assert list(_array(poly, 'id1')) == [c.id1 for c in found] and list(_array(poly, 'id2')) == [c.id2 for c in found]
    assert list(_array(poly, 'kind')) == [recorder.CONTACT_KINDS[c.kind] for c in found]


def test_a_scene_without_contacts_writes_empty_contact_files(scene, tmp_path):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    prefix = str(tmp_path / 'free-')
    O.engines = [DDAIntegrator(dt=1e-3), DDAVTKRecorder(fileName=prefix, iterPeriod=5)]
    O.run(6, True)
    poly = _read(_last(prefix, 'contacts'))
    assert poly.GetNumberOfPoints() == 0 and _array(poly, 'normalForce').size == 0


# ---- the series

@pytest.mark.parametrize('where', ['before', 'after'])
def test_the_series_lists_every_output_at_the_time_of_its_state(scene, tmp_path, where):
    """A free fall, stepped one iteration at a time: each output's time is the
    O.time of the state written, and the block in its file is where the closed
    form puts it at that time."""
    O.bodies.append(ddaBlock(box((0, 0, 10), (1, 1, 11)), material=material(O)))
    prefix = str(tmp_path / where / 'fall-')
    engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G), maxDisplacement=1)]
    rec = DDAVTKRecorder(fileName=prefix, iterPeriod=7)
    O.engines = [rec] + engines if where == 'before' else engines + [rec]
    times = {0: O.time}
    for _ in range(30):
        O.step()
        times[O.iter] = O.time
    iterations = [0, 7, 14, 21, 28] if where == 'before' else [1, 8, 15, 22, 29]
    for what, extension in (('blocks', 'vtu'), ('contacts', 'vtp')):
        series = recorder.readSeries(prefix + what + '.pvd')
        assert [t for t, _ in series] == [times[i] for i in iterations]
        assert [p for _, p in series] == ['%s%s.%010d.%s' % (prefix, what, i, extension) for i in iterations]
        assert all(os.path.isfile(p) for _, p in series)
    recorder.record(prefix)   # from the script, between iterations: O.iter and O.time wherever the engine stands
    assert recorder.readSeries(prefix + 'blocks.pvd')[-1] == (times[30], '%sblocks.%010d.vtu' % (prefix, 30))
    for time, path in recorder.readSeries(prefix + 'blocks.pvd'):
        zLow = _points(_read(path))[:, 2].min()
        assert zLow == pytest.approx(10 - G * time ** 2 / 2, abs=1e-9)


def test_virt_period_outputs(scene, tmp_path):
    O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
    prefix = str(tmp_path / 'virt-')
    O.engines = [DDAIntegrator(dt=1e-3), DDAVTKRecorder(fileName=prefix, virtPeriod=0.01)]
    O.run(35, True)
    times = [t for t, _ in recorder.readSeries(prefix + 'blocks.pvd')]
    assert len(times) == 4 and all(b - a == pytest.approx(0.01, abs=1.5e-3) for a, b in zip(times, times[1:]))


def test_the_series_continues_after_save_and_load(scene, tmp_path):
    rock = material(O, young=1e8, frictionDeg=30)
    O.bodies.append(ddaBlock(box((-3, -3, -1), (3, 3, 0)), material=rock, fixed=True))
    O.bodies.append(ddaBlock(box((0, 0, 0.5), (1, 1, 1.5)), material=rock, velocity=(0.5, 0, 0)))
    prefix = str(tmp_path / 'resume-')
    O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -G)), DDAVTKRecorder(fileName=prefix, iterPeriod=10)]
    O.run(25, True)
    saved = str(tmp_path / 'scene.yade.gz')
    O.save(saved)
    O.run(20, True)   # outputs 30 and 40 of the first run: left behind by the load
    uninterrupted = recorder.readSeries(prefix + 'blocks.pvd')
    displacement = _array(_read(uninterrupted[-1][1]), 'displacement')
    O.load(saved)
    engine = O.engines[-1]
    assert type(engine) is recorder.DDAVTKRecorder and engine.command == recorder.command(prefix)
    assert engine.iterPeriod == 10
    O.run(20, True)
    series = recorder.readSeries(prefix + 'blocks.pvd')
    assert series == uninterrupted   # the same outputs at the same times, none twice
    assert numpy.array_equal(_array(_read(series[-1][1]), 'displacement'), displacement)


def test_a_new_scene_starts_a_new_series(scene, tmp_path):
    prefix = str(tmp_path / 'again-')
    for run in range(2):
        O.reset()
        O.bodies.append(ddaBlock(box((0, 0, 0), (1, 1, 1)), material=material(O)))
        O.engines = [DDAIntegrator(dt=1e-3), DDAVTKRecorder(fileName=prefix, iterPeriod=10)]
        O.run(15 + 20 * (1 - run), True)
        assert len(recorder.readSeries(prefix + 'blocks.pvd')) == 2 + 2 * (1 - run)


# ---- parameters

def test_parameters_reach_the_engine_and_the_command(scene, tmp_path):
    rec = DDAVTKRecorder(fileName=str(tmp_path / 'made' / 'here' / 'p-'), virtPeriod=0.5, label='vtk')
    assert os.path.isdir(str(tmp_path / 'made' / 'here'))
    assert (rec.iterPeriod, rec.virtPeriod, rec.realPeriod, rec.initRun) == (0, 0.5, 0.0, True)
    assert rec.command == ("import yade_dda.recorder as _ddaVtk; _ddaVtk.record(%r, fromEngine=True)"
                           % str(tmp_path / 'made/here/p-'))
    rec.iterPeriod = 3.0
    assert rec.iterPeriod == 3 and type(rec.iterPeriod) is int
    rec.virtPeriod = 0
    rec.fileName = str(tmp_path / 'q-')
    assert rec.command.endswith("record(%r, fromEngine=True)" % str(tmp_path / 'q-'))
    rec.nDo = 5   # YADE's own


@pytest.mark.parametrize('params, error, pattern', [
    (dict(fileName='', iterPeriod=1), ValueError, 'fileName must be a non-empty string'),
    (dict(fileName=3, iterPeriod=1), ValueError, 'fileName must be a non-empty string'),
    (dict(fileName='x-'), ValueError, 'one of iterPeriod, virtPeriod or realPeriod > 0'),
    (dict(fileName='x-', iterPeriod=0, virtPeriod=0), ValueError, 'one of iterPeriod, virtPeriod or realPeriod > 0'),
    (dict(fileName='x-', iterPeriod=-1), ValueError, 'iterPeriod must be an integer in'),
    (dict(fileName='x-', iterPeriod=2.5), TypeError, 'iterPeriod must be an integer'),
    (dict(fileName='x-', iterPeriod='10'), TypeError, 'iterPeriod must be an integer'),
    (dict(fileName='x-', virtPeriod=-0.1), ValueError, r'virtPeriod must be finite and in \[0, inf\)'),
    (dict(fileName='x-', realPeriod=float('nan')), ValueError, 'realPeriod must be finite'),
    (dict(fileName='x-', iterPeriod=1, period=5), TypeError, 'DDAVTKRecorder has no parameter period'),
], ids=['empty-name', 'number-name', 'no-period', 'zero-periods', 'negative-iter', 'fractional-iter', 'string-iter',
        'negative-virt', 'nan-real', 'unknown'])
def test_bad_parameters_are_refused_by_name(scene, tmp_path, params, error, pattern):
    cwd = os.getcwd()
    os.chdir(str(tmp_path))
    try:
        with pytest.raises(error, match=pattern):
            DDAVTKRecorder(**params)
    finally:
        os.chdir(cwd)


def test_a_directory_that_cannot_be_made_is_refused(scene, tmp_path):
    (tmp_path / 'file').write_text('in the way')
    with pytest.raises(ValueError, match=r"fileName '.*file/sub/x-': its directory .* cannot be made"):
        DDAVTKRecorder(fileName=str(tmp_path / 'file' / 'sub' / 'x-'), iterPeriod=1)


def test_bad_assignments_are_refused_and_change_nothing(scene, tmp_path):
    rec = DDAVTKRecorder(fileName=str(tmp_path / 'a-'), iterPeriod=10)
    command = rec.command
    for name, value, error, pattern in [
            ('iterPeriod', 0, ValueError, 'needs a period'),
            ('iterPeriod', -5, ValueError, 'iterPeriod must be an integer in'),
            ('virtPeriod', -1, ValueError, 'virtPeriod must be finite'),
            ('fileName', '', ValueError, 'fileName must be a non-empty string'),
            ('iterPerod', 1, AttributeError, "no parameter or attribute 'iterPerod'; did you mean 'iterPeriod'")]:
        with pytest.raises(error, match=pattern):
            setattr(rec, name, value)
        assert (rec.iterPeriod, rec.virtPeriod, rec.realPeriod, rec.command) == (10, 0, 0, command)


# ---- cost

def test_importing_yade_dda_does_not_import_vtk():
    """Scenes without the recorder pay nothing for it: VTK loads at the first output."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(yade_dda.__file__)))
    code = 'import sys; sys.path.insert(0, %r); import yade_dda; print("vtkmodules" in sys.modules)' % package
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == 'False'
