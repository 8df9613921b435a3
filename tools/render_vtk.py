"""Renders the last output of a DDAVTKRecorder series to a PNG, offscreen, with VTK.

The blocks (PREFIX + 'blocks.pvd', last entry) are drawn with their edges,
coloured by von Mises stress with ParaView's default "Cool to Warm" colour map
and a scalar bar; the closed contacts (PREFIX + 'contacts.pvd') as arrows
along their normal, their length proportional to the normal force; the time
of the output in a corner.

    /usr/bin/python3 tools/render_vtk.py vtk_pile/pile- --out doc/vtk_pile.png
    /usr/bin/python3 tools/render_vtk.py tunnel/tunnel- --out doc/tunnel.png --colour displacement \
        --cut 0 1 0 10.5 --view -0.6 -1 0.35 --arrows 0

(--colour: the cell array the moving blocks are coloured by; --cut: fixed blocks beyond a plane left
out, to see inside; --view: where the camera looks from; --arrows 0: no contact arrows.)

(PREFIX may also be a directory holding one '*blocks.pvd'.) Debian 12's VTK
9.1 renders through X only (no EGL or OSMesa build), so without a DISPLAY
the script runs itself again under ``xvfb-run`` (Debian package ``xvfb``,
with ``xauth``): ``apt-get install xvfb xauth``.
"""
import argparse
import glob
import os
import shutil
import sys
import xml.etree.ElementTree as ElementTree

COOL_TO_WARM = ((0.0, (0.231373, 0.298039, 0.752941)), (0.5, (0.865003, 0.865003, 0.865003)),
                (1.0, (0.705882, 0.0156863, 0.14902)))
"""ParaView's default colour map (Moreland's diverging "Cool to Warm"): (position, RGB)."""


def lastOutput(pvd):
    """(time [s], absolute path) of the last data set of a .pvd series."""
    base = os.path.dirname(os.path.abspath(pvd))
    node = list(ElementTree.parse(pvd).getroot().iter('DataSet'))[-1]
    return float(node.get('timestep')), os.path.join(base, node.get('file'))


def seriesOf(prefix):
    """(blocks .pvd, contacts .pvd) of a recorder's prefix or of a directory holding one series."""
    if os.path.isdir(prefix):
        found = glob.glob(os.path.join(prefix, '*blocks.pvd'))
        if len(found) != 1:
            sys.exit('render_vtk: %s holds %d *blocks.pvd series; give the prefix' % (prefix, len(found)))
        prefix = found[0][:-len('blocks.pvd')]
    blocks, contacts = prefix + 'blocks.pvd', prefix + 'contacts.pvd'
    if not os.path.isfile(blocks):
        sys.exit('render_vtk: no series %s' % blocks)
    return blocks, contacts


def read(path):
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
    reader = vtkXMLUnstructuredGridReader() if path.endswith('.vtu') else vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def threshold(data, association, name, low, high):
    """The cells of data whose array `name` (on points or cells) lies in [low, high], as polygons."""
    from vtkmodules.vtkCommonDataModel import vtkDataObject
    from vtkmodules.vtkFiltersCore import vtkThreshold
    from vtkmodules.vtkFiltersGeometry import vtkDataSetSurfaceFilter
    keep = vtkThreshold()
    keep.SetInputData(data)
    keep.SetInputArrayToProcess(0, 0, 0, {'points': vtkDataObject.FIELD_ASSOCIATION_POINTS,
                                          'cells': vtkDataObject.FIELD_ASSOCIATION_CELLS}[association], name)
    keep.SetThresholdFunction(vtkThreshold.THRESHOLD_BETWEEN)
    keep.SetLowerThreshold(low)
    keep.SetUpperThreshold(high)
    surface = vtkDataSetSurfaceFilter()
    surface.SetInputConnection(keep.GetOutputPort())
    surface.Update()
    return surface.GetOutput()


def colourMap(low, high):
    from vtkmodules.vtkRenderingCore import vtkColorTransferFunction
    lut = vtkColorTransferFunction()
    lut.SetColorSpaceToDiverging()
    for position, rgb in COOL_TO_WARM:
        lut.AddRGBPoint(low + position * (high - low), *rgb)
    return lut


def cutAway(grid, plane):
    """grid without its fixed blocks whose centre lies beyond plane (a, b, c, d): a x + b y + c z > d,
    so that a section shows what the fixed blocks hide (a tunnel)."""
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk
    shown = np.zeros(grid.GetNumberOfCells())
    fixed = grid.GetCellData().GetArray('fixed')
    for k in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(k).GetPointIds()
        centre = np.mean([grid.GetPoint(ids.GetId(j)) for j in range(ids.GetNumberOfIds())], axis=0)
        shown[k] = 0 if fixed.GetValue(k) and np.dot(plane[:3], centre) > plane[3] else 1
    array = numpy_to_vtk(shown, deep=True)
    array.SetName('shown')
    grid.GetCellData().AddArray(array)
    from vtkmodules.vtkCommonDataModel import vtkDataObject
    from vtkmodules.vtkFiltersCore import vtkThreshold
    keep = vtkThreshold()
    keep.SetInputData(grid)
    keep.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_CELLS, 'shown')
    keep.SetThresholdFunction(vtkThreshold.THRESHOLD_BETWEEN)
    keep.SetLowerThreshold(1)
    keep.SetUpperThreshold(1)
    keep.Update()
    return keep.GetOutput()


def blocksActors(grid, colour='vonMises'):
    """The moving blocks' surfaces coloured by `colour` (vonMises, or the magnitude of displacement), the
    fixed ones grey, edges drawn; and the colour map."""
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper
    moving = threshold(grid, 'cells', 'fixed', 0, 0)
    high = moving.GetCellData().GetArray(colour).GetRange(-1)[1] if moving.GetNumberOfCells() else 0.0
    lut = colourMap(0.0, high if high > 0 else 1.0)
    lut.SetVectorModeToMagnitude()
    actors = []
    for blocks, coloured in ((moving, True), (threshold(grid, 'cells', 'fixed', 1, 1), False)):
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(blocks)
        if coloured:
            mapper.SetScalarModeToUseCellFieldData()
            mapper.SelectColorArray(colour)
            mapper.SetLookupTable(lut)
            mapper.SetUseLookupTableScalarRange(True)
            mapper.ScalarVisibilityOn()
        else:
            mapper.ScalarVisibilityOff()
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().EdgeVisibilityOn()
        actor.GetProperty().SetEdgeColor(0.15, 0.15, 0.15)
        actor.GetProperty().SetLineWidth(1.5)
        if coloured:
            actor.GetProperty().SetOpacity(0.6)
        else:
            actor.GetProperty().SetColor(0.78, 0.78, 0.76)
            actor.GetProperty().SetAmbient(0.35)
            actor.GetProperty().SetDiffuse(0.65)
        actors.append(actor)
    return actors, lut


def contactsActor(poly, length):
    """Arrows at the closed contacts along their normal, length proportional to the normal
    force (the largest `length` [m]); (None, 0) without closed contacts."""
    from vtkmodules.vtkFiltersCore import vtkGlyph3D
    from vtkmodules.vtkFiltersSources import vtkArrowSource
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper
    if poly.GetNumberOfPoints() == 0:
        return None, 0
    points = threshold(poly, 'points', 'state', 1, 2)   # sliding or locked
    if points.GetNumberOfPoints() == 0:
        return None, 0
    data = points.GetPointData()
    data.SetActiveVectors('normal')
    data.SetActiveScalars('normalForce')
    largest = data.GetArray('normalForce').GetRange()[1]
    arrow = vtkArrowSource()
    arrow.SetShaftRadius(0.06)
    arrow.SetTipRadius(0.15)
    glyphs = vtkGlyph3D()
    glyphs.SetInputData(points)
    glyphs.SetSourceConnection(arrow.GetOutputPort())
    glyphs.SetVectorModeToUseVector()
    glyphs.SetScaleModeToScaleByScalar()
    glyphs.SetScaleFactor(length / largest if largest > 0 else 0)
    glyphs.OrientOn()
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(glyphs.GetOutputPort())
    mapper.ScalarVisibilityOff()
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.05, 0.05, 0.05)
    return actor, points.GetNumberOfPoints()


def render(blocksPvd, contactsPvd, out, size=(1200, 900), colour='vonMises', view=(-1, -1.8, 1.3), cut=None,
           arrows=0.5):
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow, vtkTextActor, vtkWindowToImageFilter
    import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the render window's implementation)
    time, blocksPath = lastOutput(blocksPvd)
    grid = read(blocksPath)
    if cut is not None:
        grid = cutAway(grid, cut)
    renderer = vtkRenderer()
    renderer.SetBackground(1, 1, 1)
    actors, lut = blocksActors(grid, colour)
    for actor in actors:
        renderer.AddActor(actor)
    closed = 0
    if os.path.isfile(contactsPvd):
        glyphs, closed = contactsActor(read(lastOutput(contactsPvd)[1]), length=arrows)
        if glyphs is not None and arrows > 0:
            renderer.AddActor(glyphs)
    bar = vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle({'vonMises': 'von Mises stress [Pa]', 'displacement': 'displacement [m]'}.get(colour, colour))
    bar.SetNumberOfLabels(5)
    bar.SetLabelFormat('%.2g')
    bar.SetPosition(0.84, 0.12)
    bar.SetWidth(0.12)
    bar.SetHeight(0.78)
    bar.UnconstrainedFontSizeOn()
    for text, points in ((bar.GetTitleTextProperty(), 20), (bar.GetLabelTextProperty(), 18)):
        text.SetColor(0, 0, 0)
        text.SetFontSize(points)
        text.ItalicOff()
        text.ShadowOff()
    renderer.AddActor2D(bar)
    caption = vtkTextActor()
    fixed = int(sum(grid.GetCellData().GetArray('fixed').GetValue(k) for k in range(grid.GetNumberOfCells())))
    caption.SetInput('t = %.3f s   %d blocks shown (%d fixed, grey)   %d closed contacts%s'
                     % (time, grid.GetNumberOfCells(), fixed, closed, ' (arrows: normal force)' if arrows > 0 else ''))
    caption.GetTextProperty().SetColor(0, 0, 0)
    caption.GetTextProperty().SetFontSize(22)
    caption.SetPosition(20, 20)
    renderer.AddActor2D(caption)
    camera = renderer.GetActiveCamera()   # from the south-west, above; framing the moving blocks
    camera.SetViewUp(0, 0, 1)
    camera.SetPosition(*view)
    camera.SetFocalPoint(0, 0, 0)
    renderer.ResetCamera(actors[0].GetBounds() if actors[0].GetMapper().GetInput().GetNumberOfCells()
                         else grid.GetBounds())
    camera.Zoom(0.85)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    window.Render()
    image = vtkWindowToImageFilter()
    image.SetInput(window)
    image.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(out)
    writer.SetInputConnection(image.GetOutputPort())
    writer.Write()
    print('render_vtk: %s (t = %.6g s, from %s)' % (out, time, blocksPath))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('prefix', help="a DDAVTKRecorder fileName (e.g. vtk_pile/pile-) or a directory")
    parser.add_argument('--out', default='vtk_pile.png')
    parser.add_argument('--colour', default='vonMises', help="the blocks' cell array: vonMises or displacement")
    parser.add_argument('--view', type=float, nargs=3, default=(-1, -1.8, 1.3),
                        help='direction from the moving blocks to the camera')
    parser.add_argument('--cut', type=float, nargs=4, metavar=('A', 'B', 'C', 'D'),
                        help='leave out the fixed blocks whose centre has A x + B y + C z > D')
    parser.add_argument('--arrows', type=float, default=0.5, help='length of the largest contact arrow [m]; 0: none')
    args = parser.parse_args()
    if not os.environ.get('DISPLAY') and not os.environ.get('RENDER_VTK_XVFB'):
        if shutil.which('xvfb-run') is None:
            sys.exit('render_vtk: no DISPLAY, and no xvfb-run to make one (Debian: apt-get install xvfb xauth)')
        os.environ['RENDER_VTK_XVFB'] = '1'
        os.execvp('xvfb-run', ['xvfb-run', '-a', '-s', '-screen 0 1600x1200x24', sys.executable,
                               os.path.abspath(__file__)] + sys.argv[1:])
    blocks, contacts = seriesOf(args.prefix)
    render(blocks, contacts, args.out, colour=args.colour, view=args.view, cut=args.cut, arrows=args.arrows)


if __name__ == '__main__':
    main()
