"""Render docs/figures/paraview_block_gravity.png: the XDMF output of
examples/block_gravity_2d.nml in ParaView (pvbatch, offscreen), the way docs/paraview.md opens it.

    build/release/empm run examples/block_gravity_2d.nml -o /tmp/block_gravity_2d.h5
    xvfb-run -a pvbatch docs/figures/make_paraview_figure.py /tmp/block_gravity_2d.xmf \
        docs/figures/paraview_block_gravity.png
"""
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene,
                             GetColorTransferFunction, GetScalarBar, OpenDataFile, Render, SaveScreenshot, Show)

xmf, png = sys.argv[1], sys.argv[2]
reader = OpenDataFile(xmf)          # the reader ParaView picks for .xmf
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = reader.TimestepValues[-1]  # last frame, t = 1 s
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [900, 700]
view.ViewTime = reader.TimestepValues[-1]
view.OrientationAxesVisibility = 1
display = Show(reader, view)
display.SetRepresentationType("Points")
display.PointSize = 9
display.RenderPointsAsSpheres = 1
ColorBy(display, ("POINTS", "stress", "4"))  # component 4 of the row-major tensor: yy
lut = GetColorTransferFunction("stress")
lut.ApplyPreset("Cool to Warm", True)
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = "stress 4 = yy [Pa]"
bar.ComponentTitle = ""
view.ResetCamera()
view.CameraPosition = [0.5, 0.5, 3.2]
view.CameraFocalPoint = [0.5, 0.5, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
Render(view)
SaveScreenshot(png, view, ImageResolution=[900, 700])
print("wrote", png, "reader", reader.GetXMLName(), "times", list(reader.TimestepValues))
