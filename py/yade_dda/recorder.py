"""ParaView output of a DDA scene: the ``DDAVTKRecorder`` engine.

Each output writes two VTK XML files with VTK's own writers
(``vtkXMLUnstructuredGridWriter``, ``vtkXMLPolyDataWriter``; Debian package
``python3-vtk9``), read from the DDA core (``scene.BlockView``,
``scene.contacts``), never from YADE's bodies, so they show the core's
current state wherever the engine stands in ``O.engines``:

- ``PREFIX + 'blocks.<iteration>.vtu'``: one ``VTK_POLYHEDRON`` cell per DDA
  block over its deformed corners (Float64 points, the core's doubles bit for
  bit), with cell data (see BLOCK_ARRAYS);
- ``PREFIX + 'contacts.<iteration>.vtp'``: one vertex per sub-contact at its
  contact point, with point data (see CONTACT_ARRAYS; ``state`` coded as in
  CONTACT_STATES);

and rewrites the two time series ``PREFIX + 'blocks.pvd'`` and ``PREFIX +
'contacts.pvd'`` that list every output with its simulated time. VTK 9.1 has
no writer for ParaView's .pvd collection, so it is written with xml.etree
(to a temporary file renamed over the old one: a viewer never reads half a
file).

``<iteration>`` (10 digits) and the time are those of the state written: an
engine before ``DDAIntegrator`` sees the state at the start of the iteration
(``O.iter``, ``O.time``), one after it the state at its end (``O.iter + 1``,
``O.time + O.dt``, which YADE books when the iteration ends).

What must outlive ``O.save``/``O.load`` lives in the scene's tags (so a run
resumed from a checkpoint continues its series and a new scene starts a new
one): the list of outputs (iteration, time) and each block's centroid when
the recorder first saw it, the origin of ``displacement``.

VTK is imported at the first output, not with yade_dda: a scene without
the recorder pays nothing for it.
"""
import base64
import contextlib
import gc
import json
import os
import xml.etree.ElementTree as ElementTree

import numpy

from ._yade import O, wrapper
from . import scene as _scene
from .guards import INTEGRATOR_COMMAND
from .params import Engine, Parameter, finite, initEngine, integer, keywordsOnly


CONTACT_STATES = {'open': 0, 'sliding': 1, 'locked': 2}
"""The ``state`` array of the contacts' file: 0 open, 1 sliding, 2 locked (closed = state > 0)."""

CONTACT_KINDS = {'VF': 0, 'EE': 1}
"""The ``kind`` array of the contacts' file: 0 vertex-face, 1 edge-edge."""

BLOCK_ARRAYS = (
    ('id', 1, '-', 'YADE body id'),
    ('fixed', 1, '-', '1 for a fixed block, else 0'),
    ('velocity', 3, 'm/s', 'translation rate of the centroid'),
    ('angularVelocity', 3, 'rad/s', 'rotation rate'),
    ('displacement', 3, 'm', 'centroid now minus the centroid at the recorder\'s first output that held the block'),
    ('stress', 9, 'Pa', 'Cauchy stress as a full symmetric tensor, row by row (xx, xy, xz, yx, ..., zz)'),
    ('strain', 9, '-', 'accumulated strain as a full symmetric tensor, tensor shears (half the core\'s gxy, gyz, gzx)'),
    ('vonMises', 1, 'Pa', 'von Mises equivalent stress of stress'),
)
"""Cell data of the blocks' file: (name, components, unit, meaning)."""

CONTACT_ARRAYS = (
    ('id1', 1, '-', 'body owning the vertex (VF) or the first edge (EE)'),
    ('id2', 1, '-', 'body owning the face (VF) or the second edge (EE)'),
    ('kind', 1, '-', 'CONTACT_KINDS: 0 vertex-face, 1 edge-edge'),
    ('state', 1, '-', 'CONTACT_STATES: 0 open, 1 sliding, 2 locked'),
    ('bonded', 1, '-', '1 for an intact bonded joint'),
    ('normal', 3, '-', 'unit normal from id2 towards id1'),
    ('normalForce', 1, 'N', 'normal force, compressive positive (a bonded joint may pull: negative)'),
    ('shearForce', 3, 'N', 'tangential force on id1 (shear spring when locked, friction when sliding)'),
    ('force', 3, 'N', 'total force on id1: normalForce * normal + shearForce'),
    ('gap', 1, 'm', 'normal distance at the start of the step, negative when penetrating'),
)
"""Point data of the contacts' file: (name, components, unit, meaning)."""

TAG = 'yade_dda.vtk:'
"""O.tags keys of a recorder's state: TAG + 'outputs:' + fileName, TAG + 'origin:' + fileName."""

_PERIODS = ('iterPeriod', 'virtPeriod', 'realPeriod')


def _checkFileName(value):
    if not isinstance(value, str) or not value:
        raise ValueError('fileName must be a non-empty string (a path prefix), got %r' % (value,))
    directory = os.path.dirname(value)
    if directory:
        try:
            os.makedirs(directory, exist_ok=True)
        except OSError as error:
            raise ValueError('fileName %r: its directory %r cannot be made (%s)' % (value, directory, error)) from None
    return value


_PERIOD_PARAMETERS = {
    'iterPeriod': Parameter(0, integer('iterPeriod', 0), 'iterations between outputs (0: not by iterations)'),
    'virtPeriod': Parameter(0.0, lambda v: finite('virtPeriod', v, 0, unit=' s'),
                            'simulated time between outputs [s] (0: not by simulated time)'),
    'realPeriod': Parameter(0.0, lambda v: finite('realPeriod', v, 0, unit=' s'),
                            'wall time between outputs [s] (0: not by wall time)'),
}


class DDAVTKRecorder(Engine, wrapper.PyRunner):
    """Writes the DDA blocks and their contacts for ParaView: per output a
    ``.vtu`` of the blocks (one polyhedron cell per block, deformed corners in
    double precision) and a ``.vtp`` of the contacts (a point per
    sub-contact), and the time series ``PREFIX + 'blocks.pvd'`` and ``PREFIX +
    'contacts.pvd'`` with the simulated time of each output (module
    docstring; doc/guide/how-to.md, "ParaView output: DDAVTKRecorder").

    Parameters: ``fileName`` (path prefix, default 'vtk/dda-'; its directory
    is made when missing), and YADE's periods: ``iterPeriod`` [iterations],
    ``virtPeriod`` [s of simulated time], ``realPeriod`` [s of wall time], each
    >= 0, at least one > 0 (YADE runs the engine when any is due). The first
    iteration of a run is written too (``initRun``).

    Cell data of the blocks: ``id``, ``fixed``, ``velocity`` [m/s],
    ``angularVelocity`` [rad/s], ``displacement`` [m], ``stress`` [Pa, 9
    components], ``strain`` [-, 9 components], ``vonMises`` [Pa]. Point data
    of the contacts: ``id1``, ``id2``, ``kind``, ``state`` (0 open, 1
    sliding, 2 locked), ``bonded``, ``normal``, ``normalForce`` [N],
    ``shearForce`` [N], ``force`` [N], ``gap`` [m]. Example::

        O.engines = [DDAIntegrator(dt=1e-3, gravity=(0, 0, -9.81)),
                     DDAVTKRecorder(fileName='vtk/pile-', iterPeriod=100)]
    """

    fileName = Parameter('vtk/dda-', _checkFileName, 'path prefix of the output files')

    _names = ('fileName',)

    def __init__(self, *args, label='', **params):
        keywordsOnly(type(self), args)
        known = self._names + _PERIODS
        unknown = sorted(set(params) - set(known))
        if unknown:
            raise TypeError('DDAVTKRecorder has no parameter %s (parameters: %s)' % (', '.join(unknown),
                                                                                    ', '.join(known)))
        periods = {name: _PERIOD_PARAMETERS[name].check(params.pop(name, _PERIOD_PARAMETERS[name].default))
                   for name in _PERIODS}
        _requirePeriod(periods)
        _requireVtk()
        wrapper.PyRunner.__init__(self)
        initEngine(self, label, params)
        for name, value in periods.items():
            self._setYade(name, value)

    def __setattr__(self, name, value):
        if name in _PERIODS:
            self._setYade(name, self._checkPeriod(name, value))
        else:
            super().__setattr__(name, value)

    def _checkPeriod(self, name, value):
        """The checked value of a period: >= 0 and at least one of the three > 0
        afterwards; nDo is YADE's own and taken as it is."""
        if name not in _PERIODS:
            return value
        value = _PERIOD_PARAMETERS[name].check(value)
        periods = {other: getattr(self, other) for other in _PERIODS}
        periods[name] = value
        _requirePeriod(periods)
        return value

    def _updateCommand(self):
        self._setYade('command', command(self.fileName))


def command(fileName):
    """The command of a recorder writing under fileName (what a saved scene's PyRunner runs)."""
    return 'import yade_dda.recorder as _ddaVtk; _ddaVtk.record(%r, fromEngine=True)' % (fileName,)


def _requirePeriod(periods):
    if not any(value > 0 for value in periods.values()):
        raise ValueError('DDAVTKRecorder needs a period: one of iterPeriod, virtPeriod or realPeriod > 0, got %s'
                         % ', '.join('%s=%r' % item for item in periods.items()))


def _requireVtk():
    try:
        import vtkmodules.vtkIOXML  # noqa: F401
    except ImportError as error:
        raise ImportError('DDAVTKRecorder writes with VTK\'s Python modules, which this Python cannot import (%s); '
                          'on Debian 12: apt-get install python3-vtk9 (make deps installs it)' % error) from None


# ------------------------------------------------------------------ one output

def record(fileName, fromEngine=False):
    """One output under fileName: the blocks, the contacts and both series.
    DDAVTKRecorder's command calls it with fromEngine=True (the state's
    iteration and time then depend on the engine's place, see _stateClock);
    a script may call it between iterations. Returns (blocks path, contacts path)."""
    _checkFileName(fileName)
    iteration, time = _stateClock(fileName) if fromEngine else (O.iter, O.time)
    scene = _scene.current(create=False)
    if scene is not None:
        scene.resolvePending()   # blocks appended since the last step are in the core, as the next step sees them
    outputs = [entry for entry in _tagJson(TAG + 'outputs:' + fileName, []) if entry[0] < iteration]
    outputs.append([iteration, time])
    blocksPath = '%sblocks.%010d.vtu' % (fileName, iteration)
    contactsPath = '%scontacts.%010d.vtp' % (fileName, iteration)
    with _collectorPaused():
        blocks, contacts = _blockArrays(scene, fileName), _contactArrays(scene)
    _writeBlocks(blocksPath, blocks)
    _writeContacts(contactsPath, contacts)
    O.tags[TAG + 'outputs:' + fileName] = json.dumps(outputs)
    for what, extension in (('blocks', 'vtu'), ('contacts', 'vtp')):
        writeSeries(fileName + what + '.pvd',
                    [(t, '%s%s.%010d.%s' % (fileName, what, i, extension)) for i, t in outputs])
    return blocksPath, contactsPath


@contextlib.contextmanager
def _collectorPaused():
    """Python's cyclic garbage collector paused (when it was running): reading
    the core makes tens of thousands of tuples, no cycles, and each collection
    they trigger scans every live object of the process (on 10,000 blocks
    resting on each other this tripled the time of reading the contacts)."""
    running = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if running:
            gc.enable()


def _stateClock(fileName):
    """(iteration, time) of the core's state when the recorder under fileName
    runs as an engine: O.iter and O.time when it stands before the integrator,
    O.iter + 1 and O.time + O.dt (booked by YADE when the iteration ends) after it."""
    mine = command(fileName)
    engines = list(O.engines)
    position = next((k for k, e in enumerate(engines) if isinstance(e, wrapper.PyRunner) and e.command == mine), None)
    if position is None:   # run by an engine that is not in O.engines (e.g. O.engines was replaced)
        return O.iter, O.time
    for engine in engines[:position]:
        if isinstance(engine, wrapper.PyRunner) and not engine.dead and engine.command.startswith(INTEGRATOR_COMMAND):
            return O.iter + 1, O.time + O.dt
    return O.iter, O.time


def _tagJson(key, default):
    return json.loads(O.tags[key]) if key in O.tags.keys() else default


def _origins(fileName, centroids):
    """Each block's reference centroid [m] (an n x 3 array): kept in O.tags,
    extended by the centroids of blocks the recorder sees for the first time."""
    key = TAG + 'origin:' + fileName
    known = numpy.frombuffer(base64.b64decode(O.tags[key]), dtype='<f8').reshape(-1, 3) \
        if key in O.tags.keys() else numpy.zeros((0, 3))
    if len(known) > len(centroids):   # a stale tag (another scene under the same tag): start again
        known = numpy.zeros((0, 3))
    if len(known) < len(centroids):
        known = numpy.concatenate([known, centroids[len(known):]])
        O.tags[key] = base64.b64encode(numpy.ascontiguousarray(known, dtype='<f8').tobytes()).decode('ascii')
    return known


# ------------------------------------------------------------------ arrays from the core

_topologyCache = {}


def _topology(scene, views):
    """(vertex count of each block, the polyhedron face stream in block-local
    vertex ids, a mask of the stream's vertex ids, the block of each stream
    entry, the stream offset of each block) for the blocks of views. A block's
    faces never change (DDA deforms each block affinely), so they are read once
    per DDA scene (its token: a loaded or cleared scene gets a new one) and the
    arrays are rebuilt only when blocks were added."""
    cached = _topologyCache.get('scene')
    if cached is None or cached['token'] != scene.token or cached['blocks'] > len(views):
        cached = _topologyCache['scene'] = dict(token=scene.token, blocks=0, counts=[], streams=[], masks=[],
                                                arrays=None)
    if cached['blocks'] < len(views):
        for view in views[cached['blocks']:]:
            faces = view.faces
            stream, mask = [len(faces)], [False]
            for face in faces:
                stream.append(len(face))
                stream.extend(face)
                mask.append(False)
                mask.extend([True] * len(face))
            cached['counts'].append(1 + max(max(face) for face in faces))
            cached['streams'].append(stream)
            cached['masks'].append(mask)
        cached['blocks'] = len(views)
        lengths = numpy.array([len(s) for s in cached['streams']], dtype=numpy.int64)
        cached['arrays'] = (
            numpy.array(cached['counts'], dtype=numpy.int64),
            numpy.fromiter((x for s in cached['streams'] for x in s), dtype=numpy.int64, count=int(lengths.sum())),
            numpy.fromiter((x for m in cached['masks'] for x in m), dtype=bool, count=int(lengths.sum())),
            numpy.repeat(numpy.arange(len(views), dtype=numpy.int64), lengths),
            numpy.concatenate([[0], numpy.cumsum(lengths)[:-1]]).astype(numpy.int64))
    return cached['arrays']


def _xyz(vector):
    """(x, y, z) of a Vector3 (15 times faster than tuple(vector), which iterates until IndexError)."""
    return vector[0], vector[1], vector[2]


def _blockArrays(scene, fileName):
    """Everything the blocks' file holds, as numpy arrays (dict)."""
    count = scene.core.blockCount() if scene is not None else 0
    # One cell per convex part; a concave block's parts carry its state (its body's view).
    views = [_scene.BlockView(scene, index) for index in range(count)]
    bodies = [views[scene.core.bodyOf(index)] for index in range(count)]
    points = numpy.array([_xyz(v) for view in views for v in view.vertices], dtype=numpy.float64).reshape(-1, 3)
    centroids = numpy.array([_xyz(scene.core.partPosition(index)) for index in range(count)],
                            dtype=numpy.float64).reshape(-1, 3)
    rates = numpy.array([view.velocity for view in bodies], dtype=numpy.float64).reshape(-1, 12)
    stress = numpy.array([view.stress for view in bodies], dtype=numpy.float64).reshape(-1, 6)
    strain = numpy.array([view.strain for view in bodies], dtype=numpy.float64).reshape(-1, 6)
    empty = numpy.zeros(0, dtype=numpy.int64)
    counts, stream, isVertex, owner, starts = _topology(scene, views) if count else (empty,) * 5
    firstPoint = numpy.concatenate([[0], numpy.cumsum(counts)[:-1]]).astype(numpy.int64)
    stream = stream + numpy.where(isVertex, firstPoint[owner], 0)   # block-local vertex ids to the grid's
    return dict(
        points=points, counts=counts, faces=stream, faceStarts=starts,
        id=numpy.array(scene.bodyOfBlock[:count] if count else [], dtype=numpy.int64),
        fixed=numpy.array([view.fixed for view in views], dtype=numpy.int8),
        velocity=rates[:, 0:3], angularVelocity=rates[:, 3:6],
        displacement=centroids - _origins(fileName, centroids),
        stress=symmetricTensor(stress, 1.0), strain=symmetricTensor(strain, 0.5),
        vonMises=vonMises(stress))


def symmetricTensor(voigt, shearFactor):
    """n x 9 full tensors, row by row, from n x 6 (xx, yy, zz, xy, yz, zx) with
    the shears multiplied by shearFactor (0.5 for engineering shear strains)."""
    xx, yy, zz = voigt[:, 0], voigt[:, 1], voigt[:, 2]
    xy, yz, zx = (shearFactor * voigt[:, k] for k in (3, 4, 5))
    return numpy.stack([xx, xy, zx, xy, yy, yz, zx, yz, zz], axis=1)


def vonMises(stress):
    """von Mises stress [Pa] of n x 6 stresses (xx, yy, zz, xy, yz, zx):
    sqrt(((sxx-syy)^2 + (syy-szz)^2 + (szz-sxx)^2) / 2 + 3 (sxy^2 + syz^2 + szx^2))."""
    s = numpy.asarray(stress, dtype=numpy.float64).reshape(-1, 6)
    normal = (s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2 + (s[:, 2] - s[:, 0]) ** 2
    return numpy.sqrt(0.5 * normal + 3.0 * (s[:, 3] ** 2 + s[:, 4] ** 2 + s[:, 5] ** 2))


def _contactArrays(scene):
    """Everything the contacts' file holds, as numpy arrays (dict)."""
    found = _scene.contacts() if scene is not None else []
    states, kinds = CONTACT_STATES, CONTACT_KINDS
    numbers = numpy.array([(c.point[0], c.point[1], c.point[2], c.normal[0], c.normal[1], c.normal[2], c.normalForce,
                            c.shearForce[0], c.shearForce[1], c.shearForce[2], c.gap) for c in found],
                          dtype=numpy.float64).reshape(-1, 11)
    codes = numpy.array([(c.id1, c.id2, kinds[c.kind], states[c.state], bool(c.bonded)) for c in found],
                        dtype=numpy.int64).reshape(-1, 5)
    normal, normalForce, shearForce = numbers[:, 3:6], numbers[:, 6], numbers[:, 7:10]
    return dict(
        points=numbers[:, 0:3], id1=codes[:, 0], id2=codes[:, 1], kind=codes[:, 2].astype(numpy.int8),
        state=codes[:, 3].astype(numpy.int8), bonded=codes[:, 4].astype(numpy.int8),
        normal=normal, normalForce=normalForce, shearForce=shearForce,
        force=normal * normalForce[:, None] + shearForce, gap=numbers[:, 10])


# ------------------------------------------------------------------ VTK

def _vtkArray(name, values):
    from vtkmodules.util import numpy_support
    values = numpy.ascontiguousarray(values)
    array = numpy_support.numpy_to_vtk(values, deep=True)
    array.SetName(name)
    return array


def _ids(values):
    from vtkmodules.util import numpy_support
    return numpy_support.numpy_to_vtkIdTypeArray(numpy.ascontiguousarray(values, dtype=numpy.int64), deep=True)


def _vtkPoints(points):
    from vtkmodules.vtkCommonCore import vtkPoints
    out = vtkPoints()
    out.SetDataTypeToDouble()
    out.SetData(_vtkArray('Points', points))
    return out


def _write(writer, data, path):
    """Writes data to path with writer: binary appended, zlib, 64-bit headers; the file
    appears under its name only when complete."""
    writer.SetInputData(data)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetHeaderTypeToUInt64()
    writer.SetCompressorTypeToZLib()
    writer.SetCompressionLevel(1)
    temporary = _temporaryName(path)
    writer.SetFileName(temporary)
    if writer.Write() != 1:
        raise OSError('VTK could not write %r' % path)
    os.replace(temporary, path)


def _temporaryName(path):
    directory, name = os.path.split(path)
    return os.path.join(directory, '.tmp-%d-%s' % (os.getpid(), name))


def _writeBlocks(path, arrays):
    from vtkmodules.vtkCommonDataModel import VTK_POLYHEDRON, vtkCellArray, vtkUnstructuredGrid
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter
    grid = vtkUnstructuredGrid()
    grid.SetPoints(_vtkPoints(arrays['points']))
    counts = arrays['counts']
    cells = vtkCellArray()
    cells.SetData(_ids(numpy.concatenate([[0], numpy.cumsum(counts)])), _ids(numpy.arange(int(counts.sum()))))
    types = _vtkArray('types', numpy.full(len(counts), VTK_POLYHEDRON, dtype=numpy.uint8))
    grid.SetCells(types, cells, _ids(arrays['faceStarts']), _ids(arrays['faces']))
    data = grid.GetCellData()
    for name, _, _, _ in BLOCK_ARRAYS:
        data.AddArray(_vtkArray(name, arrays[name]))
    data.SetActiveScalars('vonMises')
    data.SetActiveVectors('velocity')
    data.SetActiveTensors('stress')
    _write(vtkXMLUnstructuredGridWriter(), grid, path)


def _writeContacts(path, arrays):
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    poly = vtkPolyData()
    poly.SetPoints(_vtkPoints(arrays['points']))
    count = len(arrays['points'])
    vertices = vtkCellArray()
    vertices.SetData(_ids(numpy.arange(count + 1)), _ids(numpy.arange(count)))
    poly.SetVerts(vertices)
    data = poly.GetPointData()
    for name, _, _, _ in CONTACT_ARRAYS:
        data.AddArray(_vtkArray(name, arrays[name]))
    data.SetActiveScalars('normalForce')
    data.SetActiveVectors('force')
    data.SetActiveNormals('normal')
    _write(vtkXMLPolyDataWriter(), poly, path)


def writeSeries(path, entries):
    """Writes ParaView's time series ``path`` (.pvd) listing entries, each
    (time [s], file path), with xml.etree: VTK 9.1's Python has no .pvd writer.
    File paths are stored relative to the .pvd's directory; times with repr's
    17 significant digits. Replaced atomically."""
    root = ElementTree.Element('VTKFile', type='Collection', version='0.1', byte_order='LittleEndian')
    collection = ElementTree.SubElement(root, 'Collection')
    base = os.path.dirname(os.path.abspath(path))
    for time, file in entries:
        ElementTree.SubElement(collection, 'DataSet', timestep=repr(float(time)), group='', part='0',
                               file=os.path.relpath(os.path.abspath(file), base))
    ElementTree.indent(root)
    temporary = _temporaryName(path)
    ElementTree.ElementTree(root).write(temporary, encoding='utf-8', xml_declaration=True)
    os.replace(temporary, path)


def readSeries(path):
    """[(time [s], absolute file path)] of a .pvd time series."""
    base = os.path.dirname(os.path.abspath(path))
    return [(float(node.get('timestep')), os.path.join(base, node.get('file')))
            for node in ElementTree.parse(path).getroot().iter('DataSet')]

