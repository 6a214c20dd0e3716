"""pvpython: the von Mises stress on the deformed mesh of the last frame of a femb-solve
animation, saved as a PNG. usage: pvpython render_stress.py ANIMATION.xdmf OUT.png [SCALE]
(SCALE exaggerates the deformation: the drawn mesh is x + (SCALE - 1) * deformation)."""
import sys

from paraview.simple import (ColorBy, GetActiveCamera, GetActiveViewOrCreate, GetColorTransferFunction, GetScalarBar,
                             OpenDataFile, SaveScreenshot, Show, Text, WarpByVector)

source = OpenDataFile(sys.argv[1])
source.UpdatePipelineInformation()
scale = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1400, 800]
view.ViewTime = source.TimestepValues[-1] if source.TimestepValues else 0.0
view.OrientationAxesVisibility = 1
view.Background = [1, 1, 1]
try:  # ParaView >= 5.10 uses a palette background unless told otherwise
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
warp = WarpByVector(Input=source)
warp.Vectors = ["POINTS", "deformation"]
warp.ScaleFactor = scale - 1.0
display = Show(warp, view)
ColorBy(display, ("POINTS", "von_mises"))
lut = GetColorTransferFunction("von_mises")
lut.ApplyPreset("Turbo", True)
display.RescaleTransferFunctionToDataRange(True, False)
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = "von Mises [Pa]"
bar.ComponentTitle = ""
bar.TitleColor = bar.LabelColor = [0, 0, 0]
view.CameraPosition = [0.075, -0.25, 0.30]
view.CameraFocalPoint = [0.075, 0.0, 0.01]
view.CameraViewUp = [0, 0, 1]
view.ResetCamera()
GetActiveCamera().Dolly(1.7)
label = Text(Text=f"von Mises stress, deformation x {scale:g} (femb-solve, t = {view.ViewTime:g})")
label_display = Show(label, view)
label_display.Color = [0, 0, 0]
label_display.FontSize = 14
SaveScreenshot(sys.argv[2], view, ImageResolution=[1400, 800])
print("render_stress: wrote", sys.argv[2])
