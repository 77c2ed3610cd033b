# mitsuba_media_side_by_side.py — valo's path against Mitsuba 3's volpath on the media
# scenes of tests/data/materials (smoke-ball, absorbing-glass, cloud-grid: the JSON, the
# meshes and the grid that scripts/mitsuba-materials.py writes, read by both), back to
# back on one machine: each renderer at the given sample counts, its seconds (wall clock
# of the whole render: valo's process, Mitsuba's mi.render after a warm-up render that
# compiles its kernels) and its relMSE against the committed Mitsuba reference of the
# scene (16 384 or 65 536 spp), each averaged over --seeds seeds (a few fireflies, paths
# into glass found by BSDF sampling alone, move one seed's relMSE by 2x), then each one's
# time to the relMSE of Mitsuba's largest sample count (interpolated on its own
# error-vs-time curve, log-log).
#
# Optional tooling (Python is not needed to build, render or test valo):
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 bench/mitsuba_media_side_by_side.py [--valo build/valo] [--spp 64,256,1024] [--only smoke-ball]
#          [--variant llvm_ad_rgb | scalar_rgb] [--threads 2] [--seed 12345] [--seeds 3]
# Mitsuba's scene is scripts/mitsuba-materials.py's own scene_dict, so the conventions
# matched are the ones listed there.
import argparse, importlib.util, math, os, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "tests", "data", "materials")


def load_script():
    spec = importlib.util.spec_from_file_location("mm", os.path.join(ROOT, "scripts", "mitsuba-materials.py"))
    mm = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mm)
    return mm


def relmse(img, ref):
    import numpy as np
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))


def time_to(curve, target):
    """seconds at which a renderer's (seconds, relMSE) curve reaches target (log-log)."""
    pts = sorted(curve)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - target) * (e1 - target) <= 0 and e0 != e1:
            a = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + a * (math.log(t1) - math.log(t0)))
    (t0, e0), (t1, e1) = pts[-2], pts[-1]  # beyond the curve: extrapolate its last slope
    a = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return math.exp(math.log(t0) + a * (math.log(t1) - math.log(t0)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--valo", default=os.path.join(ROOT, "build", "valo"))
    ap.add_argument("--spp", default="64,256,1024")
    ap.add_argument("--only", default="")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=12345)
    ap.add_argument("--seeds", type=int, default=3)
    a = ap.parse_args()
    import numpy as np
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(a.variant)
    dr.set_thread_count(a.threads)
    mm = load_script()
    scenes = dict(list(mm.MEDIUM_SCENES.items()) + list(mm.GRID_SCENES.items()))
    spps = [int(s) for s in a.spp.split(",")]
    print("| scene | spp | Mitsuba s | Mitsuba relMSE | valo s | valo relMSE |")
    print("|---|---|---|---|---|---|")
    summary = []
    for name, mat in scenes.items():
        if a.only and a.only != name:
            continue
        ref = np.array(mi.Bitmap(os.path.join(DATA, name + "-mitsuba.exr")))[:, :, :3]
        mcurve, vcurve = [], []
        for spp in spps:
            d, w, h = mm.scene_dict(mi, name, mat, spp)
            s = mi.load_dict(d)
            mi.render(s, seed=a.seed, spp=spp)  # compiles the kernels for this sample count
            mt = me = vt = ve = 0
            for k in range(a.seeds):
                seed = a.seed + 1 + k
                t = time.time()
                img = np.array(mi.render(s, seed=seed, spp=spp))
                mt += (time.time() - t) / a.seeds
                me += relmse(img[:, :, :3], ref) / a.seeds
                with tempfile.TemporaryDirectory() as tmp:
                    out = os.path.join(tmp, "v.exr")
                    t = time.time()
                    subprocess.run([a.valo, "render", os.path.join(DATA, name + ".json"), "--spp", str(spp), "--threads", str(a.threads),
                                    "--seed", str(seed), "-q", "-o", out], check=True)
                    vt += (time.time() - t) / a.seeds
                    ve += relmse(np.array(mi.Bitmap(out))[:, :, :3], ref) / a.seeds
            mcurve.append((mt, me))
            vcurve.append((vt, ve))
            print("| %s | %d | %.2f | %.5f | %.2f | %.5f |" % (name, spp, mt, me, vt, ve), flush=True)
        target = mcurve[-1][1]
        summary.append((name, mcurve[-1][0], time_to(vcurve, target)))
    print()
    print("| scene | Mitsuba s to its relMSE at %d spp | valo s to the same relMSE | valo / Mitsuba |" % spps[-1])
    print("|---|---|---|---|")
    for name, mt, vt in summary:
        print("| %s | %.2f | %.2f | %.2f |" % (name, mt, vt, vt / mt))


if __name__ == "__main__":
    main()
