# Primitive shapes in a stage written by Pixar's own library (PyPI usd-core 26.11, in the throwaway
# environment of reference_usd.py), with the world-space extents that library computes for each.
# Run once, 2026-12-07:
#   cd core/assets/tests/data/usd && /tmp/u/bin/python reference_shapes.py > shapes-expected.txt
# Read by `primitive_shapes_written_by_pixars_library_fill_its_extents` in
# core/assets/tests/usd_files.rs (and seeds the `gltf` fuzz target, `cargo xtask fuzz`).
#
# shapes.usda (metres, +Y up): one prim of each kind, most with authored sizes and an axis, each
# moved (and one stretched) by its own xformOps, a display colour on one, a material
# bound to another; a Cube and a Plane at the schema's fallbacks. shapes-expected.txt: each prim's
# path and its extent in the stage's world frame (UsdGeom.BBoxCache of the default purpose, which
# applies the prim's transform to the extent ComputeExtentFromPlugins gives), min then max.
from pxr import Usd, UsdGeom, UsdShade, Sdf, Gf

stage = Usd.Stage.CreateNew("shapes.usda")
UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
UsdGeom.SetStageMetersPerUnit(stage, 1.0)


def place(prim, translate, scale=None):
    xf = UsdGeom.Xformable(prim)
    xf.AddTranslateOp().Set(Gf.Vec3d(*translate))
    if scale is not None:
        xf.AddScaleOp().Set(Gf.Vec3f(*scale))


cube = UsdGeom.Cube.Define(stage, "/Shapes/Cube")
place(cube, (0, 0, 0))
sphere = UsdGeom.Sphere.Define(stage, "/Shapes/Sphere")
sphere.CreateRadiusAttr(0.5)
sphere.CreateDisplayColorAttr([Gf.Vec3f(0.8, 0.1, 0.1)])
place(sphere, (3, 0, 0))
cylinder = UsdGeom.Cylinder.Define(stage, "/Shapes/Cylinder")
cylinder.CreateRadiusAttr(0.25)
cylinder.CreateHeightAttr(1.5)
cylinder.CreateAxisAttr("X")
place(cylinder, (0, 3, 0), scale=(1, 2, 1))
cylinder1 = stage.DefinePrim("/Shapes/Frustum", "Cylinder_1")
cylinder1.CreateAttribute("radiusTop", Sdf.ValueTypeNames.Double).Set(0.2)
cylinder1.CreateAttribute("radiusBottom", Sdf.ValueTypeNames.Double).Set(0.6)
cylinder1.CreateAttribute("height", Sdf.ValueTypeNames.Double).Set(1.0)
cylinder1.CreateAttribute("axis", Sdf.ValueTypeNames.Token).Set("Y")
place(cylinder1, (-3, 0, 0))
cone = UsdGeom.Cone.Define(stage, "/Shapes/Cone")
cone.CreateRadiusAttr(0.75)
cone.CreateHeightAttr(2.0)
cone.CreateAxisAttr("Y")
place(cone, (0, -3, 0))
capsule = UsdGeom.Capsule.Define(stage, "/Shapes/Capsule")
capsule.CreateRadiusAttr(0.3)
capsule.CreateHeightAttr(1.2)
place(capsule, (0, 0, 3))
capsule1 = stage.DefinePrim("/Shapes/Pestle", "Capsule_1")
capsule1.CreateAttribute("radiusTop", Sdf.ValueTypeNames.Double).Set(0.15)
capsule1.CreateAttribute("radiusBottom", Sdf.ValueTypeNames.Double).Set(0.4)
capsule1.CreateAttribute("height", Sdf.ValueTypeNames.Double).Set(1.0)
capsule1.CreateAttribute("axis", Sdf.ValueTypeNames.Token).Set("X")
place(capsule1, (0, 0, -3))
plane = UsdGeom.Plane.Define(stage, "/Shapes/Plane")
place(plane, (3, 3, 3))

material = UsdShade.Material.Define(stage, "/Looks/Brass")
shader = UsdShade.Shader.Define(stage, "/Looks/Brass/Surface")
shader.CreateIdAttr("UsdPreviewSurface")
shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.8, 0.55, 0.25))
shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(1.0)
shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.3)
material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
UsdShade.MaterialBindingAPI.Apply(capsule1.GetPrim()).Bind(material)

for prim in stage.Traverse():
    if prim.IsA(UsdGeom.Gprim):
        UsdGeom.Boundable(prim).GetExtentAttr().Set(
            UsdGeom.Boundable.ComputeExtentFromPlugins(UsdGeom.Boundable(prim), Usd.TimeCode.Default()))
stage.GetRootLayer().Save()

cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
for prim in stage.Traverse():
    if prim.IsA(UsdGeom.Gprim):
        box = cache.ComputeWorldBound(prim).ComputeAlignedRange()
        lo, hi = box.GetMin(), box.GetMax()
        print(prim.GetPath(), *[f"{v:.7f}" for v in (*lo, *hi)])
