# mitsuba-reference.py — an independent reference image of a valo JSON scene, rendered by
# Mitsuba 3 from the same OBJ+MTL files valo reads (optional tooling: valo builds, renders
# and tests without Python; the EXRs this makes are committed).
#
#   pip install mitsuba
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 scripts/mitsuba-reference.py scenes/manylight.json --integrator direct --spp 4096 --res 64x48 \
#       --out tests/data/manylight-direct-mitsuba.exr
#
# --integrator direct: Mitsuba's "direct" (emission seen by the camera plus direct light
# at the first surface: what restir-di estimates); direct-bsdf: the same by BSDF sampling
# alone (bounded samples on diffuse surfaces: no heavy tail where lamps sit near surfaces,
# slower); path: Mitsuba's "path" with unlimited
# depth (what restir-gi and valo's path estimate). --variant defaults to llvm_ad_rgb
# (needs an LLVM >= 16 shared library, see DRJIT_LIBLLVM_PATH above), scalar_rgb works
# everywhere but slowly.
#
# Conventions matched (docs/integrators.md, "References"):
#  - the scene's OBJ files are read here, not by Mitsuba's loader: polygons fanned from
#    their first vertex (as Assimp does), one mesh per MTL material, flat shading;
#  - Kd: Lambertian ("diffuse"); Ke: an area emitter of that radiance, one-sided on the
#    counter-clockwise side (valo's and Mitsuba's front side); only these two (the
#    many-light scenes use nothing else; any other MTL key is refused);
#  - camera: the JSON camera (position, look_at, up, vertical fov), pinhole; the film's
#    box filter of one pixel ("box" rfilter); an independent sampler;
#  - a shape's JSON "material" (diffuse reflectance/emission, smooth dielectric with
#    interior ior, exterior 1) replaces its MTL; analytic spheres are Mitsuba spheres;
#  - no environment (the scenes have none).
import argparse, json, os, sys, tempfile

ap = argparse.ArgumentParser()
ap.add_argument("scene")
ap.add_argument("--integrator", default="direct", choices=["direct", "direct-bsdf", "path"])
ap.add_argument("--spp", type=int, default=4096)
ap.add_argument("--res", default="")
ap.add_argument("--out", required=True)
ap.add_argument("--variant", default="llvm_ad_rgb")
ap.add_argument("--seed", type=int, default=3)
ap.add_argument("--passes", type=int, default=1, help="render this many passes of --spp (seeds seed..) and average")
a = ap.parse_args()

import mitsuba as mi
mi.set_variant(a.variant)

with open(a.scene) as f:
    sc = json.load(f)
base = os.path.dirname(os.path.abspath(a.scene))
w, h = sc.get("film", {}).get("width", 256), sc.get("film", {}).get("height", 256)
if a.res:
    w, h = (int(v) for v in a.res.split("x"))
cam = sc["camera"]


def read_mtl(path):
    mats, cur = {}, None
    for line in open(path):
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        if t[0] == "newmtl":
            cur = t[1]
            mats[cur] = {"Kd": [0.8, 0.8, 0.8], "Ke": [0, 0, 0]}
        elif t[0] in ("Kd", "Ke"):
            mats[cur][t[0]] = [float(v) for v in t[1:4]]
        else:
            sys.exit("%s: MTL key %s is not converted by this script" % (path, t[0]))
    return mats


def read_obj(path):
    """Triangles per material: {name: [(a, b, c), ...]} (positions)."""
    v, groups, cur, mats = [], {}, "default", {"default": {"Kd": [0.8, 0.8, 0.8], "Ke": [0, 0, 0]}}
    for line in open(path):
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        if t[0] == "v":
            v.append(tuple(float(x) for x in t[1:4]))
        elif t[0] == "mtllib":
            mats.update(read_mtl(os.path.join(os.path.dirname(path), t[1])))
        elif t[0] == "usemtl":
            cur = t[1]
        elif t[0] == "f":
            idx = [int(x.split("/")[0]) for x in t[1:]]
            idx = [i - 1 if i > 0 else len(v) + i for i in idx]
            for k in range(1, len(idx) - 1):
                groups.setdefault(cur, []).append((v[idx[0]], v[idx[k]], v[idx[k + 1]]))
    return groups, mats


def json_bsdf(name):
    """A JSON material (only those the reference scenes use): diffuse with optional
    emission, or smooth dielectric."""
    m = sc["materials"][name]
    if m.get("type", "diffuse") == "dielectric":
        if set(m) - {"type", "ior"}:
            sys.exit("material %s: only ior is converted for dielectrics" % name)
        return {"type": "dielectric", "int_ior": m.get("ior", 1.5), "ext_ior": 1.0}, None
    if m.get("type", "diffuse") != "diffuse" or set(m) - {"type", "reflectance", "emission"}:
        sys.exit("material %s: only diffuse (reflectance, emission) and dielectric are converted" % name)
    rgb = lambda v: [float(v)] * 3 if not isinstance(v, list) else [float(x) for x in v]
    b = {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb(m.get("reflectance", 0.8))}}
    e = rgb(m.get("emission", 0))
    return b, ({"type": "area", "radiance": {"type": "rgb", "value": e}} if any(c > 0 for c in e) else None)


tmp = tempfile.mkdtemp(prefix="valo-mitsuba-")
shapes = {}
n = 0
for shp in sc["shapes"]:
    if shp.get("type") == "sphere" and set(shp) <= {"type", "center", "radius", "material"}:
        b, e = json_bsdf(shp["material"])
        d = {"type": "sphere", "center": shp["center"], "radius": shp["radius"], "bsdf": b}
        if e:
            d["emitter"] = e
        shapes["s%05d" % n] = d
        n += 1
        continue
    if "file" not in shp or not shp["file"].endswith(".obj") or set(shp) - {"file", "material"}:
        sys.exit("only {\"file\": \"X.obj\"[, \"material\": M]} and analytic sphere shapes are converted")
    groups, mats = read_obj(os.path.join(base, shp["file"]))
    for name, tris in groups.items():
        p = os.path.join(tmp, "m%05d.obj" % n)
        with open(p, "w") as f:
            for t in tris:
                for q in t:
                    f.write("v %.7g %.7g %.7g\n" % q)
            for i in range(len(tris)):
                f.write("f %d %d %d\n" % (3 * i + 1, 3 * i + 2, 3 * i + 3))
        if "material" in shp:
            b, e = json_bsdf(shp["material"])
        else:
            m = mats[name]
            b = {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["Kd"]}}
            e = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}} if any(c > 0 for c in m["Ke"]) else None
        d = {"type": "obj", "filename": p, "face_normals": True, "bsdf": b}
        if e:
            d["emitter"] = e
        shapes["s%05d" % n] = d
        n += 1

scene = {"type": "scene",
         "integrator": {"type": "direct"} if a.integrator == "direct" else
                       {"type": "direct", "emitter_samples": 0, "bsdf_samples": 1} if a.integrator == "direct-bsdf" else
                       {"type": "path", "max_depth": -1, "rr_depth": 5},
         "sensor": {"type": "perspective", "fov_axis": "y", "fov": cam.get("fov", 40),
                    "to_world": mi.ScalarTransform4f().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"]),
                    "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                    "sampler": {"type": "independent", "sample_count": a.spp}}}
scene.update(shapes)
s = mi.load_dict(scene)
acc = None
for k in range(a.passes):
    img = mi.render(s, seed=a.seed + k, spp=a.spp)
    acc = img if acc is None else acc + img
    print("pass %d/%d" % (k + 1, a.passes), flush=True)
mi.Bitmap(acc / a.passes).write(a.out)
print("wrote %s (%dx%d, %d spp x %d, mitsuba %s %s)" % (a.out, w, h, a.spp, a.passes, mi.__version__, a.integrator))
