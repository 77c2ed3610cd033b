# test-meshes.py — writes the PLY meshes of tests/data/mitsuba-xml: for vertex-colors.xml,
# vc-floor.ply, a 4 x 4 floor of 12 x 12 quads whose float vertex colours vary across it,
# and vc-ball.ply, a UV sphere (24 x 12, its exact normals) coloured by its normal (ASCII
# PLY with float red, green, blue, the form Mitsuba 3 writes: it reads 8-bit colours as
# 0-255); for shading-backs.xml, coarse-ball.ply, a UV sphere of 8 x 5 facets with its
# exact normals. Optional tooling: the files are committed.
#
#   python3 scripts/test-meshes.py
import math, os

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "data", "mitsuba-xml")


def write(name, verts, faces, normals, colors=True):
    with open(os.path.join(OUT, name), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(verts))
        if normals:
            f.write("property float nx\nproperty float ny\nproperty float nz\n")
        if colors:
            f.write("property float red\nproperty float green\nproperty float blue\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for v in verts:
            f.write(" ".join("%.6g" % x for x in v) + "\n")
        for t in faces:
            f.write("3 %d %d %d\n" % t)


def floor():
    n, verts, faces = 12, [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = -2 + 4.0 * i / n, -2 + 4.0 * j / n
            r = 0.1 + 0.8 * i / n
            g = 0.1 + 0.8 * j / n
            b = 0.5 + 0.4 * math.sin(1.7 * x) * math.cos(2.3 * z)
            verts.append((x, 0, z, r, g, b))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            faces += [(a, a + n + 1, a + n + 2), (a, a + n + 2, a + 1)]  # facing +y
    write("vc-floor.ply", verts, faces, False)


def area(verts, t):
    a, b, c = (verts[k][:3] for k in t)
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(x * x for x in n))


def ball(nu=24, nv=12, name="vc-ball.ply", colors=True):
    verts, faces = [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            verts.append(n + n + (tuple(0.5 + 0.45 * c for c in n) if colors else ()))
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            faces += [(a, a + 1, a + nu + 2), (a, a + nu + 2, a + nu + 1)]
    faces = [t for t in faces if area(verts, t) > 1e-9]  # none at the poles
    write(name, verts, faces, True, colors)


floor()
ball()
ball(8, 5, "coarse-ball.ply", False)
