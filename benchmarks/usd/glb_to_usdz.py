# A glTF binary's meshes (in its node hierarchy, each node's transform) and its metallic-roughness
# materials written as a .usdz by Pixar's own library (PyPI usd-core 26.11; pygltflib, numpy),
# textures packaged with their samplers' wrap modes and KHR_texture_transform as UsdTransform2d,
# colour, metallic, roughness, emission and occlusion factors as textures' scales (and biases),
# alpha modes as opacity (and its threshold), a second set of texture coordinates as primvar st1,
# so that the USD loader can be compared with the glTF one on real models (benchmarks/usd.md).
# Run in a throwaway environment, never a dependency of the project:
#   python3 -m venv /tmp/v && /tmp/v/bin/pip install usd-core==26.11 pygltflib numpy
#   /tmp/v/bin/python benchmarks/usd/glb_to_usdz.py IN.glb OUT.usdz
# A .gltf with its files beside it is read too (its buffers and images by their URIs).
#
# The texture transform: glTF's uv' = T·R·S·uv (v down) is USD's st' = R(θ)·S·st + t (t = 1 − v)
# with θ the same angle, S the same scale and t = (ox + sy·sin θ, 1 − oy − sy·cos θ). The USD
# working group's conversion of Khronos's TextureTransformTest holds exactly these values (its
# material "All": 17.188734°, 1.5, (0.24328034, −0.33300462) for glTF's 0.3, 1.5, (−0.2, −0.1)).
import sys, os, io, math, numpy as np, pygltflib
from pxr import Usd, UsdGeom, UsdShade, Sdf, Gf, UsdUtils
src, out = sys.argv[1], sys.argv[2]
g = pygltflib.GLTF2().load(src)
if src.endswith(".gltf"): g.convert_buffers(pygltflib.BufferFormat.BINARYBLOB)
blob = g.binary_blob()
def acc(i):
    a = g.accessors[i]; v = g.bufferViews[a.bufferView]
    n = {"SCALAR":1,"VEC2":2,"VEC3":3,"VEC4":4}[a.type]
    dt = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}[a.componentType]
    off = (v.byteOffset or 0) + (a.byteOffset or 0)
    stride = v.byteStride or n * np.dtype(dt).itemsize
    raw = np.frombuffer(blob, dtype=np.uint8, count=stride*(a.count-1)+n*np.dtype(dt).itemsize, offset=off)
    return np.lib.stride_tricks.as_strided(raw.view(dt), shape=(a.count, n), strides=(stride, np.dtype(dt).itemsize)).copy()
tmp = out + ".dir"; os.makedirs(tmp + "/tex", exist_ok=True)
stage = Usd.Stage.CreateNew(f"{tmp}/scene.usdc")
UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y); UsdGeom.SetStageMetersPerUnit(stage, 1.0)
root = UsdGeom.Xform.Define(stage, "/Root"); stage.SetDefaultPrim(root.GetPrim())
def image(i):
    im = g.images[i]
    if im.uri:
        data = open(os.path.join(os.path.dirname(src), im.uri), "rb").read()
        ext = "png" if im.uri.lower().endswith(".png") else "jpg"
    else:
        v = g.bufferViews[im.bufferView]
        data = blob[v.byteOffset or 0:(v.byteOffset or 0)+v.byteLength]
        ext = "png" if "png" in (im.mimeType or "") else "jpg"
    name = f"tex/image{i}.{ext}"
    open(f"{tmp}/{name}", "wb").write(data)
    return name
WRAP = {33071: "clamp", 33648: "mirror", 10497: "repeat"}
def texture(mat, shader, inp, tex, output, ctype, reader, extra=None):
    t = UsdShade.Shader.Define(stage, f"{mat}/{inp}Tex"); t.CreateIdAttr("UsdUVTexture")
    gt = g.textures[tex.index]
    t.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(image(gt.source))
    if gt.sampler is not None:
        smp = g.samplers[gt.sampler]
        t.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set(WRAP[smp.wrapS or 10497])
        t.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set(WRAP[smp.wrapT or 10497])
    source = reader
    tt = (tex.extensions or {}).get("KHR_texture_transform")
    if tt:
        theta = tt.get("rotation", 0.0); sx, sy = tt.get("scale", [1.0, 1.0]); ox, oy = tt.get("offset", [0.0, 0.0])
        place = UsdShade.Shader.Define(stage, f"{mat}/{inp}Place"); place.CreateIdAttr("UsdTransform2d")
        place.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
        place.CreateInput("rotation", Sdf.ValueTypeNames.Float).Set(math.degrees(theta))
        place.CreateInput("scale", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(sx, sy))
        place.CreateInput("translation", Sdf.ValueTypeNames.Float2).Set(
            Gf.Vec2f(ox + sy * math.sin(theta), 1.0 - oy - sy * math.cos(theta)))
        source = place
    t.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(source.ConnectableAPI(), "result")
    for k, v in (extra or {}).items(): t.CreateInput(k, Sdf.ValueTypeNames.Float4).Set(v)
    t.CreateOutput(output, ctype)
    shader.CreateInput(inp, ctype).ConnectToSource(t.ConnectableAPI(), output)
mats = []
readers = {}
def reader(path, tex):
    # One primvar reader per set of texture coordinates: st, st1.
    n = getattr(tex, "texCoord", 0) or 0
    if (path, n) not in readers:
        rd = UsdShade.Shader.Define(stage, f"{path}/St{n or ''}"); rd.CreateIdAttr("UsdPrimvarReader_float2")
        rd.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("st" if n == 0 else f"st{n}")
        readers[(path, n)] = rd
    return readers[(path, n)]
for mi, m in enumerate(g.materials):
    path = f"/Root/Material{mi}"; mat = UsdShade.Material.Define(stage, path)
    sh = UsdShade.Shader.Define(stage, f"{path}/Surface"); sh.CreateIdAttr("UsdPreviewSurface")
    pbr = m.pbrMetallicRoughness
    base = pbr.baseColorFactor or [1.0, 1.0, 1.0, 1.0]
    if pbr.baseColorTexture:
        texture(path, sh, "diffuseColor", pbr.baseColorTexture, "rgb", Sdf.ValueTypeNames.Color3f, reader(path, pbr.baseColorTexture), {"scale": Gf.Vec4f(*base)})
    else: sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*base[:3]))
    # glTF's alpha: the colour texture's alpha times the factor's, blended or cut.
    if m.alphaMode in ("BLEND", "MASK"):
        if pbr.baseColorTexture:
            texture(path, sh, "opacity", pbr.baseColorTexture, "a", Sdf.ValueTypeNames.Float, reader(path, pbr.baseColorTexture), {"scale": Gf.Vec4f(*base)})
        else: sh.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(base[3])
        if m.alphaMode == "MASK":
            sh.CreateInput("opacityThreshold", Sdf.ValueTypeNames.Float).Set(m.alphaCutoff if m.alphaCutoff is not None else 0.5)
    rough = pbr.roughnessFactor if pbr.roughnessFactor is not None else 1.0
    metal = pbr.metallicFactor if pbr.metallicFactor is not None else 1.0
    if pbr.metallicRoughnessTexture:
        rd = reader(path, pbr.metallicRoughnessTexture)
        texture(path, sh, "roughness", pbr.metallicRoughnessTexture, "g", Sdf.ValueTypeNames.Float, rd, {"scale": Gf.Vec4f(rough, rough, rough, rough)})
        texture(path, sh, "metallic", pbr.metallicRoughnessTexture, "b", Sdf.ValueTypeNames.Float, rd, {"scale": Gf.Vec4f(metal, metal, metal, metal)})
    else:
        sh.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(rough)
        sh.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(metal)
    if m.normalTexture: texture(path, sh, "normal", m.normalTexture, "rgb", Sdf.ValueTypeNames.Normal3f, reader(path, m.normalTexture), {"scale": Gf.Vec4f(2,2,2,1), "bias": Gf.Vec4f(-1,-1,-1,0)})
    if m.occlusionTexture:
        k = m.occlusionTexture.strength if m.occlusionTexture.strength is not None else 1.0
        # glTF's 1 + k·(texel − 1) is USD's texel·scale + bias.
        texture(path, sh, "occlusion", m.occlusionTexture, "r", Sdf.ValueTypeNames.Float, reader(path, m.occlusionTexture), {"scale": Gf.Vec4f(k, k, k, k), "bias": Gf.Vec4f(1 - k, 1 - k, 1 - k, 1 - k)})
    glow = m.emissiveFactor or [0.0, 0.0, 0.0]
    if m.emissiveTexture: texture(path, sh, "emissiveColor", m.emissiveTexture, "rgb", Sdf.ValueTypeNames.Color3f, reader(path, m.emissiveTexture), {"scale": Gf.Vec4f(*glow, 1.0)})
    elif any(glow): sh.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*glow))
    mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
    mats.append(mat)
parents = {c: ni for ni, n in enumerate(g.nodes) for c in (n.children or [])}
def node_path(ni): return (node_path(parents[ni]) if ni in parents else "/Root") + f"/Node{ni}"
k = 0
for ni, node in enumerate(g.nodes):
    x = UsdGeom.Xform.Define(stage, node_path(ni))
    if node.matrix: x.AddTransformOp().Set(Gf.Matrix4d(*node.matrix))
    else:
        if node.translation: x.AddTranslateOp().Set(Gf.Vec3d(*node.translation))
        if node.rotation: x.AddOrientOp().Set(Gf.Quatf(node.rotation[3], *node.rotation[:3]))
        if node.scale: x.AddScaleOp().Set(Gf.Vec3f(*node.scale))
    if node.mesh is None: continue
    for pi, p in enumerate(g.meshes[node.mesh].primitives):
        mesh = UsdGeom.Mesh.Define(stage, f"{node_path(ni)}/Prim{pi}")
        pts = acc(p.attributes.POSITION)
        idx = (acc(p.indices).reshape(-1) if p.indices is not None else np.arange(len(pts))).astype(np.int32)
        mesh.CreatePointsAttr([Gf.Vec3f(*map(float, q)) for q in pts])
        # glTF winds counter-clockwise for the front, as USD's right-handed default does.
        mesh.CreateFaceVertexCountsAttr([3] * (len(idx)//3)); mesh.CreateFaceVertexIndicesAttr(idx.tolist())
        mesh.CreateSubdivisionSchemeAttr("none")
        if p.attributes.NORMAL is not None:
            n = acc(p.attributes.NORMAL); mesh.CreateNormalsAttr([Gf.Vec3f(*map(float, q)) for q in n]); mesh.SetNormalsInterpolation("vertex")
        for name, a in (("st", p.attributes.TEXCOORD_0), ("st1", p.attributes.TEXCOORD_1)):
            if a is None: continue
            uv = acc(a)
            st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(name, Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
            st.Set([Gf.Vec2f(float(q[0]), 1.0 - float(q[1])) for q in uv])
        if p.material is not None:
            UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(mats[p.material])
            if g.materials[p.material].doubleSided: mesh.CreateDoubleSidedAttr(True)
        k += 1
stage.Save()
UsdUtils.CreateNewUsdzPackage(f"{tmp}/scene.usdc", out)
print("meshes", k)
