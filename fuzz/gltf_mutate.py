#!/usr/bin/env python3
# gltf_mutate.py — optional tooling: structure-aware mutations of a glTF (.gltf or .glb),
# each run through `valo render`; keeps every input that crashed, hung or made a
# sanitizer report. libFuzzer (scene_gltf, scene_glb) mutates bytes, and most of its
# inputs stop at valo's glTF check; these edit the JSON as a tree (values swapped for
# others of glTF's vocabulary, members deleted, copied or duplicated), so a fifth or more
# pass the check and reach Assimp. Not needed to build or test (docs/testing.md).
#   python3 fuzz/gltf_mutate.py SEED_FILE RUNS RNG_SEED OUT_DIR [VALO]
# VALO defaults to build/valo; the ASan build (build-fuzz/valo) also catches overreads.
import copy, json, os, random, struct, subprocess, sys

src, runs, rng, out = sys.argv[1], int(sys.argv[2]), random.Random(int(sys.argv[3])), sys.argv[4]
valo = sys.argv[5] if len(sys.argv) > 5 else 'build/valo'
ext = os.path.splitext(src)[1]
raw = open(src, 'rb').read()
if ext == '.glb':
    jl = struct.unpack('<I', raw[12:16])[0]
    seed, tail = json.loads(raw[20:20 + jl]), raw[20 + jl:]
else:
    seed, tail = json.loads(raw), b''
os.makedirs(out, exist_ok=True)
VALUES = [0, 1, 2, 3, 4, 5, 6, -1, 0.5, 1e30, -1e30, 65535, 4294967295, '', 'x', None, True, [], {}, [0], [1, 2, 3],
          'image/png', 'CUBICSPLINE', 'STEP', 'weights', 'rotation', 'scale', 'translation', 'spot', 'point',
          'perspective', 'orthographic', 'MASK', 'BLEND', 'OPAQUE', 5120, 5121, 5122, 5123, 5125, 5126,
          'SCALAR', 'VEC2', 'VEC3', 'VEC4', 'MAT2', 'MAT3', 'MAT4']

def paths(o, p=()):
    yield p
    items = o.items() if isinstance(o, dict) else enumerate(o) if isinstance(o, list) else ()
    for k, v in items:
        yield from paths(v, p + (k,))

def at(o, p):
    for k in p:
        o = o[k]
    return o

def mutate(g):
    for _ in range(rng.randint(1, 3)):
        ps = list(paths(g))[1:]
        if not ps:
            break
        p = rng.choice(ps)
        parent, key, v = at(g, p[:-1]), p[-1], at(g, p)
        r = rng.random()
        if r < 0.5:
            num = isinstance(v, (int, float)) and not isinstance(v, bool)
            parent[key] = v + rng.choice([-1, 1, 2]) if num and rng.random() < 0.3 else rng.choice(VALUES)
        elif r < 0.7:
            del parent[key]
        elif r < 0.85:
            if isinstance(parent, list):
                parent.append(copy.deepcopy(v))
        else:
            parent[key] = copy.deepcopy(at(g, rng.choice(ps)))
    return g

found = loaded = 0
for i in range(runs):
    js = json.dumps(mutate(copy.deepcopy(seed))).encode()
    if ext == '.glb':
        js += b' ' * (-len(js) % 4)
        data = struct.pack('<5I', 0x46546C67, 2, 20 + len(js) + len(tail), len(js), 0x4E4F534A) + js + tail
    else:
        data = js
    path = os.path.join(out, 'input' + ext)
    open(path, 'wb').write(data)
    try:
        r = subprocess.run([valo, 'render', path, '--spp', '1', '--res', '8x8', '-q', '-o', os.path.join(out, 'out.png')],
                           capture_output=True, timeout=20)
        bad = r.returncode < 0 or r.returncode > 128 or b'Sanitizer' in r.stderr or b'runtime error' in r.stderr
        why, loaded = 'rc%d' % r.returncode, loaded + (r.returncode == 0)
    except subprocess.TimeoutExpired:
        bad, why = True, 'hang'
    if bad:
        found += 1
        open(os.path.join(out, '%s-%d%s' % (why, i, ext)), 'wb').write(data)
print('%d inputs, %d loaded, %d kept' % (runs, loaded, found))
