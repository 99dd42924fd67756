# A point cloud as a USD Points prim, written by Pixar's own library (PyPI usd-core 26.11, in the
# throwaway environment of reference_usd.py). Run once, 2026-12-07:
#   cd core/assets/tests/data/usd && /tmp/v/bin/python reference_points.py
# Read by `a_points_prim_is_drawn_as_a_closed_cloud` in core/assets/tests/usd_files.rs.
#
# points.usdc (binary; centimetres, +Z up, as Maya and Apple's tools write it): /Scan/Sphere, 2000
# points on a sphere of radius 10 cm (a Fibonacci lattice) 50 cm above the origin (its Xform's
# translate), no normals, widths 0.5 cm, displayColor per point: red above its equator, blue
# below; /Scan/Helper, a guide Points prim (purpose "guide", far away), which no viewer draws.
import math
from pxr import Usd, UsdGeom, Sdf, Gf

stage = Usd.Stage.CreateNew("points.usdc")
UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
UsdGeom.SetStageMetersPerUnit(stage, 0.01)
scan = UsdGeom.Xform.Define(stage, "/Scan")
stage.SetDefaultPrim(scan.GetPrim())
scan.AddTranslateOp().Set(Gf.Vec3d(0, 0, 50))
n = 2000
golden = math.pi * (3 - math.sqrt(5))
pts, colours = [], []
for i in range(n):
    z = 1 - 2 * (i + 0.5) / n
    r = math.sqrt(1 - z * z)
    a = golden * i
    pts.append(Gf.Vec3f(10 * r * math.cos(a), 10 * r * math.sin(a), 10 * z))
    colours.append(Gf.Vec3f(1, 0, 0) if z > 0 else Gf.Vec3f(0, 0, 1))
sphere = UsdGeom.Points.Define(stage, "/Scan/Sphere")
sphere.CreatePointsAttr(pts)
sphere.CreateWidthsAttr([0.5] * n)
sphere.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
sphere.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(colours)
helper = UsdGeom.Points.Define(stage, "/Scan/Helper")
helper.CreatePointsAttr([Gf.Vec3f(1000, 0, 0), Gf.Vec3f(1001, 0, 0), Gf.Vec3f(1000, 1, 0)])
helper.CreatePurposeAttr(UsdGeom.Tokens.guide)
stage.Save()
