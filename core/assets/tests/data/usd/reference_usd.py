# USD files written by Pixar's own library (PyPI usd-core 26.11), so that the loader is checked
# against files its own crate did not write. Run once, 2026-12-06, in a throwaway virtual
# environment (never a dependency of the project):
#   python3 -m venv /tmp/v && /tmp/v/bin/pip install usd-core==26.11 pillow
#   cd core/assets/tests/data/usd && /tmp/v/bin/python reference_usd.py
# Read by `usd_files_by_pixars_library_read_as_written` in core/assets/tests/mesh_files.rs.
#
# reference-box.usdz: centimetres, +Z up (as Maya and Apple's tools write it). An Xform
# /Artifact moved 100 cm along +x and turned 90° about +z holds
# - Box: a cube of 10 cm made of six quads, scaled by (4, 2, 1) on its own prim (so 40 × 20 × 10
#   cm before its parent turns it), its texture coordinates face-varying, coloured by a 2 × 2 PNG
#   (red, green / blue, white; rows from the top) through a UsdUVTexture reading primvar st;
#   roughness 0.3, metallic 0;
# - Knob: a reference to parts/knob.usda inside the package (a triangle fan, a square pyramid 5 cm
#   high standing on the box's top at the origin), its own material blue-grey (0.2, 0.4, 0.6),
#   metallic 1, roughness 0.25.
# loose/reference-box.usdc: the same stage as a plain binary layer, its texture and the knob's
# layer beside it in loose/ (what Blender and Houdini export).
import os, shutil
from pxr import Usd, UsdGeom, UsdShade, Sdf, Gf, UsdUtils
from PIL import Image

def write_parts(folder):
    os.makedirs(f"{folder}/textures", exist_ok=True)
    os.makedirs(f"{folder}/parts", exist_ok=True)
    img = Image.new("RGB", (2, 2))
    img.putdata([(255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)])
    img.save(f"{folder}/textures/albedo.png")
    knob = Usd.Stage.CreateNew(f"{folder}/parts/knob.usda")
    UsdGeom.SetStageUpAxis(knob, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(knob, 0.01)
    root = UsdGeom.Xform.Define(knob, "/Knob")
    knob.SetDefaultPrim(root.GetPrim())
    mesh = UsdGeom.Mesh.Define(knob, "/Knob/Pyramid")
    mesh.CreatePointsAttr([(-2, -2, 5), (2, -2, 5), (2, 2, 5), (-2, 2, 5), (0, 0, 10)])
    # Four sides (triangles) and the base as one quad: mixed face sizes.
    mesh.CreateFaceVertexCountsAttr([3, 3, 3, 3, 4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4, 0, 3, 2, 1])
    mat = UsdShade.Material.Define(knob, "/Knob/Metal")
    sh = UsdShade.Shader.Define(knob, "/Knob/Metal/Surface")
    sh.CreateIdAttr("UsdPreviewSurface")
    sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.2, 0.4, 0.6))
    sh.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(1.0)
    sh.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.25)
    mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(mat)
    knob.Save()

def write_root(path):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    art = UsdGeom.Xform.Define(stage, "/Artifact")
    stage.SetDefaultPrim(art.GetPrim())
    art.AddTranslateOp().Set(Gf.Vec3d(100, 0, 0))
    art.AddRotateZOp().Set(90.0)
    box = UsdGeom.Mesh.Define(stage, "/Artifact/Box")
    box.AddScaleOp().Set(Gf.Vec3f(4, 2, 1))
    h = 5.0
    box.CreatePointsAttr([(-h, -h, -h), (h, -h, -h), (h, h, -h), (-h, h, -h),
                          (-h, -h, h), (h, -h, h), (h, h, h), (-h, h, h)])
    faces = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    box.CreateFaceVertexCountsAttr([4] * 6)
    box.CreateFaceVertexIndicesAttr([i for f in faces for i in f])
    # Each face's corners over the whole texture: v up from the image's bottom, as USD's st is.
    st = UsdGeom.PrimvarsAPI(box).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                UsdGeom.Tokens.faceVarying)
    st.Set([(0, 0), (1, 0), (1, 1), (0, 1)] * 6)
    mat = UsdShade.Material.Define(stage, "/Artifact/Painted")
    sh = UsdShade.Shader.Define(stage, "/Artifact/Painted/Surface")
    sh.CreateIdAttr("UsdPreviewSurface")
    sh.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.3)
    sh.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    reader = UsdShade.Shader.Define(stage, "/Artifact/Painted/St")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("st")
    tex = UsdShade.Shader.Define(stage, "/Artifact/Painted/Albedo")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("textures/albedo.png")
    tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    tex.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
    sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(tex.ConnectableAPI(), "rgb")
    mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(box.GetPrim()).Bind(mat)
    knob = stage.DefinePrim("/Artifact/Knob")
    knob.GetReferences().AddReference("parts/knob.usda")
    stage.Save()

tmp = "/tmp/reference-usd"
shutil.rmtree(tmp, ignore_errors=True)
write_parts(tmp)
write_root(f"{tmp}/reference-box.usdc")
UsdUtils.CreateNewUsdzPackage(f"{tmp}/reference-box.usdc", "reference-box.usdz")
shutil.rmtree("loose", ignore_errors=True)
os.makedirs("loose")
for f in ("reference-box.usdc", "textures/albedo.png", "parts/knob.usda"):
    os.makedirs(os.path.dirname(f"loose/{f}") or "loose", exist_ok=True)
    shutil.copy(f"{tmp}/{f}", f"loose/{f}")
