# mitsuba-materials.py — the material scenes and their independent references:
# writes each scene once as valo JSON + OBJ meshes (tests/data/materials/) and renders the
# same meshes with Mitsuba 3 into <name>-mitsuba.exr beside them (optional tooling: the
# files it makes are committed; valo builds, renders and tests without Python).
#
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 scripts/mitsuba-materials.py [--spp 16384] [--only gold-rough]
#   ... --variant llvm_ad_spectral --only glass-rough   (writes NAME-mitsuba-spectral.exr)
#   ... --max-depth 2 --only gold-rough   (valo's max_depth 2 = Mitsuba's 3: NAME-mitsuba-depth2.exr)
#
# Conventions matched (docs/testing.md, "Materials and textures"):
#  - geometry: the OBJ files written here, read by both (valo through Assimp, Mitsuba's own
#    OBJ loader); the sphere is a 64 x 32 UV sphere with per-vertex normals, interpolated
#    by both; floor and lamp are single quads (flat);
#  - lamp: an area emitter of radiance Le on the counter-clockwise (front) side only;
#  - GGX: valo's roughness r is Mitsuba's alpha = r^2, visible-normal sampling; Mitsuba's
#    Smith G is separable, valo's height-correlated (a difference far below the test's
#    tolerance at alpha 0.09);
#  - conductors: the same RGB eta and k in both (not Mitsuba's spectral presets); gold-spectral
#    gives both the same eta, k per wavelength (GOLD_SPECTRUM), linear between points;
#  - glass: interior ior 1.5, exterior 1.0;
#  - environment: valo's map has its centre looking down -z and u growing towards +x;
#    Mitsuba's envmap has u = 0 at -z, so its to_world is a turn of 180 + rotation degrees
#    about +y where valo's is `rotation`; both look the map up bilinearly;
#  - camera: pinhole, vertical fov, box pixel filter one pixel wide (ortho-gaussian: both
#    renderers' Gaussian filter, standard deviation 0.5 px cut at 2 px); path tracing with no
#    depth limit (Russian roulette from depth 5); an independent sampler;
#  - media (MEDIUM_SCENES): Mitsuba's volpath and homogeneous medium (sigma_t = sigma_a +
#    sigma_s as an RGB in [0, 1] times its largest value as `scale`, albedo = sigma_s /
#    sigma_t, phase hg); the boundary is Mitsuba's null BSDF or its dielectric. The
#    committed absorbing-glass reference is rendered at 65536 spp (--spp 65536 --only
#    absorbing-glass): light reaches the glass's inside only by BSDF sampling, so 16384
#    spp left fireflies of 4-6 % in its 16x16 blocks;
#  - orthographic camera (CAMERA_SCENES): Mitsuba's "orthographic" sees x in [-1, 1] and
#    y in [-1/aspect, 1/aspect] of its camera space, so valo's view height H is a to_world
#    scale of H * aspect / 2 on x and y (measured: a unit square on films of aspect 2 and
#    1/2 covers 1/2 and 1/4 of the film's width and height).
import argparse, json, math, os, struct, zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "materials")
GOLD = {"eta": [0.143, 0.374, 1.442], "k": [3.983, 2.385, 1.603]}
COPPER = {"eta": [0.200, 0.924, 1.102], "k": [3.912, 2.452, 2.142]}
# A gold-like complex index per wavelength (rounded values in the shape of published gold
# measurements; not a measured table): valo's JSON "spectrum", Mitsuba's irregular spectra.
# For --spectral renders against Mitsuba's spectral variant (--variant llvm_ad_spectral).
GOLD_NM = [360, 400, 450, 500, 550, 600, 650, 700, 750, 830]
GOLD_SPECTRUM = {"wavelengths": GOLD_NM, "eta": [1.70, 1.66, 1.50, 0.97, 0.43, 0.25, 0.17, 0.16, 0.16, 0.19],
                 "k": [1.90, 1.96, 1.88, 1.87, 2.45, 3.00, 3.55, 4.00, 4.45, 5.10]}
SCENES = {
    "gold-rough": {"type": "conductor", **GOLD, "roughness": 0.3},
    "gold-spectral": {"type": "conductor", "spectrum": GOLD_SPECTRUM, "roughness": 0.3},
    "copper-smooth": {"type": "conductor", **COPPER},
    "glass-rough": {"type": "dielectric", "ior": 1.5, "roughness": 0.3},
    "glass-smooth": {"type": "dielectric", "ior": 1.5},
    "thin-glass": {"type": "thindielectric", "ior": 1.5},
    # glTF metallic-roughness, fully metallic: valo's metal lobe is Schlick's Fresnel on the
    # base colour with GGX, as Mitsuba's principled BSDF at metallic 1 (its other lobes off).
    # Not the dielectric part: principled's specular layer (metallic 0, black base) uses the
    # exact dielectric Fresnel term where glTF prescribes Schlick's (0.089 against 0.070 at
    # 60 degrees; 25 % brighter on the sphere), and its diffuse is Disney's.
    "pbr-metal": {"type": "pbr", "base_color": [0.95, 0.64, 0.54], "metallic": 1, "roughness": 0.4},
}
# Lit only by ../shared/scenes/envmaps/ENV_SOURCE at its full 1024 x 512 (not committed:
# the test needs ../shared), turned ENV_ROTATION degrees: a diffuse and a rough gold sphere.
# Full resolution because the two renderers place texels differently: valo's texel i is
# centred at u = (i + 0.5) / W, Mitsuba's at i / W (it appends a copy of the first column
# and spreads W + 1 columns over [0, 1]; rows likewise over H - 1): half a texel, 0.18
# degrees at 1024 columns, far below a pixel of these renders (0.6 degrees).
ENV_SOURCE, ENV_ROTATION = "royal_esplanade_1k.hdr", 60.0
ENV_SCENES = {"env-spheres": [{"type": "diffuse", "reflectance": 0.8}, {"type": "conductor", **GOLD, "roughness": 0.3}]}
# Lit by one punctual light each, in its units: a spot of 8 W/sr with a hard 25-degree cone
# (valo's smoothstep edge and Mitsuba's linear one both made 0.01 degrees wide) and a sun of
# 3 W/m^2; a diffuse sphere (0.7) on the floor.
LIGHT_SCENES = {
    "spot-light": [{"type": "spot", "position": [1.2, 2.6, 0.8], "look_at": [0, 0.3, 0], "intensity": [8, 8, 8], "cone_angle": 25,
                    "cone_delta_angle": 0.01}],
    "sun-light": [{"type": "directional", "direction": [-0.4, -1, -0.5], "irradiance": [3, 3, 3]}],
}
# The diffuse sphere (0.7) on the floor under the lamp, seen by an orthographic camera of
# view height 1.6 from the usual place, on a film of aspect 1.6; and the same through the
# Gaussian pixel filter (valo's film.filter, Mitsuba's rfilter, both at their defaults).
ORTHO = {"type": "orthographic", "height": 1.6, "position": [0, 1.1, 3.6], "look_at": [0, 0.55, 0], "up": [0, 1, 0]}
CAMERA_SCENES = {"ortho-camera": {"camera": ORTHO, "filter": "box"}, "ortho-gaussian": {"camera": ORTHO, "filter": "gaussian"}}
ORTHO_W, ORTHO_H = 128, 80
# The ball filled with a homogeneous medium (MEDIUM_SCENES), on the floor under the lamp:
# behind a null boundary (valo's "null" material, Mitsuba's null BSDF), a chromatic
# scattering medium with a forward Henyey-Greenstein lobe; inside rough glass, a purely
# absorbing one (Beer-Lambert colour). valo's sigma_a, sigma_s are Mitsuba's sigma_t =
# sigma_a + sigma_s and albedo = sigma_s / sigma_t; Mitsuba's volpath integrator, with no
# depth limit (Russian roulette from depth 5).
MEDIUM_SCENES = {
    "smoke-ball": {"boundary": {"type": "null"}, "sigma_a": [0.3, 0.3, 0.3], "sigma_s": [3.0, 1.8, 0.9], "g": 0.5},
    "absorbing-glass": {"boundary": {"type": "dielectric", "ior": 1.5, "roughness": 0.3}, "sigma_a": [0.3, 1.2, 3.0], "sigma_s": [0, 0, 0], "g": 0},
}
# A cloud: the ball's null boundary around a grid medium (valo's "grid" medium, Mitsuba's
# heterogeneous medium with a gridvolume) whose density, a few Gaussian blobs on 32^3
# texels (GRID_FILE, written here), fills the ball's bounding box; grey extinction of
# GRID_SCALE times the density with a chromatic albedo (valo: sigma_s = albedo x scale,
# sigma_a = (1 - albedo) x scale). Both look the grid up trilinearly with texel centres
# at (i + 0.5) / 32 of the box, clamped at its edge texels.
GRID_SCENES = {"cloud-grid": {"albedo": [0.95, 0.8, 0.6], "scale": 12.0, "g": 0.3}}
GRID_FILE, GRID_N = "cloud.vol", 32
GRID_LO, GRID_HI = [-0.55, 0.0, -0.55], [0.55, 1.1, 0.55]
# A quad textured with an sRGB PNG under a uniform white environment (radiance = albedo):
# quadrants red, green, blue, yellow from the image's top-left, so a flipped u or v shows.
TEXTURE_SCENES = {"textured-quad": "quad-texture.png"}
QUADRANTS = [(200, 40, 40), (40, 200, 40), (40, 40, 200), (220, 220, 40)]  # TL, TR, BL, BR
WIDTH, HEIGHT = 96, 96
SHARED = os.path.join(ROOT, "..", "shared")
INTEGRATOR = {"type": "path", "max_depth": -1, "rr_depth": 5}
SUFFIX = ""
CAMERA = {"position": [0, 1.1, 3.6], "look_at": [0, 0.55, 0], "up": [0, 1, 0], "fov": 32}
LE = 12.0


def write_meshes():
    os.makedirs(OUT, exist_ok=True)
    n, rings = 64, 32
    with open(os.path.join(OUT, "sphere.obj"), "w") as f:
        f.write("# unit UV sphere, %d x %d, per-vertex normals (scripts/mitsuba-materials.py)\n" % (n, rings))
        for j in range(rings + 1):
            for i in range(n + 1):
                th, ph = math.pi * j / rings, 2 * math.pi * i / n
                x, y, z = math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)
                f.write("v %.6f %.6f %.6f\nvn %.6f %.6f %.6f\n" % (x, y, z, x, y, z))
        for j in range(rings):
            for i in range(n):
                a = j * (n + 1) + i + 1
                b, c = a + 1, a + n + 1
                d = c + 1
                if j > 0:
                    f.write("f %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c))
                if j < rings - 1:
                    f.write("f %d//%d %d//%d %d//%d\n" % (b, b, d, d, c, c))
    with open(os.path.join(OUT, "floor.obj"), "w") as f:
        f.write("v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf 1 4 3 2\n")  # counter-clockwise seen from +y
    with open(os.path.join(OUT, "lamp.obj"), "w") as f:
        f.write("v -0.5 2.5 -0.5\nv 0.5 2.5 -0.5\nv 0.5 2.5 0.5\nv -0.5 2.5 0.5\nf 1 2 3 4\n")  # faces -y


def valo_json(name, mat):
    return {"camera": CAMERA, "film": {"width": WIDTH, "height": HEIGHT}, "render": {"spp": 64},
            "materials": {"ball": mat, "floor": {"type": "diffuse", "reflectance": 0.5},
                          "lamp": {"type": "diffuse", "reflectance": 0, "emission": LE}},
            "shapes": [{"file": "sphere.obj", "material": "ball", "transform": {"scale": 0.55, "translate": [0, 0.55, 0]}},
                       {"file": "floor.obj", "material": "floor"}, {"file": "lamp.obj", "material": "lamp"}]}


def light_json(name, lights):
    j = valo_json(name, {"type": "diffuse", "reflectance": 0.7})
    j["materials"].pop("lamp")
    j["shapes"].pop()
    j["lights"] = lights
    return j


def mitsuba_light(mi, l):
    T = mi.ScalarTransform4f
    if l["type"] == "spot":
        up = [0, 0, 1] if abs(l["position"][0] - l["look_at"][0]) + abs(l["position"][2] - l["look_at"][2]) < 1e-6 else [0, 1, 0]
        return {"type": "spot", "to_world": T().look_at(origin=l["position"], target=l["look_at"], up=up),
                "intensity": {"type": "rgb", "value": l["intensity"]}, "cutoff_angle": l["cone_angle"],
                "beam_width": l["cone_angle"] - l["cone_delta_angle"]}
    return {"type": "directional", "direction": l["direction"], "irradiance": {"type": "rgb", "value": l["irradiance"]}}


def write_texture(path, n=16):
    rows = b""
    for y in range(n):
        rows += b"\x00"
        for x in range(n):
            q = (2 if y >= n // 2 else 0) + (1 if x >= n // 2 else 0)
            r, g, b = QUADRANTS[q]
            shade = 0.85 + 0.15 * ((x + y) % 2)  # a texel checker inside each quadrant
            rows += bytes((int(r * shade), int(g * shade), int(b * shade)))
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)
    with open(os.path.join(OUT, "quad-uv.obj"), "w") as f:
        f.write("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")


def texture_json(name, tex):
    return {"camera": {"position": [0, 0, 3.2], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
            "film": {"width": 96, "height": 96}, "render": {"spp": 16},
            "materials": {"tex": {"type": "diffuse", "reflectance": tex}},
            "shapes": [{"file": "quad-uv.obj", "material": "tex"}],
            "environment": {"type": "constant", "radiance": 1}}


def camera_json(name, view):
    j = valo_json(name, {"type": "diffuse", "reflectance": 0.7})
    j["camera"] = view["camera"]
    j["film"] = {"width": ORTHO_W, "height": ORTHO_H}
    if view["filter"] != "box":
        j["film"]["filter"] = view["filter"]
    return j


def medium_json(name, m):
    j = valo_json(name, m["boundary"])
    j["media"] = {"inside": {"type": "homogeneous", "sigma_a": m["sigma_a"], "sigma_s": m["sigma_s"], "g": m["g"]}}
    j["shapes"][0]["interior"] = "inside"
    return j


def mitsuba_medium(m):
    st = [a + b for a, b in zip(m["sigma_a"], m["sigma_s"])]
    top = max(st)  # Mitsuba's RGB values lie in [0, 1]: the largest becomes its scale
    return {"type": "homogeneous", "sigma_t": {"type": "rgb", "value": [t / top for t in st]}, "scale": top,
            "albedo": {"type": "rgb", "value": [b / t if t > 0 else 0 for b, t in zip(m["sigma_s"], st)]},
            "phase": {"type": "hg", "g": m["g"]}}


def cloud_density(x, y, z):
    blobs = [((0.0, 0.55, 0.0), 0.09, 1.0), ((0.22, 0.7, 0.1), 0.03, 0.8), ((-0.2, 0.4, -0.1), 0.04, 0.7)]
    return sum(a * math.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / w) for c, w, a in blobs)


def write_grid():
    vals = []
    for k in range(GRID_N):
        for j in range(GRID_N):
            for i in range(GRID_N):
                p = [GRID_LO[a] + (GRID_HI[a] - GRID_LO[a]) * (t + 0.5) / GRID_N for a, t in enumerate((i, j, k))]
                vals.append(cloud_density(*p))
    with open(os.path.join(OUT, GRID_FILE), "wb") as f:
        f.write(b"VOL" + bytes([3]) + struct.pack("<5i", 1, GRID_N, GRID_N, GRID_N, 1) + struct.pack("<6f", *GRID_LO, *GRID_HI))
        f.write(struct.pack("<%df" % len(vals), *vals))


def grid_json(name, m):
    j = valo_json(name, {"type": "null"})
    sc, al = m["scale"], m["albedo"]
    j["media"] = {"cloud": {"type": "grid", "file": GRID_FILE, "sigma_s": [a * sc for a in al], "sigma_a": [(1 - a) * sc for a in al],
                            "g": m["g"], "bounds_min": GRID_LO, "bounds_max": GRID_HI}}
    j["shapes"][0]["interior"] = "cloud"
    return j


def env_json(name, mats):
    return {"camera": {"position": [0, 0, 4.2], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
            "film": {"width": 128, "height": 64}, "render": {"spp": 64},
            "materials": {"a": mats[0], "b": mats[1]},
            "shapes": [{"file": "sphere.obj", "material": "a", "transform": {"scale": 0.7, "translate": [-0.8, 0, 0]}},
                       {"file": "sphere.obj", "material": "b", "transform": {"scale": 0.7, "translate": [0.8, 0, 0]}}],
            "environment": {"type": "map", "file": "../../../../shared/scenes/envmaps/" + ENV_SOURCE, "rotation": ENV_ROTATION}}


def mitsuba_bsdf(mat):
    r = mat.get("roughness", 0)
    if mat["type"] == "null":
        return {"type": "null"}
    if mat["type"] == "thindielectric":
        return {"type": "thindielectric", "int_ior": mat["ior"], "ext_ior": 1.0}
    if mat["type"] == "conductor":
        if "spectrum" in mat:
            sp = mat["spectrum"]
            def irregular(v):
                return {"type": "irregular", "wavelengths": ", ".join(map(str, sp["wavelengths"])), "values": ", ".join(map(str, v))}
            d = {"eta": irregular(sp["eta"]), "k": irregular(sp["k"])}
        else:
            d = {"eta": {"type": "rgb", "value": mat["eta"]}, "k": {"type": "rgb", "value": mat["k"]}}
        if r > 0:
            return {"type": "roughconductor", "distribution": "ggx", "alpha": r * r, "sample_visible": True, **d}
        return {"type": "conductor", **d}
    if mat["type"] == "pbr":
        return {"type": "principled", "base_color": {"type": "rgb", "value": mat["base_color"]}, "metallic": mat["metallic"],
                "roughness": mat["roughness"], "specular": 0.5, "spec_tint": 0.0, "sheen": 0.0, "clearcoat": 0.0}
    if mat["type"] == "diffuse":
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [mat["reflectance"]] * 3}}
    if r > 0:
        return {"type": "roughdielectric", "distribution": "ggx", "alpha": r * r, "sample_visible": True, "int_ior": 1.5, "ext_ior": 1.0}
    return {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}


def sensor(mi, cam, w, h, spp):
    T = mi.ScalarTransform4f
    to_world = T().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"])
    film = {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}, "pixel_format": "rgb"}
    sampler = {"type": "independent", "sample_count": spp}
    if cam.get("type") == "orthographic":
        s = cam["height"] * w / h / 2
        return {"type": "orthographic", "to_world": to_world @ T().scale([s, s, 1]), "film": film, "sampler": sampler}
    return {"type": "perspective", "fov_axis": "y", "fov": cam["fov"], "to_world": to_world, "film": film, "sampler": sampler}


def scene_dict(mi, name, mat, spp):
    T = mi.ScalarTransform4f
    if name in ENV_SCENES:
        j = env_json(name, mat)
        d = {"type": "scene", "integrator": INTEGRATOR,
             "sensor": sensor(mi, j["camera"], j["film"]["width"], j["film"]["height"], spp),
             "env": {"type": "envmap", "filename": os.path.join(SHARED, "scenes", "envmaps", ENV_SOURCE),
                     "to_world": T().rotate([0, 1, 0], 180 + ENV_ROTATION)}}
        for k, shp in enumerate(j["shapes"]):
            tr = shp["transform"]
            d["s%d" % k] = {"type": "obj", "filename": os.path.join(OUT, "sphere.obj"), "face_normals": False,
                            "to_world": T().translate(tr["translate"]) @ T().scale(tr["scale"]), "bsdf": mitsuba_bsdf(mat[k])}
        return d, j["film"]["width"], j["film"]["height"]
    if name in TEXTURE_SCENES:
        j = texture_json(name, mat)
        d = {"type": "scene", "integrator": INTEGRATOR,
             "sensor": sensor(mi, j["camera"], 96, 96, spp),
             "env": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
             "quad": {"type": "obj", "filename": os.path.join(OUT, "quad-uv.obj"), "face_normals": True,
                      "bsdf": {"type": "diffuse", "reflectance": {"type": "bitmap", "filename": os.path.join(OUT, mat),
                                                                  "filter_type": "bilinear"}}}}
        return d, 96, 96
    if name in CAMERA_SCENES:
        d, w, h = scene_dict(mi, "gold-rough", {"type": "diffuse", "reflectance": 0.7}, spp)
        d["sensor"] = sensor(mi, mat["camera"], ORTHO_W, ORTHO_H, spp)
        d["sensor"]["film"]["rfilter"] = {"type": mat["filter"]}
        return d, ORTHO_W, ORTHO_H
    if name in GRID_SCENES:
        d, w, h = scene_dict(mi, "gold-rough", {"type": "null"}, spp)
        d["integrator"] = dict(INTEGRATOR, type="volpath")
        ext = [GRID_HI[a] - GRID_LO[a] for a in range(3)]
        d["ball"]["interior"] = {"type": "heterogeneous", "albedo": {"type": "rgb", "value": mat["albedo"]}, "scale": mat["scale"],
                                 "sigma_t": {"type": "gridvolume", "filename": os.path.join(OUT, GRID_FILE),
                                             "to_world": T().translate(GRID_LO) @ T().scale(ext)},
                                 "phase": {"type": "hg", "g": mat["g"]}}
        return d, w, h
    if name in MEDIUM_SCENES:
        d, w, h = scene_dict(mi, "gold-rough", mat["boundary"], spp)
        d["integrator"] = dict(INTEGRATOR, type="volpath")
        d["ball"]["interior"] = mitsuba_medium(mat)
        return d, w, h
    if name in LIGHT_SCENES:
        d, w, h = scene_dict(mi, "gold-rough", {"type": "diffuse", "reflectance": 0.7}, spp)
        d.pop("lamp")
        for k, l in enumerate(LIGHT_SCENES[name]):
            d["light%d" % k] = mitsuba_light(mi, l)
        return d, w, h
    return {"type": "scene",
             "integrator": INTEGRATOR,
             "sensor": sensor(mi, CAMERA, WIDTH, HEIGHT, spp),
             "ball": {"type": "obj", "filename": os.path.join(OUT, "sphere.obj"), "face_normals": False,
                      "to_world": T().translate([0, 0.55, 0]) @ T().scale(0.55), "bsdf": mitsuba_bsdf(mat)},
             "floor": {"type": "obj", "filename": os.path.join(OUT, "floor.obj"), "face_normals": True,
                       "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}}},
             "lamp": {"type": "obj", "filename": os.path.join(OUT, "lamp.obj"), "face_normals": True,
                      "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}},
                      "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [LE, LE, LE]}}}}, WIDTH, HEIGHT


# Mitsuba's XML of a scene dict (write_xml): the element of each plugin type.
XML_TAGS = {"bsdf": "diffuse dielectric roughdielectric thindielectric conductor roughconductor principled null twosided plastic roughplastic",
            "shape": "obj ply sphere rectangle cube disk", "emitter": "area point spot directional envmap constant",
            "sensor": "perspective orthographic thinlens", "film": "hdrfilm", "rfilter": "box tent gaussian",
            "sampler": "independent", "integrator": "path volpath", "medium": "homogeneous heterogeneous", "phase": "hg isotropic",
            "volume": "gridvolume", "texture": "bitmap"}


def write_xml(mi, d, path):
    """Writes scene dict d as a Mitsuba 3 XML file (file names relative to it): the file
    valo's .xml reader is tested on, with the same meaning as the dict Mitsuba rendered
    (--check-xml renders it in Mitsuba and compares)."""
    import numpy as np
    tag = {t: k for k, ts in XML_TAGS.items() for t in ts.split()}
    out = ['<scene version="3.0.0">']

    def num(x):
        return repr(float(x)) if isinstance(x, float) else str(x)

    def emit(name, v, ind, top=False):
        pad = "\t" * ind
        attr = (' id="%s"' if top else ' name="%s"') % name if name else ""
        if isinstance(v, mi.ScalarTransform4f):
            m = np.array(v.matrix).reshape(4, 4)
            out.append('%s<transform%s><matrix value="%s"/></transform>' % (pad, attr, " ".join("%.9g" % x for x in m.flatten())))
        elif isinstance(v, dict) and v["type"] in ("rgb", "uniform", "irregular"):
            if v["type"] == "rgb":
                out.append('%s<rgb%s value="%s"/>' % (pad, attr, ", ".join(num(x) for x in v["value"])))
            elif v["type"] == "uniform":
                out.append('%s<spectrum%s value="%s"/>' % (pad, attr, num(v["value"])))
            else:
                pairs = zip(v["wavelengths"].split(", "), v["values"].split(", "))
                out.append('%s<spectrum%s value="%s"/>' % (pad, attr, ", ".join("%s:%s" % p for p in pairs)))
        elif isinstance(v, dict):
            out.append('%s<%s type="%s"%s>' % (pad, tag[v["type"]], v["type"], attr))
            for k, x in v.items():
                if k != "type":
                    emit(k, x, ind + 1)
            out.append("%s</%s>" % (pad, tag[v["type"]]))
        elif isinstance(v, bool):
            out.append('%s<boolean%s value="%s"/>' % (pad, attr, "true" if v else "false"))
        elif isinstance(v, int):
            out.append('%s<integer%s value="%d"/>' % (pad, attr, v))
        elif isinstance(v, float):
            out.append('%s<float%s value="%s"/>' % (pad, attr, num(v)))
        elif isinstance(v, str):
            s = os.path.relpath(v, os.path.dirname(path)) if name == "filename" else v
            out.append('%s<string%s value="%s"/>' % (pad, attr, s))
        elif isinstance(v, (list, tuple)) and len(v) == 3:
            out.append('%s<%s%s x="%s" y="%s" z="%s"/>' % (pad, "vector" if name == "direction" else "point", attr, *map(num, v)))
        else:
            raise ValueError("no XML for %s = %r" % (name, v))

    for k, v in d.items():
        if k != "type":
            emit(k, v, 1, top=True)
    out.append("</scene>")
    with open(path, "w") as f:
        f.write("<!-- written by scripts/mitsuba-materials.py from the scene Mitsuba rendered into the EXR beside it -->\n")
        f.write("\n".join(out) + "\n")


def spectral_white(mi):
    """Mitsuba's linear sRGB of the equal-energy spectrum of radiance 1: a constant
    environment seen directly, 16 x 16 pixels at 4096 spp (wavelength noise < 0.05 %)."""
    s = mi.load_dict({"type": "scene", "integrator": {"type": "path", "max_depth": 1},
                      "sensor": sensor(mi, {"position": [0, 0, 0], "look_at": [0, 0, 1], "up": [0, 1, 0], "fov": 30}, 16, 16, 4096),
                      "env": {"type": "constant", "radiance": {"type": "uniform", "value": 1.0}}})
    import numpy as np
    return np.array(mi.render(s, seed=1)).reshape(-1, 3).mean(axis=0)


def render(mi, name, mat, spp, seed, xml_only=False):
    scene, w, h = scene_dict(mi, name, mat, spp)
    if "spectral" not in mi.variant() and SUFFIX == "" and name != "gold-spectral":
        write_xml(mi, scene, os.path.join(OUT, name + ".xml"))
    if xml_only:
        return
    white = None
    if "spectral" in mi.variant():
        # valo's spectral white is the equal-energy spectrum, balanced per channel on the film
        # (src/core/spectrum.h); Mitsuba's RGB white is D65. On grey scenes the two agree;
        # on coloured ones (gold) they differ by up to 3 %. So here every emitter emits the
        # equal-energy spectrum and the image is divided by its sRGB, as valo's film does.
        white = spectral_white(mi)
        for v in scene.values():
            if isinstance(v, dict) and "emitter" in v:
                rad = v["emitter"]["radiance"]["value"]
                v["emitter"]["radiance"] = {"type": "uniform", "value": rad[0]}
    s = mi.load_dict(scene)
    img = None
    passes = max(1, spp // 4096)
    for k in range(passes):
        part = mi.render(s, seed=seed + k, spp=min(spp, 4096))
        img = part if img is None else img + part
    if white is not None:
        import numpy as np
        print("spectral white (equal-energy spectrum in Mitsuba's sRGB): %.5f %.5f %.5f" % tuple(white), flush=True)
        img = mi.TensorXf(np.array(img) / white)
    out = os.path.join(OUT, name + "-mitsuba" + ("-spectral" if "spectral" in mi.variant() else "") + SUFFIX + ".exr")
    mi.Bitmap(img / passes).write(out)
    print("wrote %s (%dx%d, %d spp, mitsuba %s)" % (out, w, h, passes * min(spp, 4096), mi.__version__), flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("--only", default="")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    ap.add_argument("--max-depth", type=int, default=-1, help="valo's max_depth D (bounces); Mitsuba's max_depth is D + 1")
    ap.add_argument("--xml-only", action="store_true", help="write the scenes (JSON and Mitsuba XML) without rendering")
    ap.add_argument("--check-xml", type=int, default=0, metavar="SPP",
                    help="render each written XML file in Mitsuba at SPP and compare its mean with the committed EXR")
    a = ap.parse_args()
    global SHARED, INTEGRATOR, SUFFIX
    SHARED = a.shared
    if a.max_depth >= 0:
        INTEGRATOR = {"type": "path", "max_depth": a.max_depth + 1, "rr_depth": 1000}
        SUFFIX = "-depth%d" % a.max_depth
    write_meshes()
    write_grid()
    for tex in TEXTURE_SCENES.values():
        write_texture(os.path.join(OUT, tex))
    kinds = [(SCENES, valo_json), (ENV_SCENES, env_json), (TEXTURE_SCENES, texture_json), (LIGHT_SCENES, light_json),
             (CAMERA_SCENES, camera_json), (MEDIUM_SCENES, medium_json), (GRID_SCENES, grid_json)]
    for table, to_json in kinds:
        for name, what in table.items():
            with open(os.path.join(OUT, name + ".json"), "w") as f:
                json.dump(to_json(name, what), f, indent=1)
                f.write("\n")
    import mitsuba as mi
    mi.set_variant(a.variant)
    for name, mat in (list(SCENES.items()) + list(ENV_SCENES.items()) + list(LIGHT_SCENES.items()) + list(TEXTURE_SCENES.items()) +
                      list(CAMERA_SCENES.items()) + list(MEDIUM_SCENES.items()) + list(GRID_SCENES.items())):
        if not a.only or a.only == name:
            render(mi, name, mat, a.spp, a.seed, xml_only=a.xml_only or a.check_xml > 0)
            xml = os.path.join(OUT, name + ".xml")
            if a.check_xml > 0 and os.path.exists(xml):
                import numpy as np
                img = np.array(mi.render(mi.load_file(xml), spp=a.check_xml, seed=a.seed + 1000))
                ref = np.array(mi.Bitmap(os.path.join(OUT, name + "-mitsuba.exr")))[..., :3]
                mx, mr = img.reshape(-1, 3).mean(0), ref.reshape(-1, 3).mean(0)
                print("%s: Mitsuba from the XML at %d spp against the EXR: mean %s (%s)" %
                      (name, a.check_xml, " ".join("%+.2f%%" % (100 * (x / r - 1)) for x, r in zip(mx, mr)),
                       " ".join("%.4f" % x for x in mx)), flush=True)


if __name__ == "__main__":
    main()
