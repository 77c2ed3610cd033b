# mitsuba-filter-edge.py — Mitsuba 3's renders of the pixel-filter edge scene of
# tests/test_analytic.c (pixel_filter_mitsuba): an orthographic view, one scene unit per
# pixel on a 16 x 16 film, of an emitting half-plane (radiance 1, x >= 0.3, z = -1) whose
# edge crosses the film at x = 8.3 pixels, through Mitsuba's filters with negative lobes:
# mitchell (B = C = 1/3, radius 2), catmullrom (radius 2) and lanczos (3 lobes). Writes
# tests/data/filters/mitsuba-edge-NAME.exr (optional tooling: the EXRs are committed;
# valo builds and tests without Python).
#
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#     python3 scripts/mitsuba-filter-edge.py [--spp N] [--variant scalar_rgb]
#
# 65536 samples (the default): at 2^20, Mitsuba's float sums drift by up to 0.01 at the edge.
# Conventions matched: Mitsuba's orthographic sensor sees x and y in [-1, 1] of its space,
# scaled by 8 to valo's "height": 16 on a square film; its camera looks down its +z, and
# the lookat from the origin to (0, 0, -1) with up +y puts +x on the image's right as in
# valo (checked: the lit half is on the right); the half-plane is a rectangle of area
# emitter radiance 1 facing the camera; Mitsuba splats each sample into the pixels its
# filter reaches and divides by the weights' sum, which converges to the image valo's
# filter importance sampling estimates (the image convolved with the normalised filter).
import argparse, os
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "filters")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=65536)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant(a.variant)
    T = mi.ScalarTransform4f
    for name, rf in (("mitchell", {"type": "mitchell"}), ("catmull-rom", {"type": "catmullrom"}), ("lanczos", {"type": "lanczos", "lobes": 3})):
        scene = mi.load_dict({
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 2},
            "sensor": {
                "type": "orthographic",
                "to_world": T().look_at(origin=[0, 0, 0], target=[0, 0, -1], up=[0, 1, 0]) @ T().scale([8, 8, 1]),
                "sampler": {"type": "independent", "sample_count": a.spp},
                "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": rf, "pixel_format": "rgb"},
            },
            "plane": {
                "type": "rectangle",
                "to_world": T().translate([50.15, 0, -1]) @ T().scale([49.85, 100, 1]),
                "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}},
            },
        })
        img = np.array(mi.render(scene, spp=a.spp))
        print(name, "row 8:", " ".join("%.3f" % v for v in img[8, :, 1]))
        mi.Bitmap(img).write(os.path.join(OUT, "mitsuba-edge-%s.exr" % name))


if __name__ == "__main__":
    main()
