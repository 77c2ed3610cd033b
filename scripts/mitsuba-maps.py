# mitsuba-maps.py — the Mitsuba scenes of normal and bump maps that test_mitsuba reads
# (maps_minimal_xml, maps_xml), and Mitsuba 3's renders of them:
#   tests/data/mitsuba-maps/    the maps (PNG), a quad as OBJ and PLY, a torus as PLY,
#                               CASE-SHAPE.xml (one quad under a directional light, one
#                               convention each) and maps.xml (bump and normal maps on a
#                               floor, a rough gold sphere, a rectangle and a PLY torus);
#                               NAME-mitsuba.exr, Mitsuba's render of each (half float).
# The cases, each on Mitsuba's rectangle, a PLY quad and an OBJ quad (the same place, UVs
# and normals):
#   tilt-v       a normal map tilting the normal 31 degrees along +v, lit from +v (the frame's
#                t = n x s, whatever the UVs' handedness)
#   tilt-away    a normal map tilted 31 degrees along +u, seen 17 degrees above the surface
#                from -u (the mapped normal faces away from the viewer: Mitsuba mirrors it)
#   bump-u       a bump ramp along u, lit from +u (the gradient and the frame of bump maps)
#   back-mirror  twosided(normalmap(diffuse)) seen and lit from behind (the twosided turns
#                only the frame's n)
#   back-turn    normalmap(twosided(diffuse)) seen and lit from behind (the whole frame turns)
# Every case also carries the shadowing term for mapped normals (Conty Estevez et al. 2019).
# Optional tooling: the files are committed; valo builds, renders and tests without Python.
#
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 scripts/mitsuba-maps.py [--files-only] [--spp 8192]
import argparse, math, os, struct, zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "mitsuba-maps")


def png(path, w, h, rows, channels):
    """An 8-bit PNG of rows (lists of w * channels ints), written without a library."""
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    kind = {1: 0, 3: 2}[channels]
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, kind, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def encode(n):
    l = math.sqrt(sum(c * c for c in n))
    return [int(round((c / l * 0.5 + 0.5) * 255)) for c in n]


def height(x, y):
    """A smooth tiling height field on the unit square (bumps and waves)."""
    return 0.5 + 0.25 * math.sin(2 * math.pi * 3 * x) * math.cos(2 * math.pi * 2 * y) + 0.2 * math.sin(2 * math.pi * (2 * x + 3 * y))


def write_files():
    os.makedirs(OUT, exist_ok=True)
    th = math.radians(31)
    png(os.path.join(OUT, "tilt-v.png"), 4, 4, [encode((0, 0.6, 1)) * 4] * 4, 3)
    png(os.path.join(OUT, "tilt-u.png"), 4, 4, [encode((math.sin(th), 0, math.cos(th))) * 4] * 4, 3)
    png(os.path.join(OUT, "ramp-u.png"), 16, 16, [[16 * x + 8 for x in range(16)]] * 16, 1)
    n = 64
    png(os.path.join(OUT, "bumps.png"), n, n, [[int(round(255 * min(max(height((x + 0.5) / n, (y + 0.5) / n), 0), 1))) for x in range(n)] for y in range(n)], 1)
    rows = []
    for y in range(n):
        r = []
        for x in range(n):
            e = 1e-3
            u, v = (x + 0.5) / n, 1 - (y + 0.5) / n  # v up, as the normal map's green
            hu = (height(u + e, 1 - v) - height(u - e, 1 - v)) / (2 * e)
            hv = -(height(u, 1 - v - e) - height(u, 1 - v + e)) / (2 * e)
            r += encode((-0.08 * hu, -0.08 * hv, 1))
        rows.append(r)
    png(os.path.join(OUT, "waves-normal.png"), n, n, rows, 3)
    with open(os.path.join(OUT, "quad.obj"), "w") as f:
        f.write("# a unit quad as Mitsuba's rectangle: [-1, 1]^2 at z = 0, facing +z, u along +x, v along +y\n"
                "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
    with open(os.path.join(OUT, "quad.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment the quad of quad.obj\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 2\n"
                "property list uchar int vertex_indices\nend_header\n-1 -1 0 0 0 1 0 0\n1 -1 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n-1 1 0 0 0 1 0 1\n3 0 1 2\n3 0 2 3\n")
    # a torus about +y (major radius 1, minor 0.35), u around the ring, v around the tube
    nu, nv, R, r = 48, 24, 1.0, 0.35
    verts, faces = [], []
    for i in range(nu + 1):
        for j in range(nv + 1):
            a, b = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            c = (math.cos(a), 0, -math.sin(a))
            nrm = (c[0] * math.cos(b), math.sin(b), c[2] * math.cos(b))
            p = (R * c[0] + r * nrm[0], r * nrm[1], R * c[2] + r * nrm[2])
            verts.append(p + nrm + (2 * i / nu, j / nv))
    for i in range(nu):
        for j in range(nv):
            k = i * (nv + 1) + j
            faces += [(k, k + nv + 1, k + nv + 2), (k, k + nv + 2, k + 1)]
    with open(os.path.join(OUT, "torus.ply"), "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                 "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face %d\n"
                 "property list uchar int vertex_indices\nend_header\n" % (len(verts), len(faces))).encode())
        for v in verts:
            f.write(struct.pack("<8f", *v))
        for t in faces:
            f.write(struct.pack("<B3i", 3, *t))
    for case, (nest, cam, up, light) in CASES.items():
        for shape in SHAPES:
            with open(os.path.join(OUT, "%s-%s.xml" % (case, shape)), "w") as f:
                f.write(MINIMAL % {"what": case, "cam": cam, "up": up, "light": light, "shape": SHAPES[shape] % {"bsdf": nest}})
    with open(os.path.join(OUT, "maps.xml"), "w") as f:
        f.write(SCENE)


NORMAL_U = '<bsdf type="normalmap"><texture type="bitmap" name="normalmap"><string name="filename" value="tilt-u.png"/><boolean name="raw" value="true"/></texture>%s</bsdf>'
DIFFUSE = '<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>'
CASES = {
    "tilt-v": ('<bsdf type="normalmap"><texture type="bitmap" name="normalmap"><string name="filename" value="tilt-v.png"/><boolean name="raw" value="true"/></texture>'
               + DIFFUSE + '</bsdf>', "0, 0, 4", "0, 1, 0", "0, -0.642788, -0.766044"),
    "tilt-away": (NORMAL_U % DIFFUSE, "-3.825200, 0, 1.169492", "0, 0, 1", "0, 0, -1"),
    "bump-u": ('<bsdf type="bumpmap"><texture type="bitmap" name="bumpmap"><string name="filename" value="ramp-u.png"/><boolean name="raw" value="true"/></texture>'
               '<float name="scale" value="4"/>' + DIFFUSE + '</bsdf>', "0, 0, 4", "0, 1, 0", "-0.642788, 0, -0.766044"),
    "back-mirror": ('<bsdf type="twosided">' + NORMAL_U % DIFFUSE + '</bsdf>', "1.5, 0, -4", "0, 1, 0", "0.5, 0, 0.866025"),
    "back-turn": (NORMAL_U % ('<bsdf type="twosided">' + DIFFUSE + '</bsdf>'), "1.5, 0, -4", "0, 1, 0", "0.5, 0, 0.866025"),
}
SHAPES = {
    "rectangle": '<shape type="rectangle"><transform name="to_world"><scale value="4"/></transform>%(bsdf)s</shape>',
    "ply": '<shape type="ply"><string name="filename" value="quad.ply"/><transform name="to_world"><scale value="4"/></transform>%(bsdf)s</shape>',
    "obj": '<shape type="obj"><string name="filename" value="quad.obj"/><transform name="to_world"><scale value="4"/></transform>%(bsdf)s</shape>',
}
MINIMAL = """<?xml version='1.0' encoding='utf-8'?>
<!-- Normal and bump maps as Mitsuba renders them, case %(what)s (scripts/mitsuba-maps.py says
     what each case shows): one quad 8 units wide filling the view, under a directional light
     of irradiance 2, direct light only. For test_mitsuba maps_minimal_xml. -->
<scene version="3.0.0">
  <default name="res" value="16"/>
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <sensor type="perspective"><float name="fov" value="8"/>
    <transform name="to_world"><lookat origin="%(cam)s" target="0, 0, 0" up="%(up)s"/></transform>
    <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/><rfilter type="box"/></film>
  </sensor>
  %(shape)s
  <emitter type="directional"><vector name="direction" value="%(light)s"/><rgb name="irradiance" value="2"/></emitter>
</scene>
"""
SCENE = """<?xml version='1.0' encoding='utf-8'?>
<!-- Bump and normal maps as Mitsuba renders them (scripts/mitsuba-maps.py): a floor with a
     bump map, a rough gold sphere with a bump map, a standing rectangle and a PLY torus with
     normal maps, under an area lamp and a dim sky. The film's size is $resx x $resy. For
     test_mitsuba maps_xml. -->
<scene version="3.0.0">
  <default name="resx" value="160"/>
  <default name="resy" value="96"/>
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0, 3.5, 7" target="0, 0.8, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/><rfilter type="box"/></film>
  </sensor>
  <texture type="bitmap" id="waves"><string name="filename" value="waves-normal.png"/><boolean name="raw" value="true"/></texture>
  <shape type="rectangle"><transform name="to_world"><scale value="6"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="bumpmap"><texture type="bitmap" name="bumpmap"><string name="filename" value="bumps.png"/><boolean name="raw" value="true"/>
      <transform name="to_uv"><scale value="4"/></transform></texture><float name="scale" value="0.05"/>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.55, 0.5, 0.45"/></bsdf></bsdf></shape>
  <shape type="sphere"><point name="center" value="-2.2, 1, 0.3"/><float name="radius" value="1"/>
    <bsdf type="bumpmap"><texture type="bitmap" name="bumpmap"><string name="filename" value="bumps.png"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="0.04"/>
      <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.25"/></bsdf></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1.3" y="1.3"/><translate x="0.2" y="1.4" z="-1.8"/></transform>
    <bsdf type="twosided"><bsdf type="normalmap"><ref name="normalmap" id="waves"/>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/></bsdf></bsdf></bsdf></shape>
  <shape type="ply"><string name="filename" value="torus.ply"/>
    <transform name="to_world"><rotate x="1" angle="20"/><translate x="2.3" y="0.75" z="0.4"/></transform>
    <bsdf type="normalmap"><ref name="normalmap" id="waves"/>
      <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.1, 0.25, 0.6"/><float name="alpha" value="0.2"/></bsdf></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="1"/><rotate x="1" angle="90"/><translate x="-0.5" y="5" z="1.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="9"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.15"/></emitter>
</scene>
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--files-only", action="store_true")
    ap.add_argument("--only", default="")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    a = ap.parse_args()
    write_files()
    if a.files_only:
        return
    import mitsuba as mi
    mi.set_variant(a.variant)
    names = ["%s-%s" % (c, s) for c in CASES for s in SHAPES] + ["maps"]
    for name in names:
        if a.only and a.only != name:
            continue
        scene = mi.load_file(os.path.join(OUT, name + ".xml"))
        spp = 64 if name != "maps" else a.spp
        img, passes = None, max(1, spp // 4096)
        for k in range(passes):
            part = mi.render(scene, seed=11 + k, spp=min(spp, 4096))
            img = part if img is None else img + part
        out = os.path.join(OUT, name + "-mitsuba.exr")
        mi.Bitmap(img / passes).convert(component_format=mi.Struct.Type.Float16).write(out)
        print("wrote %s (%d spp, mitsuba %s)" % (out, passes * min(spp, 4096), mi.__version__), flush=True)


if __name__ == "__main__":
    main()
