"""A glTF binary of N small boxes on a grid in 8 materials (a CAD export's shape), for
benchmarks/many-parts.md:

    python3 benchmarks/many_parts/many_parts.py N distinct|shared|joined OUT.glb

distinct: each box its own node and mesh (N primitives); shared: every node draws mesh 0 (one
material); joined: the same boxes as `distinct`, written as one node with one primitive per
material (what the loader's joining makes of `distinct`)."""
import json
import math
import struct
import sys

n, mode, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
CORNERS = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
FACES = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
side = math.ceil(n ** (1 / 3))


def size(k):
    return 0.01 * (0.8 + 0.2 * ((k * 7919) % 13) / 13)


def place(k):
    return (k % side * 0.015, (k // side) % side * 0.015, k // (side * side) * 0.015)


binary = bytearray()
views, accessors = [], []


def add(positions, indices):
    """Adds one primitive's accessors; returns (position accessor, index accessor)."""
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
    binary.extend(data)
    lo = [min(p[a] for p in positions) for a in range(3)]
    hi = [max(p[a] for p in positions) for a in range(3)]
    accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(positions),
                      "type": "VEC3", "min": lo, "max": hi})
    data = struct.pack("<%dI" % len(indices), *indices)
    views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
    binary.extend(data)
    accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"})
    return len(accessors) - 2, len(accessors) - 1


meshes, nodes = [], []
if mode == "joined":
    primitives = []
    for m in range(8):
        positions, indices = [], []
        for k in range(m, n, 8):
            base = len(positions)
            positions += [tuple(o + c * size(k) for o, c in zip(place(k), corner)) for corner in CORNERS]
            indices += [base + i for i in FACES]
        p, i = add(positions, indices)
        primitives.append({"attributes": {"POSITION": p}, "indices": i, "material": m})
    meshes.append({"primitives": primitives})
    nodes.append({"mesh": 0})
else:
    for k in range(n if mode == "distinct" else 1):
        p, i = add([tuple(c * size(k) for c in corner) for corner in CORNERS], FACES)
        meshes.append({"primitives": [{"attributes": {"POSITION": p}, "indices": i, "material": k % 8}]})
    for k in range(n):
        nodes.append({"mesh": k if mode == "distinct" else 0, "translation": list(place(k))})
materials = [{"pbrMetallicRoughness": {"baseColorFactor": [(m & 1) * 0.8 + 0.1, (m >> 1 & 1) * 0.8 + 0.1,
                                                           (m >> 2 & 1) * 0.8 + 0.1, 1],
                                       "metallicFactor": 0.0, "roughnessFactor": 0.5}} for m in range(8)]
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
       "meshes": meshes, "materials": materials, "accessors": accessors, "bufferViews": views,
       "buffers": [{"byteLength": len(binary)}]}
text = json.dumps(doc).encode()
text += b" " * (-len(text) % 4)
binary.extend(b"\0" * (-len(binary) % 4))
with open(out, "wb") as f:
    f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
    f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
    f.write(struct.pack("<II", len(binary), 0x004E4942) + bytes(binary))
