# Transform stacks as Pixar's own library composes them (PyPI usd-core 26.11, in the throwaway
# environment of reference_usd.py): transforms.usda holds one triangle under each kind of
# xformOp and op order (rotations about each axis in each order, orient, a matrix, scales,
# inverted ops, a pivot, a reset stack, nesting), and transforms-expected.txt each triangle's
# corners in the stage's frame as UsdGeom.XformCache puts them (metres, Y up: no unit or axis
# change). Run once, 2026-12-06:
#   cd core/assets/tests/data/usd && /tmp/v/bin/python reference_transforms.py
# Read by `transforms_compose_as_pixars_library_composes_them` in core/assets/tests/usd_files.rs.
from pxr import Usd, UsdGeom, Gf, Sdf

stage = Usd.Stage.CreateNew("transforms.usda")
UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
UsdGeom.SetStageMetersPerUnit(stage, 1.0)
root = UsdGeom.Xform.Define(stage, "/Root")
stage.SetDefaultPrim(root.GetPrim())
root.AddTranslateOp().Set(Gf.Vec3d(0.5, -0.25, 2.0))
root.AddRotateYOp().Set(30.0)

def triangle(path):
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr([(0.1, 0.0, 0.0), (0.0, 0.2, 0.0), (0.0, 0.0, 0.3)])
    mesh.CreateFaceVertexCountsAttr([3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2])
    return mesh

angles = Gf.Vec3f(20.0, -35.0, 50.0)
for order in ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]:
    m = triangle(f"/Root/Rotate{order}")
    getattr(m, f"AddRotate{order}Op")().Set(angles)
m = triangle("/Root/Orient")
m.AddOrientOp().Set(Gf.Quatf(0.8, Gf.Vec3f(0.2, -0.4, 0.4)).GetNormalized())
m = triangle("/Root/Matrix")
m.AddTransformOp().Set(Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(1, 2, 3), 40.0)) * Gf.Matrix4d().SetTranslate(Gf.Vec3d(1, 2, 3)))
m = triangle("/Root/ScaleAndAxes")
m.AddTranslateOp(UsdGeom.XformOp.PrecisionFloat).Set(Gf.Vec3f(-1, 0, 1))
m.AddScaleOp().Set(Gf.Vec3f(2, 0.5, -1))
m.AddRotateXOp().Set(15.0)
m.AddRotateZOp(UsdGeom.XformOp.PrecisionDouble).Set(-25.0)
m = triangle("/Root/Pivot")
pivot = m.AddTranslateOp(opSuffix="pivot")
pivot.Set(Gf.Vec3d(0.3, 0.1, -0.2))
m.AddRotateZOp().Set(60.0)
m.AddTranslateOp(opSuffix="pivot", isInverseOp=True)
m = triangle("/Root/Reset")
m.SetResetXformStack(True)
m.AddTranslateOp().Set(Gf.Vec3d(7, 8, 9))
outer = UsdGeom.Xform.Define(stage, "/Root/Outer")
outer.AddScaleOp().Set(Gf.Vec3f(3, 3, 3))
outer.AddRotateXYZOp().Set(Gf.Vec3f(10, 20, 30))
m = triangle("/Root/Outer/Inner")
m.AddTranslateOp().Set(Gf.Vec3d(0.1, 0.2, 0.3))
m.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(0.6, Gf.Vec3d(0.0, 0.8, 0.0)))
stage.Save()

cache = UsdGeom.XformCache()
with open("transforms-expected.txt", "w") as out:
    for prim in stage.Traverse():
        if prim.GetTypeName() != "Mesh":
            continue
        world = cache.GetLocalToWorldTransform(prim)
        points = UsdGeom.Mesh(prim).GetPointsAttr().Get()
        corners = [world.Transform(Gf.Vec3d(p)) for p in points]
        out.write(str(prim.GetPath()) + " " + " ".join(f"{c[0]:.9f} {c[1]:.9f} {c[2]:.9f}" for c in corners) + "\n")
