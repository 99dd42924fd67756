# Texture coordinates as the UsdPreviewSurface specification places them, in a stage written by
# Pixar's own library (PyPI usd-core 26.11, in the throwaway environment of reference_usd.py).
# Run once, 2026-12-07:
#   cd core/assets/tests/data/usd && /tmp/v/bin/python reference_texture_coordinates.py
# Read by `texture_coordinates_follow_the_transform_and_the_primvar_named` in
# core/assets/tests/usd_files.rs.
#
# coords/texture-coordinates.usda (metres, +Y up): a unit quad "Tile" in the xy plane with two
# sets of texture coordinates, primvars:st (vertex) and primvars:st1 (face-varying; its corners
# are those of st mirrored left to right), and material "Transformed":
# - its colour from coords/grid.png through a UsdTransform2d holding the values the USD working
#   group's conversion of Khronos's TextureTransformTest gives its material "All" (rotation
#   17.188734°, scale (1.5, 1.5), translation (0.24328034, -0.33300462); glTF: rotation 0.3,
#   scale 1.5, offset (-0.2, -0.1)); the primvar reader's varname an interface input of the
#   material (inputs:frame:stPrimvarName = "st"), as Blender and Apple's tools write it;
# - its occlusion from coords/grid.png's red channel through a second reader, varname "st1", no
#   transform.
# coords/grid.png: 4 × 4 texels, each a distinct colour (r = 60·column + 15, g = 60·row + 15 with
# rows from the image's top, b = 128), so that a test can tell which texel a coordinate lands on.
import os
from pxr import Usd, UsdGeom, UsdShade, Sdf, Gf
from PIL import Image

os.makedirs("coords", exist_ok=True)
img = Image.new("RGB", (4, 4))
img.putdata([(60 * x + 15, 60 * y + 15, 128) for y in range(4) for x in range(4)])
img.save("coords/grid.png")

stage = Usd.Stage.CreateNew("coords/texture-coordinates.usda")
UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
UsdGeom.SetStageMetersPerUnit(stage, 1.0)
root = UsdGeom.Xform.Define(stage, "/Root")
stage.SetDefaultPrim(root.GetPrim())
mesh = UsdGeom.Mesh.Define(stage, "/Root/Tile")
mesh.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
mesh.CreateFaceVertexCountsAttr([4])
mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
pv = UsdGeom.PrimvarsAPI(mesh)
st = pv.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
st.Set([(0, 0), (1, 0), (1, 1), (0, 1)])
st1 = pv.CreatePrimvar("st1", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying)
st1.Set([(1, 0), (0, 0), (0, 1), (1, 1)])

mat = UsdShade.Material.Define(stage, "/Root/Transformed")
name_input = mat.CreateInput("frame:stPrimvarName", Sdf.ValueTypeNames.Token)
name_input.Set("st")
surface = UsdShade.Shader.Define(stage, "/Root/Transformed/Surface")
surface.CreateIdAttr("UsdPreviewSurface")
mat.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")

reader = UsdShade.Shader.Define(stage, "/Root/Transformed/Reader")
reader.CreateIdAttr("UsdPrimvarReader_float2")
reader.CreateInput("varname", Sdf.ValueTypeNames.Token).ConnectToSource(name_input)
transform = UsdShade.Shader.Define(stage, "/Root/Transformed/Place")
transform.CreateIdAttr("UsdTransform2d")
transform.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
transform.CreateInput("rotation", Sdf.ValueTypeNames.Float).Set(17.188734)
transform.CreateInput("scale", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(1.5, 1.5))
transform.CreateInput("translation", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(0.24328034, -0.33300462))
colour = UsdShade.Shader.Define(stage, "/Root/Transformed/Colour")
colour.CreateIdAttr("UsdUVTexture")
colour.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("grid.png")
colour.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(transform.ConnectableAPI(), "result")
colour.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
colour.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(colour.ConnectableAPI(), "rgb")

reader1 = UsdShade.Shader.Define(stage, "/Root/Transformed/Reader1")
reader1.CreateIdAttr("UsdPrimvarReader_float2")
reader1.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st1")
occlusion = UsdShade.Shader.Define(stage, "/Root/Transformed/Occlusion")
occlusion.CreateIdAttr("UsdUVTexture")
occlusion.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("grid.png")
occlusion.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader1.ConnectableAPI(), "result")
surface.CreateInput("occlusion", Sdf.ValueTypeNames.Float).ConnectToSource(occlusion.ConnectableAPI(), "r")

UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(mat)
stage.Save()
