# mitsuba-shared-xml.py — Mitsuba 3's renders of the Mitsuba scene files in ../shared/scenes
# that valo reads directly (valo render scene.xml), for tests/test_mitsuba.c: each is
# rendered from its own XML file with the <default> values below (Mitsuba's -D), the
# integrator replaced by path (the files name a path-guiding plugin neither renderer has),
# or from a copy in tests/data/mitsuba-xml changed where Mitsuba 3 cannot read the original,
# and written to tests/data/mitsuba-xml/NAME-mitsuba.exr (half float). Optional tooling:
# the EXRs are committed; valo builds, renders and tests without Python.
#
#   pip install mitsuba numpy
#   DRJIT_LIBLLVM_PATH=~/.rustup/toolchains/stable-x86_64-unknown-linux-gnu/lib/libLLVM.so.22.1-rust-1.95.0-stable \
#   python3 scripts/mitsuba-shared-xml.py [--spp 8192] [--only veach-mis]
import argparse, os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "mitsuba-xml")
# name: (scene file under ../shared/scenes, its defaults); tests/test_mitsuba.c passes the
# same values with --define.
SCENES = {"veach-mis": ("veach-mis/mitsuba-source/scene.xml", {"integrator": "path", "resx": "320", "resy": "180"}),
          # the path-guiding lab's torus in a glass block (valo renders its file with guided)
          "torus": ("torus/mitsuba-source/scene.xml", {"integrator": "path", "resx": "256", "resy": "192"}),
          # Sponza's own scene file, changed only where Mitsuba 3 cannot render it (the file says
          # how), reading its serialized mesh and textures from ../shared.
          "sponza-serialized": ("@tests/data/mitsuba-xml/sponza-serialized.xml", {"resx": "128", "resy": "72"}),
          # instancing and <include>, with the bunny from ../shared
          "instances": ("@tests/data/mitsuba-xml/instances.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's plastic and roughplastic (valo's plastic material)
          "plastic": ("@tests/data/mitsuba-xml/plastic.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's mask with a binary opacity bitmap (valo's opacity)
          "mask": ("@tests/data/mitsuba-xml/mask.xml", {"resx": "128", "resy": "96"}),
          # Mitsuba's mask with fractional opacity: a number and a ramp bitmap (valo's opacity)
          "opacity": ("@tests/data/mitsuba-xml/opacity.xml", {"resx": "128", "resy": "96"}),
          # Mitsuba's blendbsdf: a number, the default and a ramp bitmap as weights (valo's blend)
          "blend": ("@tests/data/mitsuba-xml/blend.xml", {"resx": "128", "resy": "96"}),
          # Mitsuba's principled BSDF (valo's principled)
          "principled": ("@tests/data/mitsuba-xml/principled.xml", {"resx": "160", "resy": "96"}),
          "principled-glass": ("@tests/data/mitsuba-xml/principled-glass.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's checkerboard and bitmap lookups: to_uv, filter_type, wrap_mode, raw
          "textures": ("@tests/data/mitsuba-xml/textures.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's roughness and metallic textures (valo's roughness_map and metallic_map)
          "roughness": ("@tests/data/mitsuba-xml/roughness.xml", {"resx": "160", "resy": "96"}),
          # an environment map turned any way (valo's environment "matrix")
          "env-turned": ("@tests/data/mitsuba-xml/env-turned.xml", {"resx": "160", "resy": "96"}),
          # a lamp whose radiance is a bitmap, on a shape without a BSDF (black in Mitsuba)
          "lamp-texture": ("@tests/data/mitsuba-xml/lamp-texture.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's twosided of two BSDFs (valo's sided material)
          "sided": ("@tests/data/mitsuba-xml/sided.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's single-sided BSDFs seen from behind (valo's black_back)
          "backs": ("@tests/data/mitsuba-xml/backs.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's hide_emitters (valo's render.hide_emitters)
          "hide": ("@tests/data/mitsuba-xml/hide.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's measured conductors by name (valo's conductor presets)
          "metals": ("@tests/data/mitsuba-xml/metals.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's anisotropic roughness (valo's roughness_u and roughness_v)
          "aniso": ("@tests/data/mitsuba-xml/aniso.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's mesh_attribute texture of a PLY file's vertex colours (valo's vertex_colors)
          "vertex-colors": ("@tests/data/mitsuba-xml/vertex-colors.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's cylinder (valo's cylinder)
          "cylinders": ("@tests/data/mitsuba-xml/cylinders.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's specular_transmittance on dielectrics (valo's transmittance)
          "tinted-glass": ("@tests/data/mitsuba-xml/tinted-glass.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's one-sided BSDFs told by the shading normal on coarse smooth meshes (valo's black_back)
          "shading-backs": ("@tests/data/mitsuba-xml/shading-backs.xml", {"resx": "160", "resy": "96"}),
          # Mitsuba's spot lights across their transition band (valo's linear falloff)
          "spot-falloff": ("@tests/data/mitsuba-xml/spot-falloff.xml", {"resx": "160", "resy": "96"})}


def resolve(path, defs, shared):
    """The scene file of a SCENES entry and its <default> values (a repository file, "@...",
    is given the shared folder as $shared when it uses it)."""
    if path.startswith("@"):
        file = os.path.join(ROOT, path[1:])
        with open(file) as f:
            uses = "$shared" in f.read()
        return file, dict(defs, shared=os.path.abspath(shared)) if uses else dict(defs)
    return os.path.join(shared, "scenes", path), dict(defs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--only", default="")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant(a.variant)
    os.makedirs(OUT, exist_ok=True)
    for name, (path, defs) in SCENES.items():
        if a.only and a.only != name:
            continue
        file, values = resolve(path, defs, a.shared)
        scene = mi.load_file(file, **values)
        img = None
        passes = max(1, a.spp // 4096)
        for k in range(passes):
            part = mi.render(scene, seed=11 + k, spp=min(a.spp, 4096))
            img = part if img is None else img + part
        out = os.path.join(OUT, name + "-mitsuba.exr")
        mi.Bitmap(img / passes).convert(component_format=mi.Struct.Type.Float16).write(out)
        print("wrote %s (%d spp, mitsuba %s)" % (out, passes * min(a.spp, 4096), mi.__version__), flush=True)


if __name__ == "__main__":
    main()
