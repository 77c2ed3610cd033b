# mitsuba-plastic-eval.py — Mitsuba 3's own values of its plastic and roughplastic BSDFs
# (scalar_rgb, BSDF::eval with one component enabled at a time) at fixed directions, the
# independent reference of `test_mitsuba plastic_eval` (optional tooling: the table it
# writes is committed; valo builds and tests without Python).
#
#   pip install mitsuba
#   python3 scripts/mitsuba-plastic-eval.py > tests/data/mitsuba-bsdf/plastic-eval.txt
#
# Each line: the case name, theta and phi (degrees) of the direction towards the viewer
# (Mitsuba's si.wi, valo's wo), of the direction towards the light (Mitsuba's wo, valo's
# wi), then the specular and the diffuse component's RGB, each f * cos(light direction).
import math
import mitsuba as mi

mi.set_variant('scalar_rgb')

def rgb(v):
    return {'type': 'rgb', 'value': v}

# Keep in step with plastic_case() in tests/test_mitsuba.c.
CASES = [
    ('smooth', dict(type='plastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]))),
    ('smooth-nonlinear-1.9', dict(type='plastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]), nonlinear=True, int_ior=1.9)),
    ('beckmann-0.1', dict(type='roughplastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]))),
    ('ggx-0.3-tinted', dict(type='roughplastic', distribution='ggx', alpha=0.3, diffuse_reflectance=rgb([0.2, 0.5, 0.7]),
                            specular_reflectance=rgb([0.9, 0.8, 0.7]))),
    ('beckmann-0.5-nonlinear', dict(type='roughplastic', alpha=0.5, nonlinear=True, diffuse_reflectance=rgb([0.8, 0.8, 0.2]))),
]
DIRS = [(10, 0, 40, 180), (30, 0, 30, 170), (60, 0, 20, 150), (45, 0, 45, 180), (75, 0, 70, 160), (20, 0, 80, 30),
        (5, 0, 5, 90), (50, 0, 52, 178), (85, 0, 60, 180), (0, 0, 88, 0)]

def unit(t, p):
    t, p = math.radians(t), math.radians(p)
    return mi.Vector3f(math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))

print('# Mitsuba %s, scalar_rgb: name theta_wo phi_wo theta_wi phi_wi specular(rgb) diffuse(rgb)' % mi.__version__)
for name, d in CASES:
    b = mi.load_dict(d)
    for (to, po, ti, pi) in DIRS:
        si = mi.SurfaceInteraction3f()
        si.wi = unit(to, po)
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        si.n = mi.Vector3f(0, 0, 1)
        out = []
        for comp in (0, 1):
            ctx = mi.BSDFContext()
            ctx.component = comp
            v = b.eval(ctx, si, unit(ti, pi))
            out += [v[0], v[1], v[2]]
        print(name, to, po, ti, pi, ' '.join('%.7g' % x for x in out))
