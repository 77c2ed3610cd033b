# gltf-draco.py — writes the KHR_draco_mesh_compression fixtures of tests/data/gltf-draco
# (test_texture gltf_draco): a UV sphere (16 x 8 facets, its exact normals and texture
# coordinates) Draco-compressed (positions 14 bits, normals 10, texture coordinates 12) in
# sphere-draco32.gltf with 32-bit indices and in sphere-draco16.gltf with 16-bit ones, and
# sphere-float.gltf: the same mesh as plain float accessors holding what Draco decodes
# (DracoPy's decode of the same bytes), which the Draco files must load as. Optional
# tooling (pip install DracoPy numpy): the files are committed.
#
#   python3 scripts/gltf-draco.py
import base64, json, math, os
import numpy as np
import DracoPy

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "data", "gltf-draco")


def sphere(nu=16, nv=8):
    pos, uv, tri = [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            pos.append((math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)))
            uv.append((i / nu, j / nv))
    for j in range(nv):
        for i in range(nu):
            a, b = j * (nu + 1) + i, (j + 1) * (nu + 1) + i
            if j < nv - 1:
                tri.append((a, b, b + 1))
            if j > 0:  # no triangle of zero area at the poles
                tri.append((a, b + 1, a + 1))
    return np.array(pos), np.array(uv), np.array(tri, np.uint32)


def gltf(name, accessors, views, data, prim_ext=None, ext=False):
    while len(data) % 4:
        data += b"\0"
    prim = {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}
    if prim_ext:
        prim["extensions"] = {"KHR_draco_mesh_compression": prim_ext}
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
         "meshes": [{"primitives": [prim]}],
         "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
         "bufferViews": views, "accessors": accessors}
    if ext:
        g["extensionsUsed"] = g["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(g, f, indent=1)


def main():
    P, T, I = sphere()
    enc = DracoPy.encode(P, I, quantization_bits=14, tex_coord=T, normals=P, preserve_order=True,
                         tex_coord_quantization_bits=12, normal_quantization_bits=10)
    m = DracoPy.decode(enc)
    ids = {a["attribute_type"]: a["unique_id"] for a in m.attributes}  # 0 position, 1 normal, 3 texture coordinate
    n = len(m.points)
    lo, hi = np.min(m.points, 0).tolist(), np.max(m.points, 0).tolist()
    for bits, ct in ((32, 5125), (16, 5123)):
        acc = [{"componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}, {"componentType": 5126, "count": n, "type": "VEC3"},
               {"componentType": 5126, "count": n, "type": "VEC2"}, {"componentType": ct, "count": int(I.size), "type": "SCALAR"}]
        gltf("sphere-draco%d.gltf" % bits, acc, [{"buffer": 0, "byteLength": len(enc)}], bytes(enc),
             {"bufferView": 0, "attributes": {"POSITION": ids[0], "NORMAL": ids[1], "TEXCOORD_0": ids[3]}}, True)
    parts = [np.asarray(m.points, np.float32), np.asarray(m.normals, np.float32), np.asarray(m.tex_coord, np.float32), np.asarray(m.faces, np.uint32)]
    data, views = b"", []
    for p in parts:
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": p.nbytes})
        data += p.tobytes()
    acc = [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi},
           {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"}, {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
           {"bufferView": 3, "componentType": 5125, "count": int(I.size), "type": "SCALAR"}]
    gltf("sphere-float.gltf", acc, views, data)


if __name__ == "__main__":
    main()
