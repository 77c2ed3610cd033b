/* test_scene.c — scene loading: non-unit normals normalised (head.obj), the JSON
 * transform order (scale, rotate x/y/z, translate), MTL meanings of McGuire's Cornell
 * boxes (Kd, Ke front-sided emitters, illum 5 mirror, illum 7 glass), automatic framing
 * of a mesh without a camera, polygon triangulation, and the camera's film point of a world
 * point (ReSTIR's reprojection) as the inverse of its rays, perspective and orthographic, and
 * a mesh file placed again from its kept import as a second reading would place it. */
#include "harness.h"
#include "load/load.h"
#include "scene/scene.h"
#include "scene/camera.h"
#include "light/light.h"
#include "material/plastic.h"
#include "core/rng.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int head_normals_unit(void) {
  const char *p = shared_file("scenes/models/head.obj");
  if (!p) return TEST_SKIP;
  scene *s = scene_new(p);
  valo_error err;
  CHECK(load_mesh(s, p, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  uint32_t with = 0;
  for (uint32_t t = 0; t < s->ntris; t++) {
    if (!(s->tri_flags[t] & TRI_HAS_NORMALS)) continue;
    with++;
    for (int k = 0; k < 3; k++) {
      float l = v3_len(s->nrm[s->idx[3 * t + k]]);
      CHECK(fabsf(l - 1) < 1e-5f, "normal of length %g", l);
    }
  }
  CHECK(with > s->ntris / 2, "only %u of %u triangles kept normals", with, s->ntris);
  scene_free(s);
  return 0;
}

static int transform_order(void) {
  const char *obj = scratch_file("tri.obj", "v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
  CHECK(obj, "cannot write");
  char json[1024];
  /* scale 2, then rotate_y 90 (x -> -z), then translate (10,0,0). */
  snprintf(json, sizeof json,
           "{ \"shapes\": [{\"file\": \"tri.obj\", \"transform\": {\"scale\": 2, \"rotate_y\": 90, \"translate\": [10,0,0]}}] }");
  const char *jp = scratch_file("tri.json", json);
  scene *s = scene_new(jp);
  valo_error err;
  CHECK(load_json(s, jp, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(s->ntris == 1, "%u triangles", s->ntris);
  vec3 a = s->pos[s->idx[0]], b = s->pos[s->idx[1]], c = s->pos[s->idx[2]];
  CHECK(fabsf(a.x - 10) < 1e-5f && fabsf(a.y) < 1e-5f && fabsf(a.z + 2) < 1e-5f, "v1 -> (%g %g %g), expected (10 0 -2)", a.x, a.y, a.z);
  CHECK(fabsf(b.x - 10) < 1e-5f && fabsf(b.y - 2) < 1e-5f && fabsf(b.z) < 1e-5f, "v2 -> (%g %g %g)", b.x, b.y, b.z);
  CHECK(fabsf(c.x - 12) < 1e-5f && fabsf(c.y) < 1e-5f && fabsf(c.z) < 1e-5f, "v3 -> (%g %g %g), expected (12 0 0)", c.x, c.y, c.z);
  scene_free(s);
  /* A mirroring scale keeps the winding's front side facing the same way. */
  snprintf(json, sizeof json, "{ \"shapes\": [{\"file\": \"tri.obj\", \"transform\": {\"scale\": [-1,1,1]}}] }");
  jp = scratch_file("tri2.json", json);
  s = scene_new(jp);
  CHECK(load_json(s, jp, NULL, &err) == VALO_OK, "%s", err.message);
  vec3 n = scene_tri_ng(s, 0);
  CHECK(n.x < 0 && n.y > 0 && n.z > 0, "mirrored normal (%g %g %g), expected (-,+,+)", n.x, n.y, n.z);
  scene_free(s);
  return 0;
}

static int load_committed(const char *rel, scene **out) {
  const char *p = shared_file(rel);
  if (!p) return TEST_SKIP;
  scene *s = scene_new(p);
  valo_error err;
  if (load_mesh(s, p, NULL, UINT32_MAX, 1, NULL, &err) || scene_commit(s, &err)) { fprintf(stderr, "%s\n", err.message); scene_free(s); return 1; }
  *out = s;
  return 0;
}

static int mtl_meanings(void) {
  scene *s;
  int rc = load_committed("scenes/cornell/CornellBox-Original.obj", &s);
  if (rc) return rc;
  int lights = 0;
  for (uint32_t i = 0; i < s->nlights; i++) {
    const light *l = &s->lights[i];
    if (l->type != LIGHT_AREA) continue;
    lights++;
    CHECK(fabsf(l->L.r - 17) < 1e-6f && fabsf(l->L.g - 12) < 1e-6f && fabsf(l->L.b - 4) < 1e-6f, "Ke (%g %g %g)", l->L.r, l->L.g, l->L.b);
    CHECK(!l->two_sided, "MTL emitters are front-sided");
    vec3 n = scene_tri_ng(s, l->tri);
    CHECK(n.y < 0, "the light faces down into the room");
  }
  CHECK(lights == 2, "%d emissive triangles, expected 2 (one quad)", lights);
  CHECK(s->ntris == 36, "%u triangles: quads were not triangulated as expected", s->ntris);
  int red = 0;
  for (uint32_t m = 0; m < s->nmats; m++)
    if (!strcmp(s->mats[m].name, "leftWall")) { red = 1; CHECK(s->mats[m].type == MAT_DIFFUSE && fabsf(s->mats[m].kd.r - 0.63f) < 1e-6f, "leftWall"); }
  CHECK(red, "no leftWall material");
  CHECK(s->has_camera, "a camera was framed automatically");
  vec3 c = s->cam.look_at;
  CHECK(fabsf(c.x - s->center.x) < 1e-5f && fabsf(c.y - s->center.y) < 1e-5f, "auto camera looks at the centre");
  scene_free(s);

  rc = load_committed("scenes/cornell/CornellBox-Mirror.obj", &s);
  if (rc) return rc;
  int mirror = 0;
  for (uint32_t m = 0; m < s->nmats; m++)
    if (s->mats[m].type == MAT_MIRROR) { mirror = 1; CHECK(fabsf(s->mats[m].ks.r - 0.95f) < 1e-6f, "mirror Ks %g", s->mats[m].ks.r); }
  CHECK(mirror, "illum 5 did not become a mirror");
  scene_free(s);

  rc = load_committed("scenes/cornell/CornellBox-Sphere.obj", &s); /* rightSphere: illum 7, Ni 2.5 */
  if (rc) return rc;
  int glass = 0;
  for (uint32_t m = 0; m < s->nmats; m++)
    if (s->mats[m].type == MAT_DIELECTRIC) { glass = 1; CHECK(fabsf(s->mats[m].ior - 2.5f) < 1e-6f, "glass ior %g", s->mats[m].ior); }
  CHECK(glass, "illum 7 did not become a dielectric");
  scene_free(s);
  return 0;
}

static int gltf_and_ply_load(void) {
  scene *s;
  int rc = load_committed("scenes/damaged-helmet/glTF-Binary/DamagedHelmet.glb", &s);
  if (rc) return rc;
  /* 46 356 indices (the count ../shared/scenes/README.md gives) = 15 452 triangles. */
  CHECK(s->ntris == 15452, "helmet has %u triangles, expected 15452", s->ntris);
  scene_free(s);
  rc = load_committed("scenes/dragon/dragon_vrip_res4.ply", &s);
  if (rc) return rc;
  CHECK(s->ntris > 11000 && s->ntris <= 11102, "dragon res4 has %u triangles", s->ntris);
  scene_free(s);
  return 0;
}

/* A binary PLY whose data begins with a line feed (x of the first vertex is the float
 * 0xbf80000a, about -1, written little-endian): Assimp skips that byte after a header ending
 * "\n", so the loader hands it the header ending "\r\n"; the quad must load as written. */
static int ply_data_starting_with_line_feed(void) {
  static const uint32_t v[4][3] = {{0xbf80000au, 0xbf800000u, 0}, {0x3f800000u, 0xbf800000u, 0}, {0x3f800000u, 0x3f800000u, 0}, {0xbf800000u, 0x3f800000u, 0}};
  static const char head[] = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  unsigned char d[sizeof head + 48 + 26];
  size_t n = sizeof head - 1;
  memcpy(d, head, n);
  for (int i = 0; i < 4; i++)
    for (int k = 0; k < 3; k++)
      for (int b = 0; b < 4; b++) d[n++] = (unsigned char)(v[i][k] >> (8 * b));
  static const int f[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (int i = 0; i < 2; i++) {
    d[n++] = 3;
    for (int k = 0; k < 3; k++)
      for (int b = 0; b < 4; b++) d[n++] = (unsigned char)((uint32_t)f[i][k] >> (8 * b));
  }
  CHECK(d[sizeof head - 1] == '\n', "the data must start with a line feed");
  char path[1200];
  snprintf(path, sizeof path, "%s/lf_first.ply", scratch_dir());
  FILE *fp = fopen(path, "wb");
  CHECK(fp && fwrite(d, 1, n, fp) == n && fclose(fp) == 0, "cannot write %s", path);
  scene *s = scene_new(path);
  valo_error err;
  CHECK(load_mesh(s, path, NULL, UINT32_MAX, 1, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(s->ntris == 2 && s->nverts >= 4, "%u triangles, %u vertices (expected the quad's 2 and 4)", s->ntris, s->nverts);
  for (uint32_t t = 0; t < s->ntris; t++)
    for (int k = 0; k < 3; k++) {
      vec3 q = s->pos[s->idx[3 * t + k]];
      CHECK(fabsf(fabsf(q.x) - 1) < 1e-5f && fabsf(fabsf(q.y) - 1) < 1e-5f && q.z == 0, "triangle %u corner %d at (%g %g %g)", t, k, q.x, q.y, q.z);
    }
  scene_free(s);
  return 0;
}

/* glTF KHR_lights_punctual: a point light at (0,2,0) of colour (1,.5,.25) x 5, a spot at
 * (1,1,1) turned to point down with cones 0.2/0.5 rad, a directional light pointing down. */
static const char *LIGHTS_GLTF = "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"color\": [1, 0.5, 0.25], \"intensity\": 5}, {\"type\": \"spot\", \"intensity\": 2, \"spot\": {\"innerConeAngle\": 0.2, \"outerConeAngle\": 0.5}}, {\"type\": \"directional\", \"intensity\": 3}]}}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1, 2, 3]}], \"nodes\": [{\"mesh\": 0}, {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}, {\"translation\": [1, 1, 1], \"rotation\": [-0.7071068, 0, 0, 0.7071068], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}, {\"rotation\": [-0.7071068, 0, 0, 0.7071068], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1}]}], \"buffers\": [{\"byteLength\": 44, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}], \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}, {\"bufferView\": 1, \"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\"}]}";
static int gltf_lights(void) {
  const char *p = scratch_file("lights.gltf", LIGHTS_GLTF);
  scene *s = scene_new(p);
  valo_error err;
  CHECK(load_mesh(s, p, NULL, UINT32_MAX, 1, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(s->nlights == 3, "%u lights", s->nlights);
  const light *pt = &s->lights[0], *sp = &s->lights[1], *di = &s->lights[2];
  CHECK(pt->type == LIGHT_POINT && fabsf(pt->p.y - 2) < 1e-5f && fabsf(pt->L.r - 5) < 1e-5f && fabsf(pt->L.b - 1.25f) < 1e-5f,
        "point light: type %d at y %g, L (%g %g %g)", pt->type, pt->p.y, pt->L.r, pt->L.g, pt->L.b);
  CHECK(sp->type == LIGHT_SPOT && fabsf(sp->p.x - 1) < 1e-5f && fabsf(sp->dir.y + 1) < 1e-4f, "spot: type %d at (%g %g %g) dir (%g %g %g)",
        sp->type, sp->p.x, sp->p.y, sp->p.z, sp->dir.x, sp->dir.y, sp->dir.z);
  CHECK(fabsf(sp->cos_outer - cosf(0.5f)) < 1e-5f && fabsf(sp->cos_inner - cosf(0.2f)) < 1e-5f, "spot cones");
  CHECK(di->type == LIGHT_DIRECTIONAL && fabsf(di->dir.y + 1) < 1e-4f && fabsf(di->L.g - 3) < 1e-5f, "directional light");
  scene_free(s);
  return 0;
}

/* Material index by name in a loaded scene, or -1. */
static int mat_by_name(const scene *s, const char *name) {
  for (uint32_t i = 0; i < s->nmats; i++)
    if (!strcmp(s->mats[i].name, name)) return (int)i;
  return -1;
}

/* MTL's PBR extension: Pr is the microfacet alpha, Pm metallic; illum 3
 * metals with black Kd take Ks; map_Pr/map_Pm are read; Ps/Pc/Pcr/aniso are warned about
 * and do not stop the MTL parser (Assimp 5.2's stops at aniso). */
static int mtl_pbr_extension(void) {
  const char *p = shared_file("scenes/veach-mis/veach-mis.obj");
  if (!p) return TEST_SKIP;
  scene *s = scene_new(p);
  valo_error err;
  CHECK(load_mesh(s, p, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  static const struct { const char *name; float alpha; } plates[] = {
      {"SmoothBSDF", 0.01f}, {"GlossyBSDF", 0.05f}, {"RoughBSDF", 0.1f}, {"SuperRoughBSDF", 0.25f}};
  for (int i = 0; i < 4; i++) {
    int m = mat_by_name(s, plates[i].name);
    CHECK(m >= 0, "no material %s", plates[i].name);
    const material *mm = &s->mats[m];
    CHECK(mm->type == MAT_PBR, "%s: type %d, not pbr", plates[i].name, (int)mm->type);
    CHECK(fabsf(mm->roughness * mm->roughness - plates[i].alpha) < 1e-5f, "%s: alpha %g, expected %g", plates[i].name,
          mm->roughness * mm->roughness, plates[i].alpha);
    CHECK(mm->metallic == 1 && fabsf(mm->kd.r - 0.3f) < 1e-6f && mm->metal_flat, "%s: metallic %g, colour %g", plates[i].name,
          mm->metallic, mm->kd.r);
  }
  int d = mat_by_name(s, "DiffuseBSDF");
  CHECK(d >= 0 && s->mats[d].type == MAT_DIFFUSE, "DiffuseBSDF is not diffuse");
  scene_free(s);
  /* A hand-written MTL with every key of the extension. */
  unsigned char px[4] = {128, 128, 128, 255};
  char png[1200];
  snprintf(png, sizeof png, "%s/half.pfm", scratch_dir());
  FILE *f = fopen(png, "wb");
  CHECK(f, "cannot write %s", png);
  fprintf(f, "PF\n1 1\n-1\n");
  float half[3] = {0.25f, 0.25f, 0.25f};
  fwrite(half, sizeof half, 1, f);
  fclose(f);
  (void)px;
  scratch_file("pbr.mtl", "newmtl m\nKd 1 0 0\nPr .36\nPm 0.5\nPs 0.2\nPc 0.4\nPcr 0.1\naniso 0.3\nanisor 0\nmap_Pr half.pfm\n"
                          "map_Pm half.pfm\nnewmtl after\nKd 0 1 0\n");
  const char *obj = scratch_file("pbr.obj", "mtllib pbr.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\n"
                                            "f 1/1 2/2 3/3\nusemtl after\nf 1/1 3/3 2/2\n");
  s = scene_new(obj);
  CHECK(load_mesh(s, obj, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  int m = mat_by_name(s, "m"), a = mat_by_name(s, "after");
  CHECK(m >= 0 && a >= 0, "materials missing (m %d, after %d)", m, a);
  CHECK(s->mats[m].type == MAT_PBR && fabsf(s->mats[m].roughness - 0.6f) < 1e-6f && s->mats[m].metallic == 0.5f,
        "m: type %d roughness %g metallic %g", (int)s->mats[m].type, s->mats[m].roughness, s->mats[m].metallic);
  CHECK(fabsf(s->mats[m].kd.r - 1) < 1e-6f && s->mats[m].kd.g == 0, "m: Kd lost");
  CHECK(s->mats[m].tex_rough >= 0 && s->mats[m].tex_metal >= 0, "map_Pr/map_Pm not read");
  CHECK(s->mats[a].kd.g == 1 && s->mats[a].kd.r == 0, "the material after aniso lost its Kd (%g %g)", s->mats[a].kd.r, s->mats[a].kd.g);
  scene_free(s);
  return 0;
}

/* MTL statements before the first newmtl belong to no material: valo drops them (Assimp
 * 5.2 writes a texture statement there through a null material and crashes), and the
 * material after them loads as written. A comment is one line to the end, though Assimp
 * ends a line at a lone carriage return or a form feed too (the statements hidden after
 * them crashed it, or changed a colour). */
static int mtl_before_newmtl(void) {
  scratch_file("orphan.mtl", "# a texture before any material\nmap_Kd tex.png\nbump b.png\nKd 1 0 0\n# c\rmap_Kd cr.png\n"
                             "# c\fbump ff.png\nnewmtl m\nKd 0 1 0\n# c\rKd 1 0 0\n# c\fmap_Kd hidden.png\n");
  const char *obj = scratch_file("orphan.obj", "mtllib orphan.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n");
  scene *s = scene_new(obj);
  valo_error err;
  CHECK(load_mesh(s, obj, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  int m = mat_by_name(s, "m");
  CHECK(m >= 0 && s->ntris == 1, "material m %d, %u triangles", m, s->ntris);
  CHECK(s->mats[m].kd.g == 1 && s->mats[m].kd.r == 0 && s->mats[m].tex_kd < 0, "m: Kd (%g %g), texture %d", s->mats[m].kd.r,
        s->mats[m].kd.g, s->mats[m].tex_kd);
  scene_free(s);
  return 0;
}

/* Indented lines, which Assimp 5.2 skips whole in OBJ text and as an MTL's first line (a
 * vertex lost shifted every index after it; an indented first newmtl left the statements
 * after it to a null material): both load as written. */
static int obj_mtl_indented(void) {
  scratch_file("indent.mtl", "  newmtl m\n\tKd 0 1 0\n");
  const char *obj = scratch_file("indent.obj", "mtllib indent.mtl\nv 0 0 0\n  v 1 0 0\n\tv 0 1 0\n  usemtl m\n f 1 2 3\n");
  scene *s = scene_new(obj);
  valo_error err;
  CHECK(load_mesh(s, obj, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  int m = mat_by_name(s, "m");
  CHECK(s->ntris == 1 && m >= 0, "%u triangles, material m %d", s->ntris, m);
  CHECK(s->mats[m].kd.g == 1 && s->mats[m].kd.r == 0, "m: Kd (%g %g %g)", s->mats[m].kd.r, s->mats[m].kd.g, s->mats[m].kd.b);
  scene_free(s);
  return 0;
}

/* OBJ text Assimp 5.2 misreads or hides: numbers with a leading dot or a zero
 * in the exponent load with their values; faces with fewer than three vertices are
 * dropped, not fatal. */
static int obj_number_forms(void) {
  const char *obj = scratch_file("num.obj", "v 0 0 0\nv .8e-1 0 0\nv 0 1.0e-01 0\nv -.5 .25 +.5\nf 1 2 3\nf 1 2\nf 1 3 4\n");
  scene *s = scene_new(obj);
  valo_error err;
  CHECK(load_mesh(s, obj, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(s->ntris == 2, "%u triangles, expected 2 (the two-vertex face dropped)", s->ntris);
  int seen = 0;
  for (uint32_t i = 0; i < s->nverts; i++) {
    vec3 v = s->pos[i];
    if (fabsf(v.x - 0.08f) < 1e-7f && v.y == 0) seen |= 1;
    if (v.x == 0 && fabsf(v.y - 0.1f) < 1e-7f) seen |= 2;
    if (v.x == -0.5f && v.y == 0.25f && v.z == 0.5f) seen |= 4;
  }
  CHECK(seen == 7, "vertex values misread (mask %d)", seen);
  scene_free(s);
  return 0;
}

/* Silent fallbacks now warn, naming the file and what was done instead: maps
 * on a mesh without UVs, an unreadable MTL texture, a glTF camera without a usable field
 * of view, and autofocus whose centre ray hits nothing. */
static int fallback_warnings(void) {
  char png[1200];
  snprintf(png, sizeof png, "%s/paint.png", scratch_dir());
  const float px[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  valo_error err;
  CHECK(image_write(png, 2, 2, px, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scratch_file("nouv.mtl", "newmtl painted\nKd 1 1 1\nmap_Kd paint.png\nnewmtl lost\nKd 1 1 1\nmap_Kd missing-texture.png\n"), "write");
  const char *obj = scratch_file("nouv.obj", "mtllib nouv.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl painted\nf 1 2 3\nusemtl lost\nf 1 2 4\n");
  scene *s = scene_new(obj);
  warnings_capture(1);
  valo_status st = load_mesh(s, obj, NULL, UINT32_MAX, 1, NULL, &err);
  char said[4096];
  snprintf(said, sizeof said, "%s", warnings_text());
  warnings_capture(0);
  scene_free(s);
  CHECK(st == VALO_OK, "%s", err.message);
  CHECK(strstr(said, "missing-texture.png") && strstr(said, "ignored") && strstr(said, "material 'lost'"),
        "no warning naming the unreadable texture and the material asking for it: \"%s\"", said);
  CHECK(strstr(said, "nouv.obj") && strstr(said, "no texture coordinates") && strstr(said, "painted"), "no warning about maps without UVs: \"%s\"", said);
  /* a JSON sphere with a textured material: spheres carry an equirectangular layout
   * (scene_sphere_uv), so nothing is said */
  const char *sj = scratch_file("texsphere.json", "{ \"materials\": {\"painted\": {\"type\": \"diffuse\", \"reflectance\": \"paint.png\"}},\n"
                                                  "  \"shapes\": [{\"type\": \"sphere\", \"material\": \"painted\"}],\n"
                                                  "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n");
  valo_scene *vs = NULL;
  warnings_capture(1);
  st = valo_scene_load(sj, &vs, &err);
  snprintf(said, sizeof said, "%s", warnings_text());
  warnings_capture(0);
  if (vs) valo_scene_destroy(vs);
  CHECK(st == VALO_OK, "%s", err.message);
  CHECK(!strstr(said, "no texture coordinates"), "a warning about a textured sphere: \"%s\"", said);
  /* a glTF camera with yfov 0 (the triangle of LIGHTS_GLTF, seen by a camera node) */
  char gl[4096];
  snprintf(gl, sizeof gl, "%s", LIGHTS_GLTF);
  char *nodes = strstr(gl, "\"scenes\": [{\"nodes\": [0, 1, 2, 3]}], \"nodes\": [");
  CHECK(nodes, "template changed");
  char tail[4096];
  snprintf(tail, sizeof tail, "%s", nodes + strlen("\"scenes\": [{\"nodes\": [0, 1, 2, 3]}], \"nodes\": ["));
  snprintf(nodes, sizeof gl - (size_t)(nodes - gl),
           "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0, \"znear\": 0.1}}], "
           "\"scenes\": [{\"nodes\": [0, 1, 2, 3, 4]}], \"nodes\": [{\"camera\": 0, \"translation\": [0.3, 0.3, 2]}, %s",
           tail);
  const char *cpath = scratch_file("badcam.gltf", gl);
  s = scene_new(cpath);
  warnings_capture(1);
  st = load_mesh(s, cpath, NULL, UINT32_MAX, 1, NULL, &err);
  snprintf(said, sizeof said, "%s", warnings_text());
  warnings_capture(0);
  int has_cam = s->has_camera;
  scene_free(s);
  CHECK(st == VALO_OK, "%s", err.message);
  CHECK(strstr(said, "badcam.gltf") && strstr(said, "field of view"), "no warning about the camera's field of view: \"%s\" (camera %s)", said,
        has_cam ? "taken" : "not taken");
  /* autofocus with a lens (file cameras carry no focus distance), the centre ray into
   * the void: the same glTF, its camera moved off the triangle, with a usable fov */
  char *fov = strstr(gl, "\"yfov\": 0,"), *tr = strstr(gl, "\"translation\": [0.3, 0.3, 2]");
  CHECK(fov && tr, "template changed");
  memcpy(fov, "\"yfov\": 1,", strlen("\"yfov\": 1,"));
  memcpy(tr, "\"translation\": [3.0, 3.0, 2]", strlen("\"translation\": [3.0, 3.0, 2]"));
  const char *json = scratch_file("voidcam.gltf", gl);
  valo_options o;
  valo_options_init(&o);
  o.aperture_radius = 0.05;
  valo_scene *sc;
  CHECK(valo_scene_load(json, &sc, &err) == VALO_OK, "%s", err.message);
  valo_render *r = NULL;
  warnings_capture(1);
  st = valo_render_create(sc, &o, &r, &err);
  snprintf(said, sizeof said, "%s", warnings_text());
  warnings_capture(0);
  if (r) valo_render_destroy(r);
  valo_scene_destroy(sc);
  CHECK(st == VALO_OK, "%s", err.message);
  CHECK(strstr(said, "autofocus") && strstr(said, "voidcam.gltf"), "no autofocus warning: \"%s\"", said);
  return 0;
}

/* cam_view_project inverts cam_view_ray: a point along the ray through film point (fx, fy)
 * projects back to (fx, fy), for a perspective, an orthographic (the ray origins spread
 * over its plane) and a spherical camera; a point behind a perspective or orthographic
 * camera is not seen. */
static int camera_project_inverts_ray(void) {
  static const char *const kinds[3] = {"perspective", "orthographic", "spherical"};
  for (int kind = 0; kind < 3; kind++) {
    int ortho = kind == 1;
    camera c = {.pos = {1, 2, 3}, .look_at = {0.5f, 1.5f, -2}, .up = {0.1f, 1, 0}, .fov_deg = 35, .ortho_height = ortho ? 3.5f : 0,
                .spherical = kind == 2};
    cam_view v;
    CHECK(cam_view_make(&c, 120, 80, &v) == 0, "basis");
    double worst = 0;
    for (int i = 0; i < 1000; i++) {
      float fx = 120.0f * (float)((i * 37) % 1000) / 1000, fy = 80.0f * (float)((i * 91) % 1000) / 1000, t = 0.5f + (float)(i % 17);
      vec3 o, d;
      cam_view_ray(&v, fx, fy, &o, &d);
      if (ortho) CHECK(v3_dot(d, v.fwd) > 0.99999f, "an orthographic ray is not along the view axis");
      float gx, gy;
      CHECK(cam_view_project(&v, v3_add(o, v3_scale(d, t)), &gx, &gy), "a point along the ray through (%g, %g) is not seen", fx, fy);
      double dx = fabs(gx - fx);
      if (kind == 2) { /* longitudes wrap at the film's edges, and a pole has none */
        dx = fmin(dx, 120 - dx);
        if (fabs(fy - 40) > 39.9) dx = 0;
      }
      worst = fmax(worst, fmax(dx, fabs(gy - fy)));
      float hx, hy;
      CHECK(kind == 2 || !cam_view_project(&v, v3_sub(v.o, v3_scale(v.fwd, t)), &hx, &hy), "a point behind the camera is seen");
    }
    fprintf(stderr, "%s: largest film distance of a round trip %.2g px\n", kinds[kind], worst);
    CHECK(worst < 1e-3, "a round trip moved a film point by %g px", worst);
  }
  return 0;
}

/* A mesh file placed again from load_mesh_cached's kept import lands exactly as a second
 * reading of the file would: CornellBox-Original with its MTL materials and the bunny with
 * computed normals, each placed twice (turned and moved the second time), with a cache and
 * without, give the same vertices, normals, UVs, triangles and materials bit for bit; the
 * cache holds each file once. */
static int mesh_cache_places_alike(void) {
  const char *files[2] = {shared_file("scenes/cornell/CornellBox-Original.obj"), shared_file("scenes/models/stanford-bunny.obj")};
  if (!files[0] || !files[1]) return TEST_SKIP;
  static const float xf[2][12] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}, {0.6f, 0, -0.8f, 3, 0, 1, 0, -1, 0.8f, 0, 0.6f, 0.25f}};
  scene *s[2];
  valo_error err;
  mesh_cache *cache = NULL;
  for (int k = 0; k < 2; k++) {
    s[k] = scene_new("cache");
    for (int f = 0; f < 2; f++)
      for (int i = 0; i < 2; i++) {
        int flags = f ? LOAD_MESH_SMOOTH : 0;
        valo_status st = k ? load_mesh_cached(s[k], files[f], xf[i], UINT32_MAX, flags, NULL, &cache, &err)
                           : load_mesh(s[k], files[f], xf[i], UINT32_MAX, flags, NULL, &err);
        CHECK(st == VALO_OK, "%s", err.message);
      }
  }
  CHECK(s[0]->ntris == s[1]->ntris && s[0]->nverts == s[1]->nverts && s[0]->nmats == s[1]->nmats, "%u/%u triangles, %u/%u vertices, %u/%u materials",
        s[0]->ntris, s[1]->ntris, s[0]->nverts, s[1]->nverts, s[0]->nmats, s[1]->nmats);
  size_t nv = s[0]->nverts, nt = s[0]->ntris;
  CHECK(!memcmp(s[0]->pos, s[1]->pos, nv * sizeof(vec3)) && !memcmp(s[0]->nrm, s[1]->nrm, nv * sizeof(vec3)) &&
            !memcmp(s[0]->uv, s[1]->uv, nv * 2 * sizeof(float)),
        "vertices differ");
  CHECK(!memcmp(s[0]->idx, s[1]->idx, nt * 3 * sizeof(uint32_t)) && !memcmp(s[0]->tri_mat, s[1]->tri_mat, nt * sizeof(uint32_t)), "triangles differ");
  for (uint32_t m = 0; m < s[0]->nmats; m++)
    CHECK(!strcmp(s[0]->mats[m].name, s[1]->mats[m].name) && !memcmp(&s[0]->mats[m].emission, &s[1]->mats[m].emission, sizeof(rgb)) &&
              !memcmp(&s[0]->mats[m].kd, &s[1]->mats[m].kd, sizeof(rgb)),
          "material %u differs", m);
  /* the kept import is what is placed: a file removed after its first placement is placed again */
  const char *tmp = scratch_file("cache-tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  CHECK(load_mesh_cached(s[1], tmp, NULL, UINT32_MAX, 0, NULL, &cache, &err) == VALO_OK, "%s", err.message);
  remove(tmp);
  uint32_t before = s[1]->ntris;
  CHECK(load_mesh_cached(s[1], tmp, xf[1], UINT32_MAX, 0, NULL, &cache, &err) == VALO_OK && s[1]->ntris == before + 1, "not placed from the kept import: %s",
        err.message);
  mesh_cache_free(cache);
  scene_free(s[0]);
  scene_free(s[1]);
  return 0;
}

/* Plastics of one coat (index, roughness, distribution) share its tables: a material that
 * reuses another's has exactly the tables its own tabulation gives; another roughness has
 * its own. */
static int plastic_coats_shared(void) {
  const char *jp = scratch_file("plastics.json",
                                "{ \"materials\": {\"a\": {\"type\": \"plastic\", \"diffuse\": [0.8, 0.1, 0.1], \"roughness\": 0.4},\n"
                                "                \"b\": {\"type\": \"plastic\", \"diffuse\": [0.1, 0.8, 0.1], \"roughness\": 0.4},\n"
                                "                \"c\": {\"type\": \"plastic\", \"diffuse\": [0.1, 0.1, 0.8], \"roughness\": 0.5}},\n"
                                "  \"shapes\": [{\"type\": \"sphere\", \"material\": \"a\"}, {\"type\": \"sphere\", \"material\": \"b\", \"center\": [3, 0, 0]},\n"
                                "             {\"type\": \"sphere\", \"material\": \"c\", \"center\": [6, 0, 0]}] }\n");
  scene *s = scene_new(jp);
  valo_error err;
  CHECK(load_json(s, jp, NULL, &err) == VALO_OK, "%s", err.message);
  int checked = 0;
  for (uint32_t i = 0; i < s->nmats; i++) {
    material own = s->mats[i];
    if (own.type != MAT_PLASTIC) continue;
    plastic_prepare(&own);
    CHECK(!memcmp(own.coat_t, s->mats[i].coat_t, sizeof own.coat_t) && own.coat_ri == s->mats[i].coat_ri, "material %s: its coat's tables differ from its own",
          s->mats[i].name);
    checked++;
  }
  CHECK(checked == 3, "%d plastics", checked);
  scene_free(s);
  return 0;
}

/* The texture coordinates seen from +z at (x, y): the highest triangle facing +z there,
 * its UVs interpolated; 0 when none is. */
static int uv_seen_from_z(const scene *s, float x, float y, float *u, float *v) {
  float best_z = -INFINITY;
  for (uint32_t t = 0; t < s->ntris; t++) {
    const uint32_t *ix = &s->idx[3 * t];
    vec3 a = s->pos[ix[0]], b = s->pos[ix[1]], c = s->pos[ix[2]];
    float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(det > 1e-12f)) continue; /* facing away from +z, or edge-on */
    float l1 = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
    float l2 = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det, l0 = 1 - l1 - l2;
    float z = l0 * a.z + l1 * b.z + l2 * c.z;
    if (l0 < 0 || l1 < 0 || l2 < 0 || z < best_z) continue;
    best_z = z;
    *u = l0 * s->uv[2 * ix[0]] + l1 * s->uv[2 * ix[1]] + l2 * s->uv[2 * ix[2]];
    *v = l0 * s->uv[2 * ix[0] + 1] + l1 * s->uv[2 * ix[1] + 1] + l2 * s->uv[2 * ix[2] + 1];
  }
  return best_z > -INFINITY;
}

/* A sphere's texture coordinates in Mitsuba's layout (scene_sphere_uv), plain and turned by
 * a to_world of <rotate z 30/> then <rotate x 90/>, against Mitsuba 3.9.1's own
 * (scene.ray_intersect(Ray3f((x, y, 5), (0, 0, -1))).uv, v turned up): within the
 * icosphere's facets (subdivision 5) of the true sphere's. valo's own layout has +y at the
 * image's top: v 1 at the north pole, 0 at the south. */
static int mitsuba_sphere_uv(void) {
  static const struct { int turned; float x, y, u, v; } want[] = {
      {0, 0.3f, 0.4f, 0.147584f, 0.166667f}, {0, -0.5f, 0.2f, 0.439441f, 0.181015f}, {0, 0.1f, -0.7f, 0.772584f, 0.25f},
      {0, 0.6f, 0.6f, 0.125f, 0.322511f},    {1, 0.3f, 0.4f, 0.113593f, 0.63099f},    {1, -0.5f, 0.2f, 0.251901f, 0.564094f},
      {1, 0.1f, -0.7f, 0.144307f, 0.253183f}, {1, 0.6f, 0.6f, 0.0316934f, 0.704833f}};
  const float c = 0.8660254f, sn = 0.5f;
  const float plain[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, turned[9] = {c, -sn, 0, 0, 0, -1, sn, c, 0}; /* Rx(90) Rz(30) */
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    scene *s = scene_new("sphere-uv");
    valo_error err;
    CHECK(scene_add_sphere(s, v3(0, 0, 0), 1, 5, 0, 1, 0, &err) == VALO_OK, "%s", err.message);
    CHECK(scene_sphere_uv(s, 0, want[i].turned ? turned : plain) == VALO_OK, "layout");
    float u, v;
    int seen = uv_seen_from_z(s, want[i].x, want[i].y, &u, &v);
    scene_free(s);
    CHECK(seen && fabsf(u - want[i].u) < 2e-3f && fabsf(v - (1 - want[i].v)) < 2e-3f, "(%g, %g)%s: uv (%g, %g), Mitsuba's (%g, %g turned up)", want[i].x,
          want[i].y, want[i].turned ? " turned" : "", u, v, want[i].u, want[i].v);
  }
  scene *s = scene_new("sphere-uv");
  valo_error err;
  CHECK(scene_add_sphere(s, v3(0, 0, 0), 1, 3, 0, 1, 0, &err) == VALO_OK, "%s", err.message);
  float vmin = 2, vmax = -1;
  for (uint32_t k = 0; k < s->nverts; k++) {
    if (s->pos[k].y > 0.999f) vmax = fmaxf(vmax, s->uv[2 * k + 1]);
    if (s->pos[k].y < -0.999f) vmin = fminf(vmin, s->uv[2 * k + 1]);
  }
  scene_free(s);
  CHECK(vmax > 0.99f && vmin < 0.01f, "valo's layout: v %g at the north pole, %g at the south", vmax, vmin);
  return 0;
}

/* A sphere's texture coordinates at a point of its triangles are the layout's own at the
 * point's direction (both layouts, a coarse sphere of 80 triangles), not the vertices'
 * interpolated, which on such a sphere are 0.06 off, and by up to half the map beside a
 * pole (a texture showed the facets). */
static int sphere_uv_exact(void) {
  const float c = 0.8660254f, sn = 0.5f, turned[9] = {c, -sn, 0, 0, 0, -1, sn, c, 0};
  for (int k = 0; k < 2; k++) {
    scene *s = scene_new("sphere-uv");
    valo_error err;
    CHECK(scene_add_sphere(s, v3(1, 2, 3), 2, 1, 0, 1, 0, &err) == VALO_OK, "%s", err.message);
    if (k) CHECK(scene_sphere_uv(s, 0, turned) == VALO_OK, "layout");
    sampler sm = sampler_make(17, 0, 0);
    float worst = 0, worst_interp = 0;
    for (int i = 0; i < 4000; i++) {
      uint32_t t = sampler_u32(&sm) % s->ntris;
      float b1 = sampler_1d(&sm), b2 = sampler_1d(&sm);
      if (b1 + b2 > 1) { b1 = 1 - b1; b2 = 1 - b2; }
      const uint32_t *ix = &s->idx[3 * t];
      float b0 = 1 - b1 - b2;
      vec3 p = v3_add(v3_add(v3_scale(s->pos[ix[0]], b0), v3_scale(s->pos[ix[1]], b1)), v3_scale(s->pos[ix[2]], b2));
      vec3 d = v3_norm(v3_sub(p, v3(1, 2, 3)));
      float ue, ve;
      if (k) {
        vec3 l = v3(turned[0] * d.x + turned[3] * d.y + turned[6] * d.z, turned[1] * d.x + turned[4] * d.y + turned[7] * d.z,
                    turned[2] * d.x + turned[5] * d.y + turned[8] * d.z);
        ue = atan2f(l.y, l.x) / (2 * PI_F);
        ve = 1 - acosf(l.z) / PI_F;
      } else {
        ue = 0.5f + atan2f(d.z, d.x) / (2 * PI_F);
        ve = 1 - acosf(d.y) / PI_F;
      }
      if (fabsf(ve - 0.5f) > 0.45f) continue; /* u is undefined at the poles */
      float u, v;
      scene_tri_uv(s, t, b1, b2, &u, &v);
      float du = fabsf(u - ue);
      du = fminf(du, fabsf(du - 1));
      worst = fmaxf(worst, fmaxf(du, fabsf(v - ve)));
      float ui = b0 * s->uv[2 * ix[0]] + b1 * s->uv[2 * ix[1]] + b2 * s->uv[2 * ix[2]];
      float vi = b0 * s->uv[2 * ix[0] + 1] + b1 * s->uv[2 * ix[1] + 1] + b2 * s->uv[2 * ix[2] + 1];
      float dui = fabsf(ui - ue);
      dui = fminf(dui, fabsf(dui - 1));
      worst_interp = fmaxf(worst_interp, fmaxf(dui, fabsf(vi - ve)));
    }
    scene_free(s);
    fprintf(stderr, "%s layout: hit UVs within %.2g of the layout's at 4000 points (the vertices' interpolated: %.3f)\n", k ? "Mitsuba's" : "valo's",
            worst, worst_interp);
    CHECK(worst < 1e-4f, "%s layout: hit UVs %g off", k ? "Mitsuba's" : "valo's", worst);
    CHECK(worst_interp > 0.01f, "the interpolated UVs are within %g: the test cannot tell", worst_interp);
  }
  return 0;
}

/* The texture coordinates of Mitsuba's unit shapes as valo lays them out for a Mitsuba
 * scene (mitsuba_uv), at points seen from +z, against Mitsuba's own: Mitsuba 3.9.1's
 * scene.ray_intersect(Ray3f((x, y, 5), (0, 0, -1))).uv of a scene holding the shape alone,
 * its v turned up (valo's images run up from v = 0, Mitsuba's down). Without mitsuba_uv the
 * rectangle keeps v up the shape. */
static int mitsuba_primitive_uv(void) {
  static const struct { primitive_kind k; float x, y, u, v; } want[] = {
      {PRIM_RECTANGLE, 0.5f, -0.5f, 0.75f, 0.25f}, {PRIM_RECTANGLE, -0.5f, 0.2f, 0.25f, 0.6f}, {PRIM_RECTANGLE, 0.3f, 0.6f, 0.65f, 0.8f},
      {PRIM_DISK, 0.5f, -0.5f, 0.707107f, 0.875f},  {PRIM_DISK, -0.5f, 0.2f, 0.538517f, 0.439441f}, {PRIM_DISK, 0.3f, 0.6f, 0.67082f, 0.176208f},
      {PRIM_CUBE, 0.5f, -0.5f, 0.25f, 0.75f},       {PRIM_CUBE, -0.5f, 0.2f, 0.6f, 0.25f},          {PRIM_CUBE, 0.3f, 0.6f, 0.8f, 0.65f}};
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
    for (int mi = 0; mi < 2; mi++) {
      if (!mi && want[i].k != PRIM_RECTANGLE) continue;
      scene *s = scene_new("uv");
      valo_error err;
      CHECK(scene_add_primitive(s, want[i].k, NULL, 0, mi, 0, &err) == VALO_OK, "%s", err.message);
      float u, v;
      int seen = uv_seen_from_z(s, want[i].x, want[i].y, &u, &v);
      scene_free(s);
      CHECK(seen, "no face under (%g, %g)", want[i].x, want[i].y);
      float wu = want[i].u, wv = mi ? 1 - want[i].v : want[i].v;
      /* the disk's 256 flat segments: its radius within 1e-4, its angle within half a
       * segment (its centre's angle is the segment's middle) */
      float tol_v = want[i].k == PRIM_DISK ? 0.5f / 256 : 2e-4f;
      CHECK(fabsf(u - wu) < 2e-4f && fabsf(v - wv) < tol_v, "shape %d at (%g, %g)%s: uv (%g, %g), Mitsuba's (%g, %g)", (int)want[i].k, want[i].x,
            want[i].y, mi ? " with mitsuba_uv" : "", u, v, wu, wv);
    }
  /* Every corner of the cube, face by face: Mitsuba 3.9.1's cube mesh
   * (vertex_positions_buffer, vertex_texcoords_buffer), four corners a face. */
  static const float corners[6][4][5] = {
      {{1, -1, -1, 0, 1}, {1, -1, 1, 1, 1}, {-1, -1, 1, 1, 0}, {-1, -1, -1, 0, 0}}, {{1, 1, -1, 0, 1}, {-1, 1, -1, 1, 1}, {-1, 1, 1, 1, 0}, {1, 1, 1, 0, 0}},
      {{1, -1, -1, 0, 1}, {1, 1, -1, 1, 1}, {1, 1, 1, 1, 0}, {1, -1, 1, 0, 0}},     {{1, -1, 1, 0, 1}, {1, 1, 1, 1, 1}, {-1, 1, 1, 1, 0}, {-1, -1, 1, 0, 0}},
      {{-1, -1, 1, 0, 1}, {-1, 1, 1, 1, 1}, {-1, 1, -1, 1, 0}, {-1, -1, -1, 0, 0}}, {{1, 1, -1, 0, 1}, {1, -1, -1, 1, 1}, {-1, -1, -1, 1, 0}, {-1, 1, -1, 0, 0}}};
  scene *s = scene_new("cube");
  valo_error err;
  CHECK(scene_add_primitive(s, PRIM_CUBE, NULL, 0, 1, 0, &err) == VALO_OK, "%s", err.message);
  int checked = 0;
  for (uint32_t t = 0; t < s->ntris; t++) {
    const uint32_t *ix = &s->idx[3 * t];
    vec3 n = v3_cross(v3_sub(s->pos[ix[1]], s->pos[ix[0]]), v3_sub(s->pos[ix[2]], s->pos[ix[0]]));
    for (int k = 0; k < 3; k++) {
      vec3 q = s->pos[ix[k]];
      for (int f = 0; f < 6; f++) {
        /* the face whose corners share the coordinate the triangle's normal points along */
        const float *c0 = corners[f][0];
        int axis = fabsf(n.x) > 0.5f ? 0 : fabsf(n.y) > 0.5f ? 1 : 2;
        float side = axis == 0 ? n.x : axis == 1 ? n.y : n.z, cv = c0[axis];
        if (cv * side <= 0 || corners[f][1][axis] != cv || corners[f][2][axis] != cv) continue;
        for (int j = 0; j < 4; j++) {
          const float *e = corners[f][j];
          if (e[0] != q.x || e[1] != q.y || e[2] != q.z) continue;
          float u = s->uv[2 * ix[k]], v = s->uv[2 * ix[k] + 1];
          CHECK(u == e[3] && v == 1 - e[4], "cube corner (%g, %g, %g) of face %d: uv (%g, %g), Mitsuba's (%g, %g turned up)", q.x, q.y, q.z, f, u, v,
                e[3], e[4]);
          checked++;
        }
      }
    }
  }
  scene_free(s);
  CHECK(checked == 36, "%d of the cube's 36 triangle corners found among Mitsuba's", checked);
  return 0;
}

/* The cylinder (Mitsuba's, scene_cylinder_place): seen from +z at four points, its
 * texture coordinates and shading normals against Mitsuba 3.9.1's own
 * (scene.ray_intersect(Ray3f((x, y, 5), (0, 0, -1))): uv, sh_frame.n; v turned up) for
 * one along +x (Mitsuba's frame with n.z = 0) and one along -z, turned (n.z < 0), seen
 * outside and, through its open end, inside: within the 256 facets' chords. Its area within 0.01 % of 2 pi r h; flip_normals turns its
 * windings and normals in; the JSON refuses equal ends, p0 on a sphere and a centre. */
static vec3 normal_seen_from_z(const scene *s, float x, float y, float *u, float *v, int *found) {
  float best_z = -INFINITY;
  vec3 n = v3(0, 0, 0);
  for (uint32_t t = 0; t < s->ntris; t++) { /* front or back: an open tube is seen inside too */
    const uint32_t *ix = &s->idx[3 * t];
    vec3 a = s->pos[ix[0]], b = s->pos[ix[1]], c = s->pos[ix[2]];
    float det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(fabsf(det) > 1e-12f)) continue;
    float l1 = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
    float l2 = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det, l0 = 1 - l1 - l2;
    float z = l0 * a.z + l1 * b.z + l2 * c.z;
    if (l0 < 0 || l1 < 0 || l2 < 0 || z < best_z) continue;
    best_z = z;
    n = v3_norm(v3_add(v3_add(v3_scale(s->nrm[ix[0]], l0), v3_scale(s->nrm[ix[1]], l1)), v3_scale(s->nrm[ix[2]], l2)));
    *u = l0 * s->uv[2 * ix[0]] + l1 * s->uv[2 * ix[1]] + l2 * s->uv[2 * ix[2]];
    *v = l0 * s->uv[2 * ix[0] + 1] + l1 * s->uv[2 * ix[1] + 1] + l2 * s->uv[2 * ix[2] + 1];
  }
  *found = best_z > -INFINITY;
  return n;
}

static int cylinder_shape(void) {
  static const struct { float p0[3], p1[3], r, x, y, u, v, n[3]; } want[] = {
      {{-1, 0, 0}, {1, 0, 0}, 1, 0.3f, 0.4f, 0.434505f, 0.65f, {0, 0.4f, 0.916515f}},
      {{-1, 0, 0}, {1, 0, 0}, 1, -0.5f, -0.2f, 0.532047f, 0.25f, {0, -0.2f, 0.979796f}},
      {{0.2f, -0.3f, 0.5f}, {0.4f, 0.2f, -1.5f}, 0.8f, -0.5f, -0.2f, 0.474967f, 0.424453f, {-0.981113f, -0.140283f, -0.133182f}},
      {{0.2f, -0.3f, 0.5f}, {0.4f, 0.2f, -1.5f}, 0.8f, 0.1f, 0.7f, 0.712027f, 0.486932f, {-0.246733f, 0.945668f, 0.211744f}}};
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    scene *s = scene_new("cylinder");
    valo_error err;
    float xf[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    vec3 p0 = v3(want[i].p0[0], want[i].p0[1], want[i].p0[2]), p1 = v3(want[i].p1[0], want[i].p1[1], want[i].p1[2]);
    scene_cylinder_place(p0, p1, want[i].r, xf);
    CHECK(scene_add_primitive(s, PRIM_CYLINDER, xf, 0, 1, 0, &err) == VALO_OK, "%s", err.message);
    float u = 0, v = 0;
    int found;
    vec3 n = normal_seen_from_z(s, want[i].x, want[i].y, &u, &v, &found);
    double area = 0;
    for (uint32_t t = 0; t < s->ntris; t++) area += 0.5 * v3_len(scene_tri_ng(s, t));
    scene_free(s);
    CHECK(found, "no surface under (%g, %g)", want[i].x, want[i].y);
    /* a chord lies up to 7.5e-5 r inside the circle, which moves a grazing hit (the inside
     * of the tube along -z, 7.6 degrees from its wall) along the axis: v within 1e-3 */
    CHECK(fabsf(u - want[i].u) < 2e-4f && fabsf(v - (1 - want[i].v)) < 1e-3f, "cylinder %zu at (%g, %g): uv (%g, %g), Mitsuba's (%g, %g turned up)", i,
          want[i].x, want[i].y, u, v, want[i].u, want[i].v);
    CHECK(fabsf(n.x - want[i].n[0]) < 2e-4f && fabsf(n.y - want[i].n[1]) < 2e-4f && fabsf(n.z - want[i].n[2]) < 2e-4f,
          "cylinder %zu at (%g, %g): normal (%g %g %g), Mitsuba's (%g %g %g)", i, want[i].x, want[i].y, n.x, n.y, n.z, want[i].n[0], want[i].n[1], want[i].n[2]);
    double exact = 2 * M_PI * want[i].r * v3_len(v3_sub(p1, p0));
    CHECK(fabs(area / exact - 1) < 1e-4, "cylinder %zu: area %g, 2 pi r h %g", i, area, exact);
  }
  /* flipped: every winding normal and every vertex normal points at the axis (z) */
  scene *s = scene_new("flipped");
  valo_error err;
  CHECK(scene_add_primitive(s, PRIM_CYLINDER, NULL, 1, 0, 0, &err) == VALO_OK, "%s", err.message);
  for (uint32_t t = 0; t < s->ntris; t++) {
    const uint32_t *ix = &s->idx[3 * t];
    vec3 c = v3_scale(v3_add(v3_add(s->pos[ix[0]], s->pos[ix[1]]), s->pos[ix[2]]), 1.0f / 3), ng = scene_tri_ng(s, t);
    CHECK(ng.x * c.x + ng.y * c.y < 0 && s->nrm[ix[0]].x * s->pos[ix[0]].x + s->nrm[ix[0]].y * s->pos[ix[0]].y < 0, "triangle %u faces out", t);
  }
  scene_free(s);
  static const struct { const char *shape, *says; } bad[] = {
      {"{\"type\": \"cylinder\", \"p0\": [1, 2, 3], \"p1\": [1, 2, 3]}", "p0 and p1 must differ"},
      {"{\"type\": \"sphere\", \"p0\": [0, 0, 0]}", "\"p0\" and \"p1\" are a cylinder's"},
      {"{\"type\": \"cylinder\", \"center\": [0, 0, 0]}", "a cylinder takes no \"center\""},
      {"{\"type\": \"cylinder\", \"radius\": -1}", "radius"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char json[512];
    snprintf(json, sizeof json, "{\"shapes\": [%s], \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 1}]}", bad[i].shape);
    scene *sc = NULL;
    valo_options file;
    CHECK(scene_load(scratch_file("badcyl.json", json), NULL, &sc, &file, &err) != VALO_OK, "loaded %s", bad[i].shape);
    CHECK(strstr(err.message, bad[i].says) && strstr(err.message, "shapes[0]"), "%s: \"%s\" does not say \"%s\"", bad[i].shape, err.message, bad[i].says);
  }
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"mtl_pbr_extension", mtl_pbr_extension}, {"cylinder_shape", cylinder_shape}, {"obj_number_forms", obj_number_forms},
                                    {"mtl_before_newmtl", mtl_before_newmtl},
                                    {"obj_mtl_indented", obj_mtl_indented},
                                    {"head_normals_unit", head_normals_unit}, {"transform_order", transform_order},
                                    {"mtl_meanings", mtl_meanings}, {"gltf_and_ply_load", gltf_and_ply_load}, {"gltf_lights", gltf_lights}, {"ply_data_starting_with_line_feed", ply_data_starting_with_line_feed}, {"fallback_warnings", fallback_warnings},
                                    {"camera_project_inverts_ray", camera_project_inverts_ray}, {"mesh_cache_places_alike", mesh_cache_places_alike},
                                    {"mitsuba_primitive_uv", mitsuba_primitive_uv},
                                    {"mitsuba_sphere_uv", mitsuba_sphere_uv}, {"sphere_uv_exact", sphere_uv_exact}, {"plastic_coats_shared", plastic_coats_shared}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
