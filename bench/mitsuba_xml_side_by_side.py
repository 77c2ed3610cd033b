# mitsuba_xml_side_by_side.py — valo against Mitsuba 3 on a Mitsuba scene file both read:
# the scenes of scripts/mitsuba-shared-xml.py (../shared's own scene.xml files, with the
# same <default> values: Mitsuba's -D, valo's --define), back to back on one machine. Each
# renderer at the given sample counts: its seconds (wall clock of the whole render:
# valo's process, Mitsuba's mi.render after a warm-up render that compiles its kernels)
# and its relMSE against the committed Mitsuba reference (tests/data/mitsuba-xml, 8192
# spp), averaged over --seeds seeds; then each one's time to the relMSE of Mitsuba's
# largest sample count (interpolated on its own error-vs-time curve, log-log). valo runs
# twice: with the file's sampler (independent, as the file asks) and with its own
# default, Sobol (--sampler sobol).
#
# Optional tooling (Python is not needed to build, render or test valo):
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 bench/mitsuba_xml_side_by_side.py [--valo build/valo] [--spp 64,256,1024] [--seeds 2] [--threads 2] [--only NAME]
import argparse, importlib.util, os, subprocess, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load(path, name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(ROOT, path))
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    return m


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--valo", default=os.path.join(ROOT, "build", "valo"))
    ap.add_argument("--spp", default="64,256,1024")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=12345)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    ap.add_argument("--only", default="", help="one scene of scripts/mitsuba-shared-xml.py")
    a = ap.parse_args()
    import numpy as np
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(a.variant)
    dr.set_thread_count(a.threads)
    media = load("bench/mitsuba_media_side_by_side.py", "media")  # relmse, time_to
    shared = load("scripts/mitsuba-shared-xml.py", "shared")
    spps = [int(s) for s in a.spp.split(",")]
    print("| scene | spp | Mitsuba s | Mitsuba relMSE | valo (file's sampler) s | relMSE | valo (Sobol) s | relMSE |")
    print("|---|---|---|---|---|---|---|---|")
    summary = []
    for name, (rel, defs0) in shared.SCENES.items():
        if a.only and a.only != name:
            continue
        path, defs = shared.resolve(rel, defs0, a.shared)
        ref = np.array(mi.Bitmap(os.path.join(ROOT, "tests", "data", "mitsuba-xml", name + "-mitsuba.exr")))[:, :, :3].astype(np.float32)
        s = mi.load_file(path, **defs)
        defines = sum([["-D", "%s=%s" % kv] for kv in defs.items()], [])
        curves = [[], [], []]
        for spp in spps:
            mi.render(s, seed=a.seed, spp=spp)  # compiles the kernels for this sample count
            row = [[0, 0], [0, 0], [0, 0]]
            for k in range(a.seeds):
                seed = a.seed + 1 + k
                t = time.time()
                img = np.array(mi.render(s, seed=seed, spp=spp))
                row[0][0] += (time.time() - t) / a.seeds
                row[0][1] += media.relmse(img[:, :, :3], ref) / a.seeds
                for j, extra in ((1, []), (2, ["--sampler", "sobol"])):
                    with tempfile.TemporaryDirectory() as tmp:
                        out = os.path.join(tmp, "v.exr")
                        t = time.time()
                        subprocess.run([a.valo, "render", path] + defines + extra + ["--spp", str(spp), "--threads", str(a.threads),
                                        "--seed", str(seed), "-q", "-o", out], check=True, stderr=subprocess.DEVNULL)
                        row[j][0] += (time.time() - t) / a.seeds
                        row[j][1] += media.relmse(np.array(mi.Bitmap(out))[:, :, :3], ref) / a.seeds
            for j in range(3):
                curves[j].append(tuple(row[j]))
            print("| %s | %d | %.2f | %.5f | %.2f | %.5f | %.2f | %.5f |" % (name, spp, *row[0], *row[1], *row[2]), flush=True)
        target = curves[0][-1][1]
        summary.append((name, curves[0][-1][0], media.time_to(curves[1], target), media.time_to(curves[2], target)))
    print()
    print("| scene | Mitsuba s to its relMSE at %d spp | valo (file's sampler) / Mitsuba | valo (Sobol) / Mitsuba |" % spps[-1])
    print("|---|---|---|---|")
    for name, mt, v1, v2 in summary:
        print("| %s | %.2f | %.2f | %.2f |" % (name, mt, v1 / mt, v2 / mt))


if __name__ == "__main__":
    main()
