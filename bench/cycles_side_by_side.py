# cycles_side_by_side.py — valo against Blender Cycles on the same OBJ scene, back to back
# on one machine: renders with Cycles (CPU, box filter of width 1, no adaptive sampling,
# no denoising, no clamping, glossy filter 0, light threshold 0, 128 bounces of every kind, front-sided
# emitters, the MTL meanings of ../shared/scenes/README.md) and with valo at the given
# sample counts, prints each one's seconds and relMSE against a reference, and the time
# each needs to reach the relMSE of Cycles' largest sample count (valo's interpolated on
# its own error-vs-time curve, log-log). It can also make that reference (--make-ref).
#
# Optional tooling (Python is not needed to build, render or test valo). Runs inside
# Blender's Python, which needs numpy (Debian: apt install blender python3-numpy):
#   blender -b --factory-startup --python bench/cycles_side_by_side.py -- \
#       --obj ../shared/scenes/cornell/CornellBox-Original.obj \
#       --ref ../shared/references/cornell-original.exr --valo build/valo
# Options: --spp 64,256,1024  --res 256  --threads 2  --cam px,py,pz,lx,ly,lz  --fov 40
#          --env FILE.exr [--env-rotation DEG]  --make-ref OUT.exr --ref-spp 4096
#          --texture FILE.png (every material becomes Lambertian with this sRGB texture:
#          for meshes without an MTL, such as Keenan Crane's Spot)
#          --valo-args "..." (extra valo flags)  --label NAME  --seed N (default 12345: not
#          the shared references' seed 7, whose samples a Cycles render would share)
#          --adaptive THRESHOLD: also each renderer's adaptive sampling at every sample
#          count (Cycles: its noise threshold THRESHOLD, at most spp samples; valo:
#          --adaptive, spp on average) and its gain at equal time over its own uniform
#          sampling, (uniform relMSE x time) / (adaptive relMSE x time)
#
# Conventions matched (documented in docs/performance.md):
#  - OBJ axes: valo's (x, y, z) is Blender's (x, -z, y) (the importer's -Z forward, Y up);
#  - camera: pinhole, vertical fov, up +y;
#  - the OBJ read by this script, not Blender's importer: faces fanned from their first
#    vertex as Assimp does, flat shading, exact duplicate triangles dropped (Cycles would
#    shadow one with the other);
#  - --texture: an 8-bit sRGB texture is decoded to linear floats first and given to both
#    (Cycles interpolates 8-bit sRGB texels before decoding, valo after);
#  - Kd Lambertian; Ke emitted radiance from the front side only (strength 1 - Backfacing);
#    illum 5: Kd diffuse + a sharp glossy lobe of colour Ks (no Fresnel); illum 7: sharp
#    glass of index Ni; map_Kd: an sRGB image texture on the diffuse colour;
#  - environment: valo's equirect map (centre of the image towards -z, u towards +x, y up)
#    is Blender's world Environment Texture looked up with the direction turned -90 deg
#    about Blender's z; black world without --env.
import bpy, sys, os, time, math, subprocess, tempfile
import numpy as np
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
opt = {"spp": "64,256,1024", "res": "256", "threads": "2", "cam": "0,1,3.4,0,1,0", "fov": "40", "env": "",
       "env-rotation": "0", "make-ref": "", "ref-spp": "4096", "valo": "build/valo", "valo-args": "", "label": "", "ref": "",
       "obj": "", "seed": "12345", "texture": "", "bounces": "128", "adaptive": ""}
i = 0
while i < len(argv):
    k = argv[i].lstrip("-")
    if k not in opt:
        sys.exit("unknown option --%s" % k)
    opt[k] = argv[i + 1]
    i += 2
if not opt["obj"]:
    sys.exit("--obj is required")
res = int(opt["res"])
threads = int(opt["threads"])
cam = [float(v) for v in opt["cam"].split(",")]
fov = float(opt["fov"])


def to_blender(v):
    return Vector((v[0], -v[2], v[1]))


def read_mtl(path):
    mats, cur = {}, None
    if not os.path.exists(path):
        return mats
    for line in open(path, errors="replace"):
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        if t[0] == "newmtl":
            cur = mats.setdefault(" ".join(t[1:]), {})
        elif cur is not None and len(t) > 1:
            cur[t[0]] = t[1:]
    return mats


def build_material(mat, m, mtl_dir):
    if opt["texture"]:
        m = {"Kd": ["1", "1", "1"], "map_Kd": [os.path.abspath(opt["texture"])]}
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    rgb = lambda key, d: tuple(float(x) for x in (m.get(key, d) + m.get(key, d)[-1:] * 2)[:3]) + (1.0,)
    kd, ks, ke = rgb("Kd", ["0.8"]), rgb("Ks", ["0"]), rgb("Ke", ["0"])
    illum = int(float(m.get("illum", ["1"])[0]))
    diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diff.inputs["Color"].default_value = kd
    if "map_Kd" in m:
        img = nt.nodes.new("ShaderNodeTexImage")
        img.image = bpy.data.images.load(os.path.join(mtl_dir, m["map_Kd"][-1]))
        mix = nt.nodes.new("ShaderNodeMixRGB")
        mix.blend_type = "MULTIPLY"
        mix.inputs["Fac"].default_value = 1
        mix.inputs["Color1"].default_value = kd
        nt.links.new(img.outputs["Color"], mix.inputs["Color2"])
        nt.links.new(mix.outputs["Color"], diff.inputs["Color"])
    shader = diff.outputs[0]
    if illum == 7:
        glass = nt.nodes.new("ShaderNodeBsdfGlass")
        glass.distribution = "SHARP"
        glass.inputs["IOR"].default_value = float(m.get("Ni", ["1.5"])[0])
        glass.inputs["Color"].default_value = (1, 1, 1, 1)
        shader = glass.outputs[0]
    elif illum == 5 and max(ks[:3]) > 0:
        gl = nt.nodes.new("ShaderNodeBsdfGlossy")
        gl.distribution = "SHARP"
        gl.inputs["Color"].default_value = ks
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(diff.outputs[0], add.inputs[0])
        nt.links.new(gl.outputs[0], add.inputs[1])
        shader = add.outputs[0]
    if max(ke[:3]) > 0:
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = ke
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        inv = nt.nodes.new("ShaderNodeMath")
        inv.operation = "SUBTRACT"
        inv.inputs[0].default_value = 1.0
        nt.links.new(geo.outputs["Backfacing"], inv.inputs[1])
        nt.links.new(inv.outputs[0], em.inputs["Strength"])
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(shader, add.inputs[0])
        nt.links.new(em.outputs[0], add.inputs[1])
        shader = add.outputs[0]
    nt.links.new(shader, out.inputs["Surface"])


def load_obj(sc, path, mtl_dir):
    """The OBJ as valo reads it: positions converted to Blender's axes, faces fanned from
    their first vertex (as Assimp triangulates), relative indices, vt kept, flat shading
    (vertex normals are not carried over), one material slot per usemtl name. Blender's
    own importer (3.4) mangles McGuire's relative indices after g lines (stripes on the
    tall box), so it is not used."""
    V, VT, tris, uvs, mats, tri_mat = [], [], [], [], [], []
    mtls, cur = {}, -1
    for line in open(path, errors="replace"):
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            V.append(to_blender([float(x) for x in t[1:4]]))
        elif t[0] == "vt":
            VT.append((float(t[1]), float(t[2]) if len(t) > 2 else 0.0))
        elif t[0] == "mtllib":
            mtls.update(read_mtl(os.path.join(mtl_dir, line.split(None, 1)[1].strip())))
        elif t[0] == "usemtl":
            name = " ".join(t[1:])
            if name not in mats:
                mats.append(name)
            cur = mats.index(name)
        elif t[0] == "f":
            ref = []
            for tok in t[1:]:
                p = tok.split("/")
                vi = int(p[0])
                vi = vi - 1 if vi > 0 else len(V) + vi
                ti = None
                if len(p) > 1 and p[1]:
                    ti = int(p[1])
                    ti = ti - 1 if ti > 0 else len(VT) + ti
                ref.append((vi, ti))
            for k in range(1, len(ref) - 1):
                tri = (ref[0], ref[k], ref[k + 1])
                tris.append(tuple(r[0] for r in tri))
                uvs.append(tuple(VT[r[1]] if r[1] is not None and VT else (0.0, 0.0) for r in tri))
                tri_mat.append(cur)
    # Exact duplicate triangles (McGuire's tall box lists its front face twice: "Bottom
    # Face" reuses the front face's vertices) shadow each other in Cycles, which skips only
    # the primitive a ray leaves; valo's offset origins pass both. Drop them.
    seen, keep = set(), []
    for k, tri in enumerate(tris):
        key = tuple(sorted(tuple(round(c, 7) for c in V[i]) for i in tri))
        if key not in seen:
            seen.add(key)
            keep.append(k)
    tris, uvs, tri_mat = [tris[k] for k in keep], [uvs[k] for k in keep], [tri_mat[k] for k in keep]
    me = bpy.data.meshes.new("obj")
    me.from_pydata(V, [], tris)
    uvl = me.uv_layers.new(name="UVMap")
    for poly, uv in zip(me.polygons, uvs):
        for li, u in zip(poly.loop_indices, uv):
            uvl.data[li].uv = u
    names = mats if mats else ["default"]
    for name in names:
        m = bpy.data.materials.new(name)
        build_material(m, mtls.get(name, {}), mtl_dir)
        me.materials.append(m)
    for poly, mi in zip(me.polygons, tri_mat):
        poly.material_index = max(mi, 0)
        poly.use_smooth = False
    ob = bpy.data.objects.new("obj", me)
    sc.collection.objects.link(ob)


def setup_cycles():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    mtl_dir = os.path.dirname(os.path.abspath(opt["obj"]))
    load_obj(sc, opt["obj"], mtl_dir)
    cd = bpy.data.cameras.new("cam")
    co = bpy.data.objects.new("cam", cd)
    sc.collection.objects.link(co)
    pos, look = to_blender(cam[0:3]), to_blender(cam[3:6])
    co.location = pos
    co.rotation_mode = "QUATERNION"
    co.rotation_quaternion = (look - pos).to_track_quat("-Z", "Y")
    cd.sensor_fit = "VERTICAL"
    cd.angle_y = math.radians(fov)
    sc.camera = co
    world = bpy.data.worlds.new("world")
    sc.world = world
    world.use_nodes = True
    wn = world.node_tree
    bg = wn.nodes["Background"]
    if opt["env"]:
        tex = wn.nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(os.path.abspath(opt["env"]))
        tc = wn.nodes.new("ShaderNodeTexCoord")
        mp = wn.nodes.new("ShaderNodeMapping")
        mp.inputs["Rotation"].default_value = (0, 0, math.radians(-90 - float(opt["env-rotation"])))
        wn.links.new(tc.outputs["Generated"], mp.inputs["Vector"])
        wn.links.new(mp.outputs["Vector"], tex.inputs["Vector"])
        wn.links.new(tex.outputs["Color"], bg.inputs["Color"])
        bg.inputs["Strength"].default_value = 1
    else:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
    r = sc.render
    r.engine = "CYCLES"
    r.resolution_x = r.resolution_y = res
    r.resolution_percentage = 100
    r.threads_mode = "FIXED"
    r.threads = threads
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGB"
    sc.view_settings.view_transform = "Standard"
    c = sc.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = int(opt["bounces"])
    c.sample_clamp_direct = c.sample_clamp_indirect = 0
    c.blur_glossy = 0
    c.caustics_reflective = c.caustics_refractive = True
    c.light_sampling_threshold = 0  # never skip a light sample (the default 0.01 adds noise)
    c.seed = int(opt["seed"])
    return sc


def read_exr(path):
    img = bpy.data.images.load(path)
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]
    bpy.data.images.remove(img)
    return px


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").astype(np.float64)
    return data.reshape(h, w, 3)[::-1]


def relmse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))


def cycles_render(sc, spp, out, adaptive=""):
    sc.cycles.samples = spp
    sc.cycles.use_adaptive_sampling = bool(adaptive)
    if adaptive:
        sc.cycles.adaptive_threshold = float(adaptive)
    sc.render.filepath = out
    t0 = time.time()
    bpy.ops.render.render(write_still=True)
    return time.time() - t0


def valo_render(spp, out, extra=()):
    scene_json = os.path.join(tempfile.gettempdir(), "valo-side-by-side.json")
    with open(scene_json, "w") as f:
        env = ', "environment": {"type": "map", "file": "%s", "rotation": %s}' % (os.path.abspath(opt["env"]), opt["env-rotation"]) if opt["env"] else ""
        if opt["texture"]:
            env += ', "materials": {"tex": {"type": "diffuse", "reflectance": "%s"}}' % os.path.abspath(opt["texture"])
        f.write('{ "camera": {"position": [%g,%g,%g], "look_at": [%g,%g,%g], "up": [0,1,0], "fov": %g},\n'
                '  "film": {"width": %d, "height": %d}, "render": {"seed": %s},\n'
                '  "shapes": [{"file": "%s"%s}]%s }\n' % (*cam, fov, res, res, opt["seed"], os.path.abspath(opt["obj"]),
                                                     ', "material": "tex"' if opt["texture"] else "", env))
    cmd = [opt["valo"], "render", scene_json, "--spp", str(spp), "--threads", str(threads), "-o", out] + opt["valo-args"].split() + list(extra)
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode:
        sys.exit("valo failed: " + p.stderr)
    for line in p.stderr.splitlines():
        if "summary" in line:
            return float(line.split("render ")[1].split(" s")[0])
    sys.exit("no summary from valo")


def linear_texture(path):
    """An 8-bit sRGB texture decoded to a linear float EXR (in a temporary folder), used by
    both renderers: Cycles interpolates 8-bit sRGB texels before decoding them, valo (like
    pbrt-v4 and Mitsuba 3) decodes each texel first; on Spot that alone left a relMSE floor
    of 1.4e-4 between them (2.6e-5 with the linear texture, which is both renders' noise)."""
    img = bpy.data.images.load(os.path.abspath(path))
    if img.is_float:
        return os.path.abspath(path)
    w, h = img.size
    a = np.array(img.pixels[:]).reshape(h, w, 4)[:, :, :3]
    lin = np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)
    out = bpy.data.images.new("linear-texture", w, h, float_buffer=True)
    out.pixels[:] = np.concatenate([lin, np.ones((h, w, 1))], axis=2).ravel()
    dst = os.path.join(tempfile.mkdtemp(prefix="side-by-side-tex-"), "texture.exr")
    out.filepath_raw = dst
    out.file_format = "OPEN_EXR"
    out.save()
    return dst


if opt["texture"]:
    opt["texture"] = linear_texture(opt["texture"])
sc = setup_cycles()
tmp = tempfile.mkdtemp(prefix="side-by-side-")
if opt["make-ref"]:
    t = cycles_render(sc, int(opt["ref-spp"]), os.path.abspath(opt["make-ref"]))
    print("reference: %s, %s spp, %.1f s" % (opt["make-ref"], opt["ref-spp"], t))
    sys.exit(0)
ref = read_exr(os.path.abspath(opt["ref"]))
spps = [int(v) for v in opt["spp"].split(",")]
rows = []
adaptive_rows = []
for spp in spps:
    tc = cycles_render(sc, spp, os.path.join(tmp, "cycles.exr"))
    ec = relmse(read_exr(os.path.join(tmp, "cycles.exr")), ref)
    tv = valo_render(spp, os.path.join(tmp, "valo.pfm"))
    ev = relmse(read_pfm(os.path.join(tmp, "valo.pfm")), ref)
    rows.append((spp, tc, ec, tv, ev))
    print("spp %d: Cycles %.2f s relMSE %.6f | valo %.2f s relMSE %.6f" % (spp, tc, ec, tv, ev), flush=True)
    if opt["adaptive"]:
        tca = cycles_render(sc, spp, os.path.join(tmp, "cycles-a.exr"), opt["adaptive"])
        eca = relmse(read_exr(os.path.join(tmp, "cycles-a.exr")), ref)
        tva = valo_render(spp, os.path.join(tmp, "valo-a.pfm"), ["--adaptive"])
        eva = relmse(read_pfm(os.path.join(tmp, "valo-a.pfm")), ref)
        adaptive_rows.append((spp, tca, eca, ec * tc / (eca * tca), tva, eva, ev * tv / (eva * tva)))
        print("spp %d adaptive: Cycles (threshold %s) %.2f s relMSE %.6f, gain %.2f | valo %.2f s relMSE %.6f, gain %.2f"
              % (spp, opt["adaptive"], tca, eca, adaptive_rows[-1][3], tva, eva, adaptive_rows[-1][6]), flush=True)


def time_to(errs, times, target):
    """Time at which the log-log line through the (time, error) points reaches target."""
    lt, le = np.log(times), np.log(errs)
    slope, icpt = np.polyfit(lt, le, 1)
    return float(np.exp((np.log(target) - icpt) / slope)), slope


target = rows[-1][2]
tv_needed, slope_v = time_to([r[4] for r in rows], [r[3] for r in rows], target)
tc_needed = rows[-1][1]
label = opt["label"] or os.path.basename(opt["obj"])
print("\n### %s, %dx%d, %d threads (%s)\n" % (label, res, res, threads, time.strftime("%Y-%m-%d")))
print("| spp | Cycles s | Cycles relMSE | valo s | valo relMSE |\n|---|---|---|---|---|")
for spp, tc, ec, tv, ev in rows:
    print("| %d | %.2f | %.6f | %.2f | %.6f |" % (spp, tc, ec, tv, ev))
print("\nCycles' %d-spp relMSE %.6f: Cycles %.1f s; valo reaches it in %.1f s (log-log fit, slope %.2f): "
      "**%.2fx Cycles' time**" % (spps[-1], target, tc_needed, tv_needed, slope_v, tv_needed / tc_needed))
for spp, tc, ec, tv, ev in rows:
    t, _ = time_to([r[4] for r in rows], [r[3] for r in rows], ec)
    print("At %d spp: valo reaches Cycles' relMSE %.6f in %.2fx Cycles' time" % (spp, ec, t / tc))
if adaptive_rows:
    print("\nAdaptive sampling, gain at equal time over the same renderer's uniform sampling, (relMSE x s) uniform / adaptive:\n")
    print("| max/avg spp | Cycles adaptive s | relMSE | **gain** | valo --adaptive s | relMSE | **gain** |\n|---|---|---|---|---|---|---|")
    for spp, tca, eca, gc, tva, eva, gv in adaptive_rows:
        print("| %d | %.2f | %.6f | **%.2f** | %.2f | %.6f | **%.2f** |" % (spp, tca, eca, gc, tva, eva, gv))
