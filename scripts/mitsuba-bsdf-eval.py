# mitsuba-bsdf-eval.py — Mitsuba 3's own values of its plastic, roughplastic and principled
# BSDFs (scalar_rgb, BSDF::eval) at fixed directions, the independent references of
# `test_mitsuba plastic_eval` and `principled_eval` (optional tooling: the tables it writes
# are committed; valo builds and tests without Python).
#
#   pip install mitsuba
#   python3 scripts/mitsuba-bsdf-eval.py plastic > tests/data/mitsuba-bsdf/plastic-eval.txt
#   python3 scripts/mitsuba-bsdf-eval.py principled > tests/data/mitsuba-bsdf/principled-eval.txt
#
# Each line: the case name, theta and phi (degrees) of the direction towards the viewer
# (Mitsuba's si.wi, valo's wo), of the direction towards the light (Mitsuba's wo, valo's
# wi), then RGB values of f * cos(light direction): for plastics the specular and the
# diffuse component's (one component enabled at a time), for principled the whole BSDF's.
import math
import sys
import mitsuba as mi

mi.set_variant('scalar_rgb')

def rgb(v):
    return {'type': 'rgb', 'value': v}

# Keep in step with plastic_case() and principled_case() in tests/test_mitsuba.c.
PLASTIC = [
    ('smooth', dict(type='plastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]))),
    ('smooth-nonlinear-1.9', dict(type='plastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]), nonlinear=True, int_ior=1.9)),
    ('beckmann-0.1', dict(type='roughplastic', diffuse_reflectance=rgb([0.6, 0.3, 0.1]))),
    ('ggx-0.3-tinted', dict(type='roughplastic', distribution='ggx', alpha=0.3, diffuse_reflectance=rgb([0.2, 0.5, 0.7]),
                            specular_reflectance=rgb([0.9, 0.8, 0.7]))),
    ('beckmann-0.5-nonlinear', dict(type='roughplastic', alpha=0.5, nonlinear=True, diffuse_reflectance=rgb([0.8, 0.8, 0.2]))),
]
PRINCIPLED = [
    ('dielectric-0.4', dict(type='principled', base_color=rgb([0.6, 0.3, 0.1]), roughness=0.4)),
    ('metal-0.2', dict(type='principled', base_color=rgb([0.9, 0.6, 0.3]), metallic=1.0, roughness=0.2)),
    ('half-metal-tinted', dict(type='principled', base_color=rgb([0.2, 0.6, 0.3]), metallic=0.5, spec_tint=0.7, roughness=0.6, specular=0.8)),
    ('sheen-flat', dict(type='principled', base_color=rgb([0.7, 0.4, 0.6]), sheen=0.8, sheen_tint=0.5, flatness=0.6, roughness=0.7)),
    ('clearcoat', dict(type='principled', base_color=rgb([0.2, 0.5, 0.7]), clearcoat=1.0, clearcoat_gloss=0.7, roughness=0.5)),
    ('eta-1.8', dict(type='principled', base_color=rgb([0.3, 0.3, 0.3]), eta=1.8, roughness=0.15)),
    ('glass-0.3', dict(type='principled', base_color=rgb([0.9, 0.95, 1.0]), spec_trans=1.0, roughness=0.3)),
    ('half-trans', dict(type='principled', base_color=rgb([0.8, 0.5, 0.3]), spec_trans=0.5, metallic=0.2, roughness=0.5, eta=1.33,
                        clearcoat=0.5)),
    ('aniso-0.7', dict(type='principled', base_color=rgb([0.7, 0.5, 0.3]), metallic=0.6, roughness=0.4, anisotropic=0.7)),
    ('aniso-glass', dict(type='principled', base_color=rgb([0.9, 0.9, 1.0]), spec_trans=1.0, roughness=0.35, anisotropic=0.5)),
]
# for the anisotropic cases, also pairs at other azimuths (the frame's s is +x)
DIRS_A = [(30, 45, 40, 225), (50, 90, 45, 270), (20, 30, 60, 200), (70, 120, 50, 300), (40, 10, 40, 190), (60, 80, 30, 250),
          (15, 135, 65, 315), (80, 45, 75, 225), (35, 60, 25, 240), (55, 160, 50, 340)]
# for the transmissive cases, also light below the surface and the viewer inside
DIRS_T = [(30, 0, 150, 180), (10, 0, 170, 0), (60, 0, 130, 200), (45, 0, 100, 180), (140, 0, 150, 180), (150, 0, 40, 180),
          (120, 0, 60, 0), (170, 0, 30, 170), (100, 0, 20, 180), (160, 0, 120, 30)]
DIRS = [(10, 0, 40, 180), (30, 0, 30, 170), (60, 0, 20, 150), (45, 0, 45, 180), (75, 0, 70, 160), (20, 0, 80, 30),
        (5, 0, 5, 90), (50, 0, 52, 178), (85, 0, 60, 180), (0, 0, 88, 0)]

def unit(t, p):
    t, p = math.radians(t), math.radians(p)
    return mi.Vector3f(math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))

which = sys.argv[1] if len(sys.argv) > 1 else ''
if which not in ('plastic', 'principled'):
    sys.exit('usage: mitsuba-bsdf-eval.py plastic|principled')
plastic = which == 'plastic'
print('# Mitsuba %s, scalar_rgb: name theta_wo phi_wo theta_wi phi_wi %s' %
      (mi.__version__, 'specular(rgb) diffuse(rgb)' if plastic else 'f*cos(rgb)'))
for name, d in (PLASTIC if plastic else PRINCIPLED):
    b = mi.load_dict(d)
    for (to, po, ti, pi) in DIRS + (DIRS_T if not plastic and 'spec_trans' in d else []) + (DIRS_A if 'anisotropic' in d else []):
        si = mi.SurfaceInteraction3f()
        si.wi = unit(to, po)
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        si.n = mi.Vector3f(0, 0, 1)
        out = []
        for comp in ((0, 1) if plastic else (None,)):
            ctx = mi.BSDFContext()
            if comp is not None:
                ctx.component = comp
            v = b.eval(ctx, si, unit(ti, pi))
            out += [v[0], v[1], v[2]]
        print(name, to, po, ti, pi, ' '.join('%.7g' % x for x in out))
