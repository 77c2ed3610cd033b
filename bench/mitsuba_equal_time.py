# mitsuba_equal_time.py — valo against Mitsuba 3 at equal time, on every scene valo's
# tests hold a Mitsuba reference for: the Mitsuba scene files both read
# (scripts/mitsuba-shared-xml.py: Veach's MIS scene, Sponza's own file and the plugin
# scenes of tests/data/mitsuba-xml), the normal- and bump-map scene
# (tests/data/mitsuba-maps/maps.xml), and the material, light, camera and media scenes of
# scripts/mitsuba-materials.py (valo reads their JSON and OBJ files, Mitsuba the same
# meshes through that script's scene_dict). For each scene, on one machine, back to back:
# Mitsuba renders --spp samples per pixel (timed: mi.render after a warm-up render that
# compiles its kernels), then valo at its defaults is given that time (--time, the render
# phase, as Mitsuba's timing has no loading either; --spp 1048576 so that a sample count
# the scene file sets does not stop it first). Both against the committed Mitsuba
# reference (8 192 to 65 536 spp), averaged over --seeds seeds. Printed per scene: the
# relMSE ratio valo / Mitsuba (below 1: valo is ahead at equal time), and its two
# factors apart: the cost of a sample (valo's render seconds per sample per pixel, from
# its summary line, over Mitsuba's) and the error per sample (relMSE x spp, valo's over
# Mitsuba's); their product is the relMSE ratio where error falls as 1 / spp and valo
# spends the whole budget (it stops after the pass that reaches it, or before a pass
# that would not fit). Where a few rare paths carry most of the error (fireflies) or
# valo's converged image differs from Mitsuba's, error does not fall as 1 / spp and the
# error per sample depends on the sample count.
#
# Optional tooling (Python is not needed to build, render or test valo):
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 bench/mitsuba_equal_time.py [--valo build/valo] [--spp 256] [--seeds 2] [--threads 2]
#          [--only NAME[,NAME...]] [--group xml|maps|materials] [--valo-args "--accel kdtree"]
import argparse, math, os, re, shlex, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from mitsuba_xml_side_by_side import load  # noqa: E402 (a script file as a module)


def panel(mi, shared_dir):
    """(group, name, valo argv head, Mitsuba scene maker (spp -> scene), reference path)."""
    xml = load("scripts/mitsuba-shared-xml.py", "xml")
    mm = load("scripts/mitsuba-materials.py", "mm")
    out = []
    for name, (rel, defs0) in xml.SCENES.items():
        path, defs = xml.resolve(rel, defs0, shared_dir)
        ref = os.path.join(ROOT, "tests", "data", "mitsuba-xml", name + "-mitsuba.exr")
        if not os.path.exists(ref):
            continue
        dflags = sum([["-D", "%s=%s" % kv] for kv in defs.items()], [])
        out.append(("xml", name, [path] + dflags, lambda spp, p=path, d=defs: mi.load_file(p, **d), ref))
    maps = os.path.join(ROOT, "tests", "data", "mitsuba-maps")
    out.append(("maps", "maps", [os.path.join(maps, "maps.xml")], lambda spp: mi.load_file(os.path.join(maps, "maps.xml")),
                os.path.join(maps, "maps-mitsuba.exr")))
    groups = [mm.SCENES, mm.ENV_SCENES, mm.LIGHT_SCENES, mm.CAMERA_SCENES, mm.MEDIUM_SCENES, mm.GRID_SCENES, mm.TEXTURE_SCENES]
    for g in groups:
        for name, mat in g.items():
            ref = os.path.join(mm.OUT, name + "-mitsuba.exr")
            js = os.path.join(mm.OUT, name + ".json")
            if not os.path.exists(ref) or not os.path.exists(js):
                continue  # gold-spectral: its reference is Mitsuba's spectral variant
            out.append(("materials", name, [js], lambda spp, n=name, m=mat: mi.load_dict(mm.scene_dict(mi, n, m, spp)[0]), ref))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--valo", default=os.path.join(ROOT, "build", "valo"))
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=12345)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    ap.add_argument("--only", default="", help="scene names, comma-separated")
    ap.add_argument("--group", default="", help="xml, maps or materials")
    ap.add_argument("--valo-args", default="", help="more valo options, e.g. \"--accel kdtree\"")
    a = ap.parse_args()
    import numpy as np
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(a.variant)
    dr.set_thread_count(a.threads)
    relmse = load("bench/mitsuba_media_side_by_side.py", "media").relmse
    only = set(x for x in a.only.split(",") if x)
    print("| scene | Mitsuba s (%d spp) | Mitsuba relMSE | valo spp in that time | valo relMSE | relMSE valo / Mitsuba "
          "| cost per sample valo / Mitsuba | error per sample valo / Mitsuba |" % a.spp)
    print("|---|---|---|---|---|---|---|---|")
    ratios = []
    for group, name, head, make, refpath in panel(mi, a.shared):
        if (only and name not in only) or (a.group and a.group != group):
            continue
        ref = np.array(mi.Bitmap(refpath))[:, :, :3].astype(np.float32)
        s = make(a.spp)
        mi.render(s, seed=a.seed, spp=a.spp)  # compiles the kernels for this sample count
        mt = me = vs = vt = ve = 0.0
        for k in range(a.seeds):
            seed = a.seed + 1 + k
            t = time.time()
            img = np.array(mi.render(s, seed=seed, spp=a.spp))
            dt = time.time() - t
            mt += dt / a.seeds
            me += relmse(img[:, :, :3], ref) / a.seeds
            with tempfile.TemporaryDirectory() as tmp:
                out = os.path.join(tmp, "v.exr")
                p = subprocess.run([a.valo, "render"] + head + shlex.split(a.valo_args) +
                                   ["--time", "%.3f" % dt, "--spp", "1048576", "--threads", str(a.threads), "--seed", str(seed), "-o", out],
                                   check=True, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
                m = re.search(r"summary:.*?render ([0-9.]+) s; ([0-9.]+) spp", p.stderr)
                vt += (float(m.group(1)) if m else float("nan")) / a.seeds
                vs += (float(m.group(2)) if m else float("nan")) / a.seeds
                ve += relmse(np.array(mi.Bitmap(out))[:, :, :3], ref) / a.seeds
        r, cost, eps = ve / me, (vt / vs) / (mt / a.spp), (ve * vs) / (me * a.spp)
        ratios.append((name, r, cost, eps))
        print("| %s | %.2f | %.5f | %.0f | %.5f | %.2f | %.2f | %.2f |" % (name, mt, me, vs, ve, r, cost, eps), flush=True)
    if ratios:
        g = lambda i: math.exp(sum(math.log(x[i]) for x in ratios) / len(ratios))
        print("\n%d scenes; geometric means valo / Mitsuba: relMSE %.2f, cost per sample %.2f, error per sample %.2f; "
              "valo ahead (relMSE ratio <= 1) on %d" % (len(ratios), g(1), g(2), g(3), sum(1 for x in ratios if x[1] <= 1)))


if __name__ == "__main__":
    main()
