/* test_texture.c — textures: texel-exact bilinear lookups at texel centres of the
 * DamagedHelmet's base-colour map (embedded in the .glb and beside the .gltf), sRGB
 * decoding against the raw 8-bit values, wrap modes, and alpha cutout honoured by camera
 * and shadow rays alike on the kd-tree and on Embree. */
#include "harness.h"
#include "load/load.h"
#include "scene/scene.h"
#include "image/texture.h"
#include "image/image_io.h"
#include "material/shading.h"
#include "material/bsdf.h"
#include "material/sheen.h"
#include <stb_image.h>
#include <stb_image_write.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A 10 x 10 floor at y = 0, facing up (its own OBJ). */
#define FLOOR_OBJ "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\n"
/* floors at y = 0 with texture coordinates (u along +z, v along +x), 2 and 10 units wide */
#define UV_QUAD_2 "v -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
#define UV_QUAD_10 "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
/* Writes a PNG of w x h pixels of n channels into the scratch folder: 1 on success. */
static int scratch_png(const char *name, int w, int h, int n, const unsigned char *px) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", scratch_dir(), name);
  return stbi_write_png(path, w, h, n, px, w * n) != 0;
}
/* The material of that name, or NULL. */
static const material *material_named(const scene *s, const char *name) {
  for (uint32_t m = 0; m < s->nmats; m++)
    if (!strcmp(s->mats[m].name, name)) return &s->mats[m];
  return NULL;
}

static float srgb_dec(int b) { float c = b / 255.0f; return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f); }

static int helmet_texels(const char *rel) {
  const char *p = shared_file(rel), *jpg = shared_file("scenes/damaged-helmet/glTF/Default_albedo.jpg");
  if (!p || !jpg) return TEST_SKIP;
  scene *s = scene_new(p);
  valo_error err;
  CHECK(load_mesh(s, p, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  int kd = s->mats[s->tri_mat[0]].tex_kd;
  CHECK(kd >= 0, "no base colour texture");
  const texture *t = &s->tex[kd];
  int w, h, n;
  unsigned char *raw = stbi_load(jpg, &w, &h, &n, 3);
  CHECK(raw && t->w == w && t->h == h, "texture %dx%d vs file %dx%d", t->w, t->h, w, h);
  /* At texel centres the bilinear lookup returns the texel itself, v = 0 at the bottom. */
  int xs[5] = {0, 17, 1024, 1500, 2047}, ys[5] = {0, 2047, 333, 1024, 5};
  for (int i = 0; i < 5; i++) {
    float u = (xs[i] + 0.5f) / w, v = 1 - (ys[i] + 0.5f) / h, px[4];
    texture_lookup(t, u, v, px);
    for (int c = 0; c < 3; c++) {
      float expect = srgb_dec(raw[3 * (ys[i] * w + xs[i]) + c]);
      CHECK(fabsf(px[c] - expect) < 1e-6f, "texel (%d,%d) channel %d: %g, expected %g", xs[i], ys[i], c, px[c], expect);
    }
  }
  stbi_image_free(raw);
  /* The metallic-roughness map: linear (no sRGB decoding), G = roughness, B = metallic,
   * texel-exact too; the material is the glTF metallic-roughness model. */
  const material *m = &s->mats[s->tri_mat[0]];
  const char *mrjpg = shared_file("scenes/damaged-helmet/glTF/Default_metalRoughness.jpg");
  CHECK(m->type == MAT_PBR && m->tex_mr >= 0 && mrjpg, "no metallic-roughness material or map");
  t = &s->tex[m->tex_mr];
  raw = stbi_load(mrjpg, &w, &h, &n, 3);
  CHECK(raw && t->w == w && t->h == h, "metallic-roughness map %dx%d vs file %dx%d", t->w, t->h, w, h);
  for (int i = 0; i < 5; i++) {
    float u = (xs[i] + 0.5f) / w, v = 1 - (ys[i] + 0.5f) / h, px[4];
    texture_lookup(t, u, v, px);
    for (int c = 1; c < 3; c++) {
      float expect = raw[3 * (ys[i] * w + xs[i]) + c] / 255.0f;
      CHECK(fabsf(px[c] - expect) < 1e-6f, "metallic-roughness texel (%d,%d) channel %d: %g, expected %g", xs[i], ys[i], c, px[c], expect);
    }
  }
  stbi_image_free(raw);
  /* Emissive map present too. */
  CHECK(s->mats[s->tri_mat[0]].tex_ke >= 0, "no emissive texture");
  scene_free(s);
  return 0;
}
static int helmet_glb_texels(void) { return helmet_texels("scenes/damaged-helmet/glTF-Binary/DamagedHelmet.glb"); }
static int helmet_gltf_texels(void) { return helmet_texels("scenes/damaged-helmet/glTF/DamagedHelmet.gltf"); }

static int wrap_modes(void) {
  texture t;
  memset(&t, 0, sizeof t);
  t.w = 4; t.h = 1;
  float px[16] = {0, 0, 0, 1, 1, 1, 1, 1, 2, 2, 2, 1, 3, 3, 3, 1};
  t.px = px;
  float o[4];
  t.smp.wrap = TEX_REPEAT;
  texture_lookup(&t, 1.125f, 0.5f, o); /* texel 0 again */
  CHECK(fabsf(o[0] - 0) < 1e-6f, "repeat: %g", o[0]);
  t.smp.wrap = TEX_CLAMP;
  texture_lookup(&t, 1.125f, 0.5f, o);
  CHECK(fabsf(o[0] - 3) < 1e-6f, "clamp: %g", o[0]);
  t.smp.wrap = TEX_MIRROR;
  texture_lookup(&t, 1.125f, 0.5f, o); /* mirrored: texel 3 */
  CHECK(fabsf(o[0] - 3) < 1e-6f, "mirror: %g", o[0]);
  texture_lookup(&t, -0.125f, 0.5f, o);
  CHECK(fabsf(o[0] - 0) < 1e-6f, "mirror below 0: %g", o[0]);
  t.smp.wrap = TEX_REPEAT;
  texture_lookup(&t, 0.25f, 0.5f, o); /* halfway between texel 0 and 1 */
  CHECK(fabsf(o[0] - 0.5f) < 1e-6f, "bilinear: %g", o[0]);
  return 0;
}

/* A quad with a fully transparent alpha map hides nothing: camera rays pass through it,
 * and a floor in its shadow is lit as if it were absent. A fully opaque map blocks. */
static double cutout_mean(const char *backend, int alpha, int with_quad) {
  unsigned char rgba[4 * 4 * 4];
  for (int i = 0; i < 16; i++) { rgba[4 * i] = 200; rgba[4 * i + 1] = 20; rgba[4 * i + 2] = 20; rgba[4 * i + 3] = (unsigned char)alpha; }
  char png[1200];
  snprintf(png, sizeof png, "%s/alpha%d.png", scratch_dir(), alpha);
  if (!stbi_write_png(png, 4, 4, 4, rgba, 16)) return -1;
  char mtl[256];
  snprintf(mtl, sizeof mtl, "newmtl leaf\nKd 0 0 0\nmap_Kd alpha%d.png\nmap_d alpha%d.png\n", alpha, alpha);
  char name[64];
  snprintf(name, sizeof name, "leaf%d.mtl", alpha);
  scratch_file(name, mtl);
  char obj[512];
  snprintf(obj, sizeof obj,
           "mtllib leaf%d.mtl\nv -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl leaf\nf 1/1 2/2 3/3 4/4\n", alpha);
  snprintf(name, sizeof name, "leaf%d.obj", alpha);
  scratch_file(name, obj);
  scratch_file("floor.obj", FLOOR_OBJ);
  char json[1024];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,4,0.01], \"look_at\": [0,0,0], \"fov\": 30},\n"
           "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 4, \"max_depth\": 1, \"accel\": \"%s\"},\n"
           "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
           "  \"shapes\": [{\"file\": \"floor.obj\", \"material\": \"floor\"}%s%s%s],\n"
           "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
           backend, with_quad ? ", {\"file\": \"leaf" : "", with_quad ? (alpha ? "255" : "0") : "", with_quad ? ".obj\"}" : "");
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  if (!px) return -1;
  double s = 0;
  for (int i = 0; i < w * h * 3; i++) s += px[i];
  free(px);
  return s / (w * h * 3);
}

static int alpha_cutout(void) {
  const char *kinds[2] = {"kdtree", "embree"};
  for (int k = 0; k < 2; k++) {
    double none = cutout_mean(kinds[k], 0, 0), clear = cutout_mean(kinds[k], 0, 1), opaque = cutout_mean(kinds[k], 255, 1);
    fprintf(stderr, "%s: floor alone %.5f, behind a transparent quad %.5f, behind an opaque quad %.5f\n", kinds[k], none, clear, opaque);
    CHECK(none > 0 && clear >= 0 && opaque >= 0, "render failed");
    CHECK(fabs(clear - none) < 1e-6, "%s: a fully transparent quad changed the image (%g vs %g)", kinds[k], clear, none);
    CHECK(opaque < 0.5 * none, "%s: an opaque quad should shadow and hide the floor (%g vs %g)", kinds[k], opaque, none);
  }
  return 0;
}

/* The normal AOV at the centre of an 8x8 render of `json` (scratch file name). */
static int centre_normal(const char *name, const char *json, float out[3]) {
  const char *path = scratch_file(name, json);
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  CHECK(r, "render failed");
  image im;
  int rc = read_aov(r, "normal", &im);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  CHECK(rc == 0, "cannot write or read the normal AOV");
  memcpy(out, &im.rgb[3 * (4 * 8 + 4)], 3 * sizeof(float));
  image_free(&im);
  return 0;
}

/* Normal maps: a quad facing the camera (u along +x, v along +y) with a constant map
 * tilting the normal 30 degrees towards +u, then towards +v, shows that normal in the
 * normal AOV (to 8-bit precision). */
/* A normal tilted 30 degrees refuses directions in the wedge between the shading and the
 * geometric hemisphere: 30/360 = 8.3 % of uniformly spread light samples, a little more
 * of the BSDF's (measured 10.2 % with the normal map, 8.6 % with the bump map). */
#define TILT_LOSS 0.15
static int normal_map(void) {
  allow_shading_loss(TILT_LOSS);
  CHECK(scratch_file("nquad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"), "write");
  float th = 30.0f * 3.14159265f / 180;
  for (int axis = 0; axis < 2; axis++) {
    float n[3] = {axis == 0 ? sinf(th) : 0, axis == 1 ? sinf(th) : 0, cosf(th)};
    unsigned char bytes[4 * 4 * 3];
    for (int i = 0; i < 16; i++)
      for (int c = 0; c < 3; c++) bytes[3 * i + c] = (unsigned char)lrintf((n[c] * 0.5f + 0.5f) * 255);
    char png[1200];
    snprintf(png, sizeof png, "%s/nmap%d.png", scratch_dir(), axis);
    CHECK(stbi_write_png(png, 4, 4, 3, bytes, 12), "png");
    char json[1024];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 20},\n"
             "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 2},\n"
             "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, \"normal_map\": \"nmap%d.png\"}},\n"
             "  \"shapes\": [{\"file\": \"nquad.obj\", \"material\": \"m\"}],\n"
             "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n", axis);
    float c[3];
    if (centre_normal("nmap.json", json, c)) return 1;
    fprintf(stderr, "map tilted towards %s: normal (%.4f %.4f %.4f), expected (%.4f %.4f %.4f)\n", axis ? "+v" : "+u", c[0], c[1], c[2], n[0], n[1], n[2]);
    for (int k = 0; k < 3; k++) CHECK(fabsf(c[k] - n[k]) < 0.01f, "normal component %d: %g vs %g", k, c[k], n[k]);
  }
  return 0;
}

/* Bump maps: the same quad (2 units across, so dp/du = (2,0,0)) under a 16x16 grey
 * height ramp rising by 16/255 per texel along u (then along v). Displaced by
 * scale * height, the surface rises with slope scale * (256/255) / 2 per unit, so its
 * normal tilts away from the rise by atan of that: 30 degrees for the scale below.
 * Checked from JSON (bump_map, bump_scale) and from MTL (map_bump -bm); scale 0 and a
 * flat map leave the normal alone. */
static int bump_map(void) {
  allow_shading_loss(TILT_LOSS);
  CHECK(scratch_file("nquad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"), "write");
  double th = 30.0 * M_PI / 180, scale = 2 * tan(th) * 255.0 / 256.0;
  for (int axis = 0; axis < 3; axis++) { /* 0: ramp in u, 1: ramp in v, 2: flat */
    unsigned char bytes[16 * 16];
    for (int y = 0; y < 16; y++)
      for (int x = 0; x < 16; x++) bytes[16 * y + x] = (unsigned char)(axis == 0 ? 16 * x + 8 : axis == 1 ? 16 * (15 - y) + 8 : 128);
    char png[1200];
    snprintf(png, sizeof png, "%s/ramp%d.png", scratch_dir(), axis);
    CHECK(stbi_write_png(png, 16, 16, 1, bytes, 16), "png");
    float n[3] = {axis == 0 ? (float)-sin(th) : 0, axis == 1 ? (float)-sin(th) : 0, axis == 2 ? 1 : (float)cos(th)};
    for (int form = 0; form < 3; form++) { /* JSON, MTL, JSON with scale 0 */
      char json[1024], mtl[300], obj[300];
      const char *mat = "";
      if (form == 1) {
        snprintf(mtl, sizeof mtl, "newmtl m\nKd 0.5 0.5 0.5\nmap_bump -bm %.6f ramp%d.png\n", scale, axis);
        CHECK(scratch_file("bquad.mtl", mtl), "write");
        snprintf(obj, sizeof obj, "mtllib bquad.mtl\nusemtl m\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n");
        CHECK(scratch_file("bquad.obj", obj), "write");
      } else mat = ", \"material\": \"m\"";
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 20},\n"
               "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 2},\n"
               "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, \"bump_map\": \"ramp%d.png\", \"bump_scale\": %.6f}},\n"
               "  \"shapes\": [{\"file\": \"%s\"%s}],\n"
               "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n",
               axis, form == 2 ? 0.0 : scale, form == 1 ? "bquad.obj" : "nquad.obj", mat);
      float c[3];
      if (centre_normal("bump.json", json, c)) return 1;
      float e[3] = {n[0], n[1], n[2]};
      if (form == 2) { e[0] = 0; e[1] = 0; e[2] = 1; }
      fprintf(stderr, "ramp %s, %s: normal (%.4f %.4f %.4f), expected (%.4f %.4f %.4f)\n", axis == 0 ? "in u" : axis == 1 ? "in v" : "flat",
              form == 0 ? "JSON" : form == 1 ? "MTL -bm" : "scale 0", c[0], c[1], c[2], e[0], e[1], e[2]);
      for (int k = 0; k < 3; k++) CHECK(fabsf(c[k] - e[k]) < 0.01f, "normal component %d: %g vs %g", k, c[k], e[k]);
    }
  }
  return 0;
}

/* glTF metallic-roughness per texel: a quad whose 2x1 metallic-roughness map is metal
 * with roughness 0 on the left (B = 255, G = 0) and a rough dielectric on the right
 * (B = 0, G = 255), lit by a point light off to the side. The mirror-like left half
 * reflects nothing towards the camera; the right half is diffusely lit. Checked for the
 * glTF file (factors 1 x texels, clamped by its sampler) and for the JSON "pbr" material. */
static const char gltf_mr_quad[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1, \"TEXCOORD_0\": 2}, \"indices\": 3, \"material\": 0}]}],\n"
    " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, 1], \"metallicFactor\": 1, \"roughnessFactor\": 1,\n"
    "                 \"metallicRoughnessTexture\": {\"index\": 0}}}],\n"
    " \"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{\"wrapS\": 33071, \"wrapT\": 33071}], \"images\": [{\"uri\": \"mr.png\"}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1,-1,0], \"max\": [1,1,0]},\n"
    "               {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"},\n"
    "               {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},\n"
    "               {\"bufferView\": 3, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 48},\n"
    "                 {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 32}, {\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 12}],\n"
    " \"buffers\": [{\"byteLength\": 140, \"uri\": \"data:application/octet-stream;base64,"
    "AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/"
    "AAAAAAAAAAAAAIA/AAAAAAAAgD8AAIA/AACAPwAAgD8AAAAAAAAAAAAAAAAAAAEAAgAAAAIAAwA=\"}]}\n";
static int gltf_metallic_roughness(void) {
  unsigned char mr[6] = {0, 0, 255, 0, 255, 0};
  char png[1200];
  snprintf(png, sizeof png, "%s/mr.png", scratch_dir());
  CHECK(stbi_write_png(png, 2, 1, 3, mr, 6), "png");
  /* JSON textures repeat, so the JSON material gets a 4x1 map (two texels per half). */
  unsigned char mr4[12] = {0, 0, 255, 0, 0, 255, 0, 255, 0, 0, 255, 0};
  snprintf(png, sizeof png, "%s/mr4.png", scratch_dir());
  CHECK(stbi_write_png(png, 4, 1, 3, mr4, 12), "png");
  CHECK(scratch_file("mr_quad.gltf", gltf_mr_quad), "write");
  for (int form = 0; form < 2; form++) {
    char json[1200];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 30},\n"
             "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 64},\n"
             "  %s\"shapes\": [{\"file\": \"mr_quad.gltf\"%s}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [3,0,2], \"intensity\": 10}] }\n",
             form ? "\"materials\": {\"m\": {\"type\": \"pbr\", \"base_color\": 0.8, \"metallic\": 1, \"roughness\": 1, "
                    "\"metallic_roughness_map\": \"mr4.png\"}},\n  " : "",
             form ? ", \"material\": \"m\"" : "");
    int w, h;
    float *px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "render failed");
    /* Columns 4-5 see only texel 0 (u < 0.25, clamped), 26-27 only texel 1; rows 14-17. */
    double left = 0, right = 0;
    for (int y = 14; y < 18; y++)
      for (int k = 0; k < 2; k++) { left += px[3 * (y * w + 4 + k) + 1]; right += px[3 * (y * w + 26 + k) + 1]; }
    free(px);
    fprintf(stderr, "%s: metal (roughness 0) half %.5f, rough dielectric half %.5f\n", form ? "JSON pbr" : "glTF", left / 8, right / 8);
    CHECK(right / 8 > 0.05, "the rough dielectric half should be lit (%g)", right / 8);
    CHECK(left < 0.01 * right, "the mirror-like metal half should reflect no light towards the camera (%g vs %g)", left / 8, right / 8);
  }
  return 0;
}

/* MTL map_Ns multiplies the Phong exponent: Ns 250 with a map of value 0.2 (51/255)
 * renders as Ns 50 (to float rounding), and differs clearly from Ns 250 alone. */
static float *phong_quad(const char *mtl_body) {
  char mtl[300];
  snprintf(mtl, sizeof mtl, "newmtl m\nKd 0.3 0.3 0.3\nKs 0.5 0.5 0.5\nillum 2\n%s", mtl_body);
  if (!scratch_file("nsquad.mtl", mtl)) return NULL;
  if (!scratch_file("nsquad.obj", "mtllib nsquad.mtl\nusemtl m\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                  "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"))
    return NULL;
  int w, h;
  return render_json_text("{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 30},\n"
                          "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 64},\n"
                          "  \"shapes\": [{\"file\": \"nsquad.obj\"}],\n"
                          "  \"lights\": [{\"type\": \"point\", \"position\": [0.3,0,3], \"intensity\": 5}] }\n",
                          NULL, &w, &h);
}
static int phong_exponent_map(void) {
  unsigned char v[4 * 4];
  memset(v, 51, sizeof v);
  char png[1200];
  snprintf(png, sizeof png, "%s/ns.png", scratch_dir());
  CHECK(stbi_write_png(png, 4, 4, 1, v, 4), "png");
  float *mapped = phong_quad("Ns 250\nmap_Ns ns.png\n"), *ns50 = phong_quad("Ns 50\n"), *ns250 = phong_quad("Ns 250\n");
  CHECK(mapped && ns50 && ns250, "render failed");
  double d50 = 0, d250 = 0, peak = 0;
  for (int i = 0; i < 16 * 16 * 3; i++) {
    d50 = fmax(d50, fabs(mapped[i] - ns50[i]));
    d250 = fmax(d250, fabs(mapped[i] - ns250[i]));
    peak = fmax(peak, ns50[i]);
  }
  free(mapped); free(ns50); free(ns250);
  fprintf(stderr, "Ns 250 x map 0.2 against Ns 50: max difference %.5f; against Ns 250: %.5f (peak %.4f)\n", d50, d250, peak);
  CHECK(d50 < 0.01 * peak, "map_Ns should give exponent 50 (max difference %g of peak %g)", d50, peak);
  CHECK(d250 > 0.2 * peak, "map_Ns had no effect (difference from Ns 250 only %g)", d250);
  return 0;
}

/* A UV sphere as OBJ text (positions, normals, UVs), n segments around, n/2 rings. */
static char *uv_sphere_obj(int n) {
  size_t cap = (size_t)n * n * 160 + 256, len = 0;
  char *t = malloc(cap);
  if (!t) return NULL;
  int rings = n / 2;
  for (int j = 0; j <= rings; j++)
    for (int i = 0; i <= n; i++) {
      double th = M_PI * j / rings, ph = 2 * M_PI * i / n;
      double x = sin(th) * cos(ph), y = cos(th), z = sin(th) * sin(ph);
      len += (size_t)snprintf(t + len, cap - len, "v %.6f %.6f %.6f\nvn %.6f %.6f %.6f\nvt %.6f %.6f\n", x, y, z, x, y, z, (double)i / n,
                              1 - (double)j / rings);
    }
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < n; i++) {
      int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
      if (j > 0) len += (size_t)snprintf(t + len, cap - len, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, a, a, c, c, c, b, b, b); /* not at a pole */
      if (j < rings - 1) len += (size_t)snprintf(t + len, cap - len, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", b, b, b, c, c, c, d, d, d);
    }
  return t;
}

/* The stress scene: rough glass (roughness 0.3 and 0.01), a thin pane and a near-mirror
 * rough metal, all under a normal map of random normals tilted up to 70 degrees, on a
 * normal-mapped floor seen at grazing angles, lit by a small area light and an
 * environment. Every integrator must finish it with no NaN, infinite or negative sample
 * and no non-finite BSDF sample (the shading-normal refusals such maps cause are allowed). */
static int stress_no_nan(void) {
  char *sph = uv_sphere_obj(48);
  CHECK(sph && scratch_file("usphere.obj", sph), "write");
  free(sph);
  CHECK(scratch_file("sfloor.obj", "v -6 0 -6\nv 6 0 -6\nv 6 0 6\nv -6 0 6\nvt 0 0\nvt 6 0\nvt 6 6\nvt 0 6\nf 1/1 4/4 3/3 2/2\n"), "write");
  CHECK(scratch_file("slamp.obj", "v -0.3 3 -0.3\nv 0.3 3 -0.3\nv 0.3 3 0.3\nv -0.3 3 0.3\nf 1 2 3 4\n"), "write");
  unsigned char bytes[32 * 32 * 3];
  uint32_t st = 12345;
  for (int i = 0; i < 32 * 32; i++) {
    st = st * 1664525u + 1013904223u;
    double th = 70 * M_PI / 180 * ((st >> 8) / 16777216.0);
    st = st * 1664525u + 1013904223u;
    double ph = 2 * M_PI * ((st >> 8) / 16777216.0);
    double n[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
    for (int c = 0; c < 3; c++) bytes[3 * i + c] = (unsigned char)lrint((n[c] * 0.5 + 0.5) * 255);
  }
  char png[1200];
  snprintf(png, sizeof png, "%s/rough-nmap.png", scratch_dir());
  CHECK(stbi_write_png(png, 32, 32, 3, bytes, 96), "png");
  const char *json =
      "{ \"camera\": {\"position\": [0, 0.15, 5], \"look_at\": [0, 0.6, 0], \"fov\": 50},\n"
      "  \"film\": {\"width\": 48, \"height\": 32}, \"render\": {\"spp\": 8},\n"
      "  \"materials\": {\n"
      "    \"glass\": {\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0.3, \"normal_map\": \"rough-nmap.png\"},\n"
      "    \"sharp\": {\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0.01, \"normal_map\": \"rough-nmap.png\"},\n"
      "    \"metal\": {\"type\": \"conductor\", \"preset\": \"Au\", \"roughness\": 0.02, \"normal_map\": \"rough-nmap.png\"},\n"
      "    \"pane\": {\"type\": \"thindielectric\", \"ior\": 1.5, \"normal_map\": \"rough-nmap.png\"},\n"
      "    \"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.6, \"normal_map\": \"rough-nmap.png\"},\n"
      "    \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 40}},\n"
      "  \"shapes\": [{\"file\": \"usphere.obj\", \"material\": \"glass\", \"transform\": {\"translate\": [-1.3, 1, 0]}},\n"
      "             {\"file\": \"usphere.obj\", \"material\": \"sharp\", \"transform\": {\"translate\": [1.3, 1, 0]}},\n"
      "             {\"file\": \"usphere.obj\", \"material\": \"metal\", \"transform\": {\"scale\": 0.6, \"translate\": [0, 0.6, 1.5]}},\n"
      "             {\"file\": \"usphere.obj\", \"material\": \"pane\", \"transform\": {\"scale\": 0.5, \"translate\": [0, 1.7, -1]}},\n"
      "             {\"file\": \"sfloor.obj\", \"material\": \"floor\"},\n"
      "             {\"file\": \"slamp.obj\", \"material\": \"lamp\"}],\n"
      "  \"environment\": {\"type\": \"constant\", \"radiance\": 0.3} }\n";
  const char *path = scratch_file("stress.json", json);
  CHECK(path, "write");
  allow_shading_loss(0.5);
  const char *integ[] = {"path", "whitted", "distribution", "photon", "vpl", "vsl", "restir-di", "restir-gi", "ao"};
  for (int spectral = 0; spectral < 2; spectral++)
    for (size_t k = 0; k < sizeof integ / sizeof *integ; k++) {
      if (spectral && k > 0) break;
      valo_options o;
      valo_options_init(&o);
      snprintf(o.integrator, sizeof o.integrator, "%s", integ[k]);
      o.spectral = spectral;
      if (!strncmp(integ[k], "restir", 6)) o.frames = 2;
      valo_scene *sc;
      valo_render *r = render_file(path, &o, &sc); /* fails on any NaN, infinite or negative sample */
      CHECK(r, "%s%s: render failed or lost samples", integ[k], spectral ? " --spectral" : "");
      valo_stats s;
      valo_render_stats(r, &s);
      fprintf(stderr, "%-12s%s: %llu surface samples, %.2f %% refused for shading normals, 0 NaN/inf/negative/BSDF\n", integ[k],
              spectral ? " spectral" : "", (unsigned long long)s.surface_samples,
              s.surface_samples ? 100.0 * (double)s.lost[VALO_LOSS_SHADING_NORMAL] / (double)s.surface_samples : 0.0);
      CHECK(s.surface_samples > 0 || !strcmp(integ[k], "ao") || !strcmp(integ[k], "whitted"), "%s drew no surface samples", integ[k]);
      valo_render_destroy(r);
      valo_scene_destroy(sc);
    }
  return 0;
}

/* Base64 of n bytes into out (NUL-terminated). */
static void base64(const unsigned char *in, size_t n, char *out) {
  static const char *a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  size_t o = 0;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
    out[o++] = a[v >> 18 & 63];
    out[o++] = a[v >> 12 & 63];
    out[o++] = i + 1 < n ? a[v >> 6 & 63] : '=';
    out[o++] = i + 2 < n ? a[v & 63] : '=';
  }
  out[o] = 0;
}

/* Writes a glTF 2.0 quad (-1..1 in x and y, facing +z, texcoord (0,0) at its top-left
 * as glTF defines, normals +z and TANGENT (0, 1, 0, 1): along +v, not +u, so a renderer
 * that recomputes tangents from the UVs shows) with PNG `png` as its base-colour texture: a .gltf whose image is
 * "quad-texture.png" beside it (the caller writes that file), or a .glb holding the image
 * in its binary chunk. `material_extra` is added to the material (e.g. alphaMode).
 * Returns 0 on success. */
static int write_gltf_quad(const char *name, const unsigned char *png, size_t png_n, const char *material_extra, int glb) {
  static unsigned char bin[204 + 65536];
  static char b64[400], json[4096];
  if (png_n > 65536) return -1;
  const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, tan[16] = {0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1};
  const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  memcpy(bin, pos, 48);
  memcpy(bin + 48, uv, 32);
  memcpy(bin + 80, idx, 12);
  memcpy(bin + 92, nrm, 48);
  memcpy(bin + 140, tan, 64);
  base64(bin, 204, b64);
  const char *fmt =
      "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],"
      " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1, \"NORMAL\": 3, \"TANGENT\": 4}, \"indices\": 2, \"material\": 0}]}],"
      " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0, \"roughnessFactor\": 1}%s}],"
      " \"textures\": [{\"source\": 0}], \"images\": [%s],"
      " \"buffers\": [{\"byteLength\": %d%s}],"
      " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 32},"
      " {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 12}, {\"buffer\": 0, \"byteOffset\": 92, \"byteLength\": 48},"
      " {\"buffer\": 0, \"byteOffset\": 140, \"byteLength\": 64}%s],"
      " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1, -1, 0], \"max\": [1, 1, 0]},"
      " {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"},"
      " {\"bufferView\": 3, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, {\"bufferView\": 4, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC4\"}]}";
  if (!glb) {
    char uri[600];
    snprintf(uri, sizeof uri, ", \"uri\": \"data:application/octet-stream;base64,%s\"", b64);
    snprintf(json, sizeof json, fmt, material_extra, "{\"uri\": \"quad-texture.png\"}", 204, uri, "");
    return scratch_file(name, json) ? 0 : -1;
  }
  memcpy(bin + 204, png, png_n);
  size_t bin_n = (204 + png_n + 3) & ~(size_t)3;
  memset(bin + 204 + png_n, 0, bin_n - 204 - png_n);
  char view[200];
  snprintf(view, sizeof view, ", {\"buffer\": 0, \"byteOffset\": 204, \"byteLength\": %zu}", png_n);
  snprintf(json, sizeof json, fmt, material_extra, "{\"bufferView\": 5, \"mimeType\": \"image/png\"}", (int)bin_n, "", view);
  size_t json_n = (strlen(json) + 3) & ~(size_t)3;
  while (strlen(json) < json_n) strcat(json, " ");
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", scratch_dir(), name);
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  uint32_t head[3] = {0x46546C67u, 2, (uint32_t)(12 + 8 + json_n + 8 + bin_n)}, cj[2] = {(uint32_t)json_n, 0x4E4F534Au},
           cb[2] = {(uint32_t)bin_n, 0x004E4942u};
  int ok = fwrite(head, 4, 3, f) == 3 && fwrite(cj, 4, 2, f) == 2 && fwrite(json, 1, json_n, f) == json_n && fwrite(cb, 4, 2, f) == 2 &&
           fwrite(bin, 1, bin_n, f) == bin_n;
  return fclose(f) == 0 && ok ? 0 : -1;
}

/* UV orientation: the same four-quadrant texture (red, green, blue, yellow from
 * the image's top-left: tests/data/materials/quad-texture.png) on a quad through OBJ
 * (v = 0 at the image's bottom), glTF and glb (v = 0 at its top, the image embedded in
 * the .glb), under a uniform white sky: each quadrant of the render shows its colour. */
static int uv_orientation(void) {
  const char *png_src = VALO_SOURCE_DIR "/tests/data/materials/quad-texture.png";
  FILE *f = fopen(png_src, "rb");
  CHECK(f, "cannot open %s", png_src);
  unsigned char png[4096];
  size_t png_n = fread(png, 1, sizeof png, f);
  fclose(f);
  CHECK(png_n > 8 && png_n < sizeof png, "texture of %zu bytes", png_n);
  char pngp[1200];
  snprintf(pngp, sizeof pngp, "%s/quad-texture.png", scratch_dir());
  f = fopen(pngp, "wb");
  CHECK(f && fwrite(png, 1, png_n, f) == png_n, "write");
  fclose(f);
  CHECK(scratch_file("uvq.obj", "mtllib uvq.mtl\nusemtl t\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n") &&
            scratch_file("uvq.mtl", "newmtl t\nKd 1 1 1\nmap_Kd quad-texture.png\n"),
        "write");
  CHECK(write_gltf_quad("uvq.gltf", png, png_n, "", 0) == 0 && write_gltf_quad("uvq.glb", png, png_n, "", 1) == 0, "write glTF");
  const char *files[3] = {"uvq.obj", "uvq.gltf", "uvq.glb"};
  for (int k = 0; k < 3; k++) {
    char sj[1024];
    snprintf(sj, sizeof sj,
             "{ \"camera\": {\"position\": [0,0,3.2], \"look_at\": [0,0,0], \"fov\": 40}, \"film\": {\"width\": 32, \"height\": 32},\n"
             "  \"render\": {\"spp\": 4}, \"shapes\": [{\"file\": \"%s\"}], \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n",
             files[k]);
    int w, h;
    valo_options o;
    valo_options_init(&o);
    float *px = render_json_text(sj, &o, &w, &h);
    CHECK(px, "%s: render failed", files[k]);
    /* quadrant centres: (8,8) top-left ... (24,24) bottom-right, image rows from the top */
    const int at[4][2] = {{9, 9}, {22, 9}, {9, 22}, {22, 22}};
    const char *want[4] = {"red", "green", "blue", "yellow"};
    for (int q = 0; q < 4; q++) {
      const float *c = &px[3 * (at[q][1] * w + at[q][0])];
      int ok = q == 0 ? c[0] > 3 * c[1] && c[0] > 3 * c[2]
             : q == 1 ? c[1] > 3 * c[0] && c[1] > 3 * c[2]
             : q == 2 ? c[2] > 3 * c[0] && c[2] > 3 * c[1]
                      : c[0] > 3 * c[2] && c[1] > 3 * c[2];
      fprintf(stderr, "%s: %s quadrant (%.3f %.3f %.3f)\n", files[k], want[q], c[0], c[1], c[2]);
      CHECK(ok, "%s: the %s quadrant shows (%.3f %.3f %.3f)", files[k], want[q], c[0], c[1], c[2]);
    }
    free(px);
  }
  return 0;
}

/* A 4 x 4 red PNG of alpha 128/255, written to the scratch folder as name and read back
 * into png (at most cap bytes); its length, 0 on failure. */
static size_t red_half_alpha_png(const char *name, unsigned char *png, size_t cap) {
  unsigned char rgba[4 * 4 * 4];
  for (int i = 0; i < 16; i++) { rgba[4 * i] = 220; rgba[4 * i + 1] = 30; rgba[4 * i + 2] = 30; rgba[4 * i + 3] = 128; }
  char pngp[1200];
  snprintf(pngp, sizeof pngp, "%s/%s", scratch_dir(), name);
  if (!stbi_write_png(pngp, 4, 4, 4, rgba, 16)) return 0;
  FILE *f = fopen(pngp, "rb");
  if (!f) return 0;
  size_t n = fread(png, 1, cap, f);
  fclose(f);
  return n;
}

/* Alpha cutoff: a glTF quad whose base colour has alpha 128/255 = 0.502,
 * alphaMode MASK at cutoffs 0.25, 0.49 (opaque) and 0.51, 0.75 (cut out), 1 unit above a
 * floor under a point light. Camera rays: from above, the centre shows the quad (red) or
 * the floor (grey). Shadow rays: from below the quad's plane, the floor under it is dark
 * or lit. Both on the kd-tree and on Embree. */
static int alpha_cutoff(void) {
  unsigned char png[4096];
  size_t png_n = red_half_alpha_png("alpha-half.png", png, sizeof png);
  CHECK(png_n > 0, "png");
  CHECK(scratch_file("afloor.obj", FLOOR_OBJ), "write");
  const double cut[4] = {0.25, 0.49, 0.51, 0.75};
  const char *accels[2] = {"kdtree", "embree"};
  for (int k = 0; k < 4; k++) {
    char extra[128], name[64];
    snprintf(extra, sizeof extra, ", \"alphaMode\": \"MASK\", \"alphaCutoff\": %.2f", cut[k]);
    snprintf(name, sizeof name, "cut%d.glb", k);
    CHECK(write_gltf_quad(name, png, png_n, extra, 1) == 0, "write glb");
    int opaque = 128 / 255.0 >= cut[k];
    for (int a = 0; a < 2; a++)
      for (int view = 0; view < 2; view++) { /* 0: camera rays from above, 1: shadow rays seen from below */
        char json[1024];
        snprintf(json, sizeof json,
                 "{ \"camera\": {\"position\": %s, \"look_at\": [0,0,0], \"fov\": 20},\n"
                 "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 4, \"max_depth\": 1, \"accel\": \"%s\"},\n"
                 "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
                 "  \"shapes\": [{\"file\": \"afloor.obj\", \"material\": \"floor\"},\n"
                 "             {\"file\": \"%s\", \"transform\": {\"rotate_x\": -90, \"translate\": [0, 1, 0]}}],\n"
                 "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
                 view ? "[3, 0.4, 0.01]" : "[0, 4, 0.01]", accels[a], name);
        int w, h;
        float *px = render_json_text(json, NULL, &w, &h);
        CHECK(px, "render failed");
        const float *c = &px[3 * (4 * w + 4)];
        fprintf(stderr, "cutoff %.2f, %s, %s: centre (%.3f %.3f %.3f)\n", cut[k], accels[a], view ? "floor under the quad" : "from above", c[0], c[1],
                c[2]);
        if (!view) {
          int red = c[0] > 3 * c[1];
          CHECK(red == opaque, "cutoff %.2f (%s): camera rays %s the quad", cut[k], accels[a], red ? "hit" : "passed through");
        } else {
          int lit = c[1] > 0.05f;
          CHECK(lit == !opaque, "cutoff %.2f (%s): the floor under the quad is %s", cut[k], accels[a], lit ? "lit" : "in shadow");
        }
        free(px);
      }
  }
  return 0;
}

/* Stochastic opacity ("opacity" < 1): a hit counts with probability opacity, decided per
 * ray and triangle, so what passes is 1 - opacity in expectation, for camera and shadow
 * rays alike. Camera rays: a glowing floor (radiance 1) seen through one black veil of
 * opacity 0.3 on the left (0.7 passes) and two of 0.5 on the right (0.25: the two veils
 * decide independently; one coin for both would give 0.5). Shadow rays: a floor lit by a
 * point light above, a black veil of opacity 0.4 between them over the left half and the
 * camera under the veil: the left half has 0.6 of the mirrored right half's light. Both
 * backends; the two must agree within noise. */
static int opacity_stochastic(void) {
  CHECK(scratch_file("ofloor.obj", FLOOR_OBJ), "write");
  CHECK(scratch_file("oleft1.obj", "v -5 1 -5\nv -5 1 5\nv 0 1 5\nv 0 1 -5\nf 1 2 3 4\n"), "write");
  CHECK(scratch_file("oright1.obj", "v 0 1 -5\nv 0 1 5\nv 5 1 5\nv 5 1 -5\nf 1 2 3 4\n"), "write");
  CHECK(scratch_file("oright2.obj", "v 0 2 -5\nv 0 2 5\nv 5 2 5\nv 5 2 -5\nf 1 2 3 4\n"), "write");
  const char *accels[2] = {"kdtree", "embree"};
  double seen[2][2], shadow[2];
  for (int a = 0; a < 2; a++) {
    if (a == 1 && !test_embree()) break;
    char json[2048];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0, 6, 0.001], \"look_at\": [0,0,0], \"fov\": 40},\n"
             "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 64, \"max_depth\": 1, \"accel\": \"%s\"},\n"
             "  \"materials\": {\"glow\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 1},\n"
             "                \"v3\": {\"type\": \"diffuse\", \"reflectance\": 0, \"opacity\": 0.3},\n"
             "                \"v5\": {\"type\": \"diffuse\", \"reflectance\": 0, \"opacity\": 0.5}},\n"
             "  \"shapes\": [{\"file\": \"ofloor.obj\", \"material\": \"glow\"}, {\"file\": \"oleft1.obj\", \"material\": \"v3\"},\n"
             "             {\"file\": \"oright1.obj\", \"material\": \"v5\"}, {\"file\": \"oright2.obj\", \"material\": \"v5\"}] }\n",
             accels[a]);
    int w, h;
    float *px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "render failed");
    double sum[2] = {0, 0};
    int n[2] = {0, 0};
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        if (x == w / 2 - 1 || x == w / 2) continue; /* the seam */
        int right = x >= w / 2;
        sum[right] += px[3 * (y * w + x) + 1];
        n[right]++;
      }
    free(px);
    for (int k = 0; k < 2; k++) seen[a][k] = sum[k] / n[k];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0, 0.6, 0.001], \"look_at\": [0,0,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 64, \"max_depth\": 1, \"accel\": \"%s\"},\n"
             "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5},\n"
             "                \"v4\": {\"type\": \"diffuse\", \"reflectance\": 0, \"opacity\": 0.4}},\n"
             "  \"shapes\": [{\"file\": \"ofloor.obj\", \"material\": \"floor\"}, {\"file\": \"oleft1.obj\", \"material\": \"v4\"}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
             accels[a]);
    px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "render failed");
    double l = 0, r = 0;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w / 2 - 1; x++) { l += px[3 * (y * w + x) + 1]; r += px[3 * (y * w + (w - 1 - x)) + 1]; }
    free(px);
    shadow[a] = l / r;
    fprintf(stderr, "%s: seen through one veil of 0.3 %.4f (0.7), two of 0.5 %.4f (0.25); light under a veil of 0.4 %.4f (0.6)\n", accels[a],
            seen[a][0], seen[a][1], shadow[a]);
    CHECK(fabs(seen[a][0] - 0.7) < 0.015, "%s: %.4f seen through one veil of opacity 0.3, not 0.7", accels[a], seen[a][0]);
    CHECK(fabs(seen[a][1] - 0.25) < 0.015, "%s: %.4f seen through two veils of 0.5, not 0.25", accels[a], seen[a][1]);
    CHECK(fabs(shadow[a] - 0.6) < 0.015, "%s: the light under a veil of opacity 0.4 is %.4f of the light beside it, not 0.6", accels[a], shadow[a]);
  }
  return 0;
}

/* glTF alphaMode BLEND: the base colour's alpha (128/255 here) as stochastic opacity, as
 * Cycles renders a blended material: seen from above, the quad over a floor lit by a point
 * light gives a·Q + (1 - a)·(1 - a)·F, Q the opaque quad (MASK at cutoff 0.25), F the floor
 * alone, (1 - a) once for the camera ray through the quad and once for the floor's shadow
 * ray through it. */
static int gltf_blend(void) {
  unsigned char png[4096];
  size_t png_n = red_half_alpha_png("quad-texture.png", png, sizeof png);
  CHECK(png_n > 0, "png");
  CHECK(scratch_file("bfloor.obj", FLOOR_OBJ), "write");
  CHECK(write_gltf_quad("blend.glb", png, png_n, ", \"alphaMode\": \"BLEND\"", 1) == 0, "write glb");
  CHECK(write_gltf_quad("opaque.glb", png, png_n, ", \"alphaMode\": \"MASK\", \"alphaCutoff\": 0.25", 1) == 0, "write glb");
  const char *quads[3] = {"blend.glb", "opaque.glb", NULL};
  double c[3][3];
  for (int k = 0; k < 3; k++) {
    char json[1024], quad[256] = "";
    if (quads[k]) snprintf(quad, sizeof quad, ", {\"file\": \"%s\", \"transform\": {\"rotate_x\": -90, \"translate\": [0, 1, 0]}}", quads[k]);
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0, 4, 0.01], \"look_at\": [0,0,0], \"fov\": 20},\n"
             "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 1024, \"max_depth\": 1},\n"
             "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
             "  \"shapes\": [{\"file\": \"bfloor.obj\", \"material\": \"floor\"}%s],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
             quad);
    int w, h;
    float *px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "render failed");
    for (int ch = 0; ch < 3; ch++) {
      c[k][ch] = 0;
      for (int y = 2; y < 6; y++)
        for (int x = 2; x < 6; x++) c[k][ch] += px[3 * (y * w + x) + ch] / 16;
    }
    free(px);
  }
  double a = 128 / 255.0;
  for (int ch = 0; ch < 3; ch++) {
    double want = a * c[1][ch] + (1 - a) * (1 - a) * c[2][ch];
    fprintf(stderr, "channel %d: blend %.4f, a Q + (1-a)^2 F = %.4f (Q %.4f, F %.4f)\n", ch, c[0][ch], want, c[1][ch], c[2][ch]);
    CHECK(fabs(c[0][ch] - want) < 0.03 * want, "channel %d: BLEND gives %.4f, not %.4f", ch, c[0][ch], want);
  }
  return 0;
}

/* "blend": diffuse 0.2 and 0.8 at weight 0.25 scatter as diffuse 0.35 (a point light over
 * a floor, direct light: the means agree within noise); the file's mistakes are refused
 * with the key and the reason. */
static int blend_mixes(void) {
  CHECK(scratch_file("mfloor.obj", FLOOR_OBJ), "write");
  const char *mats[2] = {"\"a\": {\"type\": \"diffuse\", \"reflectance\": 0.2}, \"b\": {\"type\": \"diffuse\", \"reflectance\": 0.8},"
                         " \"f\": {\"type\": \"blend\", \"weight\": 0.25, \"materials\": [\"a\", \"b\"]}",
                         "\"f\": {\"type\": \"diffuse\", \"reflectance\": 0.35}"};
  double mean[2];
  for (int k = 0; k < 2; k++) {
    char json[1024];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0, 2, 0.001], \"look_at\": [0,0,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 256, \"max_depth\": 1},\n"
             "  \"materials\": {%s},\n  \"shapes\": [{\"file\": \"mfloor.obj\", \"material\": \"f\"}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
             mats[k]);
    mean[k] = render_json_mean_green(json);
    CHECK(mean[k] >= 0, "render failed");
  }
  fprintf(stderr, "blend of 0.2 and 0.8 at 0.25: %.5f; diffuse 0.35: %.5f\n", mean[0], mean[1]);
  CHECK(fabs(mean[0] / mean[1] - 1) < 0.01, "the blend's mean %.5f is not diffuse 0.35's %.5f", mean[0], mean[1]);
  static const struct { const char *mats, *says; } bad[] = {
      {"\"f\": {\"type\": \"blend\", \"weight\": 0.5, \"materials\": [\"a\", \"zz\"]}, \"a\": {\"type\": \"diffuse\"}", "no material is named \"zz\""},
      {"\"f\": {\"type\": \"blend\", \"weight\": 0.5, \"materials\": [\"f\", \"f\"]}", "cannot hold itself"},
      {"\"f\": {\"type\": \"blend\", \"materials\": [\"a\"]}, \"a\": {\"type\": \"diffuse\"}", "must name two materials"},
      {"\"f\": {\"type\": \"blend\", \"weight\": 2, \"materials\": [\"a\", \"a\"]}, \"a\": {\"type\": \"diffuse\"}", "out of range"},
      {"\"f\": {\"type\": \"blend\", \"materials\": [\"a\", \"b\"]}, \"a\": {\"type\": \"diffuse\", \"emission\": 1}, \"b\": {\"type\": \"diffuse\"}",
       "has its own emission"},
      {"\"f\": {\"type\": \"blend\", \"materials\": [\"a\", \"b\"]}, \"a\": {\"type\": \"diffuse\"}, \"b\": {\"type\": \"blend\"}", "a blend material"},
      {"\"f\": {\"type\": \"blend\", \"materials\": [\"a\", \"a\"], \"emission\": 1}, \"a\": {\"type\": \"diffuse\"}", "unknown key"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char json[1024];
    snprintf(json, sizeof json, "{ \"materials\": {%s}, \"shapes\": [{\"file\": \"mfloor.obj\", \"material\": \"f\"}] }\n", bad[i].mats);
    const char *path = scratch_file("bad-blend.json", json);
    valo_scene *sc = NULL;
    valo_error err;
    CHECK(valo_scene_load(path, &sc, &err) != VALO_OK, "case %zu loaded", i);
    CHECK(strstr(err.message, bad[i].says) && strstr(err.message, "materials.f"), "case %zu: \"%s\" does not say \"%s\"", i, err.message, bad[i].says);
  }
  return 0;
}

/* A scene of `mesh` with these materials (the "materials" object's inside) on material
 * "f" is refused, the message naming materials.f and saying `says`: 0, else 1. */
static int material_refused(const char *mesh, const char *materials, const char *says) {
  char json[1200];
  snprintf(json, sizeof json, "{ \"materials\": {%s}, \"shapes\": [{\"file\": \"%s\", \"material\": \"f\"}] }\n", materials, mesh);
  valo_scene *sc = NULL;
  valo_error err;
  CHECK(valo_scene_load(scratch_file("refused.json", json), &sc, &err) != VALO_OK, "loaded: %s", materials);
  CHECK(strstr(err.message, says) && strstr(err.message, "materials.f"), "\"%s\" does not say \"%s\"", err.message, says);
  return 0;
}

/* "sided" (Mitsuba's twosided of two BSDFs): a floor of diffuse 0.2 in front (its
 * winding's normal is +y) and 0.8 behind, seen and lit from above, then from below,
 * renders as diffuse 0.2, then 0.8, bit for bit (the same hits pick one material); a
 * sided material holding a blend, and a weight, are refused. */
static int sided_material(void) {
  CHECK(scratch_file("mfloor.obj", FLOOR_OBJ), "write");
  double mean[2][2];
  for (int side = 0; side < 2; side++)
    for (int k = 0; k < 2; k++) {
      const char *mat = k ? (side ? "\"f\": {\"type\": \"diffuse\", \"reflectance\": 0.8}" : "\"f\": {\"type\": \"diffuse\", \"reflectance\": 0.2}")
                          : "\"a\": {\"type\": \"diffuse\", \"reflectance\": 0.2}, \"b\": {\"type\": \"diffuse\", \"reflectance\": 0.8},"
                            " \"f\": {\"type\": \"sided\", \"materials\": [\"a\", \"b\"]}";
      char json[1024];
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0, %d, 0.001], \"look_at\": [0,0,0], \"fov\": 60},\n"
               "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16, \"max_depth\": 1},\n"
               "  \"materials\": {%s},\n  \"shapes\": [{\"file\": \"mfloor.obj\", \"material\": \"f\"}],\n"
               "  \"lights\": [{\"type\": \"point\", \"position\": [0,%d,0], \"intensity\": 10}] }\n",
               side ? -2 : 2, mat, side ? -3 : 3);
      mean[side][k] = render_json_mean_green(json);
      CHECK(mean[side][k] > 0, "render failed");
    }
  fprintf(stderr, "sided from the front %.6f (diffuse 0.2: %.6f), from the back %.6f (diffuse 0.8: %.6f)\n", mean[0][0], mean[0][1], mean[1][0], mean[1][1]);
  CHECK(mean[0][0] == mean[0][1] && mean[1][0] == mean[1][1], "the sided floor is not its front's material above and its back's below");
  static const struct { const char *mats, *says; } bad[] = {
      {"\"f\": {\"type\": \"sided\", \"materials\": [\"a\", \"b\"], \"weight\": 0.5}, \"a\": {\"type\": \"diffuse\"}, \"b\": {\"type\": \"diffuse\"}", "unknown key \"weight\""},
      {"\"f\": {\"type\": \"sided\", \"materials\": [\"a\", \"b\"]}, \"a\": {\"type\": \"diffuse\"}, \"b\": {\"type\": \"blend\"}", "a blend material"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
    if (material_refused("mfloor.obj", bad[i].mats, bad[i].says)) return 1;
  return 0;
}

/* "black_back": a floor seen and lit from above renders bit for bit as without it; from
 * below it is black (a plain diffuse there is not); a blend does not take the key (its
 * materials do). */
static int black_back_material(void) {
  CHECK(scratch_file("mfloor.obj", FLOOR_OBJ), "write");
  double mean[2][2];
  for (int side = 0; side < 2; side++)
    for (int k = 0; k < 2; k++) {
      char json[1024];
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0, %d, 0.001], \"look_at\": [0,0,0], \"fov\": 60},\n"
               "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16},\n"
               "  \"materials\": {\"f\": {\"type\": \"diffuse\", \"reflectance\": 0.8%s}},\n"
               "  \"shapes\": [{\"file\": \"mfloor.obj\", \"material\": \"f\"}],\n"
               "  \"lights\": [{\"type\": \"point\", \"position\": [0,%d,0], \"intensity\": 10}] }\n",
               side ? -2 : 2, k ? ", \"black_back\": true" : "", side ? -3 : 3);
      mean[side][k] = render_json_mean_green(json);
      CHECK(mean[side][k] >= 0, "render failed");
    }
  fprintf(stderr, "from above %.6f (without black_back %.6f), from below %.6f (without %.6f)\n", mean[0][1], mean[0][0], mean[1][1], mean[1][0]);
  CHECK(mean[0][0] > 0 && mean[0][1] == mean[0][0], "from the front black_back changed the image");
  CHECK(mean[1][0] > 0 && mean[1][1] == 0, "from behind: %g (without black_back %g)", mean[1][1], mean[1][0]);
  return material_refused("mfloor.obj", "\"a\": {\"type\": \"diffuse\"}, \"f\": {\"type\": \"blend\", \"materials\": [\"a\", \"a\"], \"black_back\": true}",
                          "unknown key \"black_back\"");
}

/* The kd a material shows at barycentrics (b1, b2) of triangle t, seen from +y. */
static rgb kd_at(const scene *s, uint32_t t, float b1, float b2) {
  ray r = {v3(0, 5, 0), v3(0, -1, 0), INFINITY};
  hit h = {5, b1, b2, t};
  isect it;
  isect_from_hit(s, &r, &h, &it);
  return bsdf_at(s, &it).kd;
}

/* Writes a glTF quad (y = 0, facing +y, 2 x 2) whose COLOR_0 is n components of type
 * ctype (5126 float, 5121 and 5123 normalized bytes and shorts) per vertex, all equal to
 * col (n = 0: none), its buffer in a .bin beside it; its materials mat (JSON objects;
 * NULL: one of base colour factor (0.5, 1, 0.25), metallic 0), the primitive's the one at
 * mat_index, and the document's "extensionsUsed" used (JSON; NULL: none). */
static int gltf_quad(const char *name, int ctype, int n, const double *col, const char *mat, const char *used, int mat_index) {
  static const double white[3] = {1, 1, 1};
  int attr = n > 0; /* without COLOR_0 the accessor stays, unused */
  if (!attr) { n = 3; ctype = 5126; col = white; }
  static const float pos[12] = {-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1};
  static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  unsigned char buf[256];
  size_t size = ctype == 5126 ? 4 : ctype == 5123 ? 2 : 1, clen = (4 * n * size + 3) & ~(size_t)3, len = 0;
  memcpy(buf, pos, sizeof pos);
  len = sizeof pos;
  memset(buf + len, 0, clen);
  for (int v = 0; v < 4; v++)
    for (int k = 0; k < n; k++) {
      double x = k < 3 ? col[k] : 1;
      unsigned char *at = buf + len + (size_t)(v * n + k) * size;
      if (ctype == 5126) { float f = (float)x; memcpy(at, &f, 4); }
      else if (ctype == 5123) { uint16_t u = (uint16_t)lround(x * 65535); memcpy(at, &u, 2); }
      else *at = (unsigned char)lround(x * 255);
    }
  len += clen;
  memcpy(buf + len, idx, sizeof idx);
  len += sizeof idx;
  char bin[64], json[2048];
  snprintf(bin, sizeof bin, "%s.bin", name);
  FILE *f = fopen(scratch_path(bin), "wb");
  if (!f || fwrite(buf, 1, len, f) != len || fclose(f)) return 0;
  snprintf(json, sizeof json,
           "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],%s%s%s\n"
           " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0%s}, \"indices\": 2, \"material\": %d}]}],\n"
           " \"materials\": [%s],\n"
           " \"buffers\": [{\"byteLength\": %zu, \"uri\": \"%s\"}],\n"
           " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": %zu},\n"
           "   {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 12}],\n"
           " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1, 0, -1], \"max\": [1, 0, 1]},\n"
           "   {\"bufferView\": 1, \"componentType\": %d, \"count\": 4, \"type\": \"VEC%d\"%s},\n"
           "   {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n",
           used ? " \"extensionsUsed\": " : "", used ? used : "", used ? "," : "", attr ? ", \"COLOR_0\": 1" : "", mat_index,
           mat ? mat : "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 1, 0.25, 1], \"metallicFactor\": 0}}", len, bin, clen, 48 + clen,
           ctype, n, ctype == 5126 ? "" : ", \"normalized\": true");
  char gl[64];
  snprintf(gl, sizeof gl, "%s.gltf", name);
  return scratch_file(gl, json) != NULL;
}

/* Vertex colours ("vertex_colors", glTF's COLOR_0): a PLY quad's 8-bit colours, each
 * corner its own, multiply the reflectance, interpolated across each triangle (kd at
 * corners and at inner points to 1e-6), and the PLY's own default material's; without
 * the key, and on an OBJ without colours beside it, the reflectance alone; a quad of one colour renders as a plain material of
 * that colour (to 1e-5); glTF's COLOR_0 as floats, bytes and shorts multiplies the base
 * colour factor; a conductor and a blend refuse the key. */
static int vertex_colors(void) {
  static const char *const ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "-1 0 -1 255 0 0\n-1 0 1 0 255 0\n1 0 1 0 0 255\n1 0 -1 51 102 204\n4 0 1 2 3\n";
  static const char *const json =
      "{ \"materials\": {\"vc\": {\"type\": \"diffuse\", \"reflectance\": [0.5, 1, 0.8], \"vertex_colors\": true},\n"
      "    \"plain\": {\"type\": \"diffuse\", \"reflectance\": [0.5, 1, 0.8]},\n"
      "    \"pbr\": {\"type\": \"pbr\", \"base_color\": 0.5, \"vertex_colors\": true}},\n"
      "  \"shapes\": [{\"file\": \"vcquad.ply\", \"material\": \"vc\"}, {\"file\": \"vcquad.ply\", \"material\": \"plain\"},\n"
      "    {\"file\": \"mfloor.obj\", \"material\": \"vc\"}, {\"file\": \"vcquad.ply\", \"material\": \"pbr\"}, {\"file\": \"vcquad.ply\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n";
  CHECK(scratch_file("vcquad.ply", ply) && scratch_file("mfloor.obj", FLOOR_OBJ), "write");
  scene *s = NULL;
  valo_error err;
  valo_options file;
  CHECK(scene_load(scratch_file("vc.json", json), NULL, &s, &file, &err) == VALO_OK, "%s", err.message);
  CHECK(s->ntris == 10 && s->col, "%u triangles, colours %s", s->ntris, s->col ? "kept" : "dropped");
  /* the quad's corners as the triangles hold them: (tri, b1, b2) and the colour there */
  const float corner[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2f, 0.4f, 0.8f}};
  const rgb refl = c3(0.5f, 1, 0.8f);
  for (uint32_t t = 0; t < 2; t++) {
    const uint32_t *ix = &s->idx[3 * t];
    const float bs[4][2] = {{0, 0}, {1, 0}, {0, 1}, {0.25f, 0.35f}};
    for (int k = 0; k < 4; k++) {
      float w[3] = {1 - bs[k][0] - bs[k][1], bs[k][0], bs[k][1]}, e[3] = {0, 0, 0};
      for (int j = 0; j < 3; j++) {
        vec3 p = s->pos[ix[j]];
        int c = p.x < 0 ? (p.z < 0 ? 0 : 1) : (p.z > 0 ? 2 : 3); /* which corner */
        for (int ch = 0; ch < 3; ch++) e[ch] += w[j] * corner[c][ch];
      }
      rgb kd = kd_at(s, t, bs[k][0], bs[k][1]), plain = kd_at(s, t + 2, bs[k][0], bs[k][1]);
      CHECK(fabsf(kd.r - e[0] * refl.r) < 1e-6f && fabsf(kd.g - e[1] * refl.g) < 1e-6f && fabsf(kd.b - e[2] * refl.b) < 1e-6f,
            "triangle %u at (%g, %g): kd (%g %g %g), expected (%g %g %g)", t, bs[k][0], bs[k][1], kd.r, kd.g, kd.b, e[0] * refl.r, e[1] * refl.g, e[2] * refl.b);
      CHECK(plain.r == refl.r && plain.g == refl.g && plain.b == refl.b, "without vertex_colors: (%g %g %g)", plain.r, plain.g, plain.b);
      rgb pb = kd_at(s, t + 6, bs[k][0], bs[k][1]);
      CHECK(fabsf(pb.r - 0.5f * e[0]) < 1e-6f && fabsf(pb.b - 0.5f * e[2]) < 1e-6f, "pbr base colour (%g %g %g)", pb.r, pb.g, pb.b);
      rgb own = kd_at(s, t + 8, bs[k][0], bs[k][1]), base = s->mats[s->tri_mat[t + 8]].kd; /* the PLY's own (default) material shows its colours */
      CHECK(fabsf(own.r - base.r * e[0]) < 1e-6f && fabsf(own.g - base.g * e[1]) < 1e-6f && fabsf(own.b - base.b * e[2]) < 1e-6f,
            "the PLY's own material: (%g %g %g)", own.r, own.g, own.b);
    }
    rgb white = kd_at(s, t + 4, 0.3f, 0.3f);
    CHECK(white.r == refl.r && white.g == refl.g && white.b == refl.b, "a mesh without colours: (%g %g %g)", white.r, white.g, white.b);
  }
  scene_free(s);
  /* one colour everywhere renders as that colour's plain material */
  static const char *const one =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property float red\nproperty float green\nproperty float blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "-5 0 -5 0.2 0.5 0.7\n-5 0 5 0.2 0.5 0.7\n5 0 5 0.2 0.5 0.7\n5 0 -5 0.2 0.5 0.7\n4 0 1 2 3\n";
  CHECK(scratch_file("vcone.ply", one), "write");
  double mean[2];
  for (int k = 0; k < 2; k++) {
    char scn[1024];
    snprintf(scn, sizeof scn,
             "{ \"camera\": {\"position\": [0, 2, 0.001], \"look_at\": [0,0,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16},\n"
             "  \"materials\": {\"f\": {\"type\": \"diffuse\", \"reflectance\": %s}},\n"
             "  \"shapes\": [{\"file\": \"vcone.ply\", \"material\": \"f\"}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0,3,0], \"intensity\": 10}] }\n",
             k ? "[0.2, 0.5, 0.7]" : "1, \"vertex_colors\": true");
    mean[k] = render_json_mean_green(scn);
    CHECK(mean[k] > 0, "render failed");
  }
  fprintf(stderr, "one colour: vertex colours %.7f, plain %.7f\n", mean[0], mean[1]);
  CHECK(fabs(mean[0] - mean[1]) < 1e-5 * mean[1], "vertex colours %g against the plain material %g", mean[0], mean[1]);
  /* glTF COLOR_0: floats, normalized bytes and shorts (RGBA), times the base colour factor */
  static const int types[3][2] = {{5126, 3}, {5121, 4}, {5123, 4}};
  const double col[3] = {0.2, 0.4, 0.6};
  for (int i = 0; i < 3; i++) {
    char name[32];
    snprintf(name, sizeof name, "vc%d", i);
    CHECK(gltf_quad(name, types[i][0], types[i][1], col, NULL, NULL, 0), "write");
    char path[64];
    snprintf(path, sizeof path, "%s.gltf", name);
    s = scene_new(scratch_path(path));
    CHECK(load_mesh(s, scratch_path(path), NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
    CHECK(s->mats[s->tri_mat[0]].vertex_colors && s->col, "COLOR_0 of type %d not taken", types[i][0]);
    rgb kd = kd_at(s, 0, 0.3f, 0.3f);
    double tol = types[i][0] == 5121 ? 0.5 / 255 : 1e-5;
    CHECK(fabs(kd.r - 0.5 * col[0]) < tol && fabs(kd.g - col[1]) < tol && fabs(kd.b - 0.25 * col[2]) < tol, "COLOR_0 of type %d: base colour (%g %g %g)",
          types[i][0], kd.r, kd.g, kd.b);
    scene_free(s);
  }
  if (material_refused("vcquad.ply", "\"f\": {\"type\": \"conductor\", \"preset\": \"Au\", \"vertex_colors\": true}", "unknown key \"vertex_colors\"")) return 1;
  return material_refused("vcquad.ply", "\"a\": {\"type\": \"diffuse\"}, \"f\": {\"type\": \"blend\", \"materials\": [\"a\", \"a\"], \"vertex_colors\": true}",
                          "unknown key \"vertex_colors\"");
}

/* glTF's KHR_materials_transmission, _ior and _volume (gltf_material.c): full
 * transmission without a volume is a thin dielectric tinted by the base colour factor,
 * with a thickness a dielectric of the file's ior and roughness; partial transmission over
 * a metal is the blend of the pbr material at metallic m / (1 - w) and the glass at weight
 * w = t (1 - m); none leaves the pbr material, and an emitting one stays opaque with a
 * warning, as does an ior below 1 (read as 1.5); a thin pane seen face on under a white
 * sky shows R + (1 - R) tint (R the pane's reflectance, 2r / (1 + r), r = 0.04); the blend
 * renders as the JSON blend of the same two materials; a volume's attenuation is an
 * absorbing medium inside the mesh (a cube of ior 1 seen face on shows colour^(side /
 * distance)); a file that only uses an extension valo does not read loads with a warning
 * naming it, one that requires it is refused. */
static int gltf_transmission(void) {
#define PBR(base, m, r) "\"pbrMetallicRoughness\": {\"baseColorFactor\": [" base ", 1], \"metallicFactor\": " #m ", \"roughnessFactor\": " #r "}"
  static const struct { const char *mat; mat_type type; float ior, rough, weight; } cases[] = {
      {"{" PBR("0.9, 0.6, 0.3", 0, 0) ", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}}}", MAT_THIN_DIELECTRIC, 1.5f, 0, 0},
      {"{" PBR("1, 1, 1", 0, 0.2) ", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 1.33},"
       " \"KHR_materials_volume\": {\"thicknessFactor\": 0.5}}}", MAT_DIELECTRIC, 1.33f, 0.2f, 0},
      {"{" PBR("0.9, 0.6, 0.3", 0.2, 0.4) ", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 0.5}}}", MAT_BLEND, 1.5f, 0.4f, 0.4f},
      {"{" PBR("0.9, 0.6, 0.3", 0, 0.4) "}", MAT_PBR, 1.5f, 0.4f, 0},
      {"{" PBR("1, 1, 1", 0, 0) ", \"emissiveFactor\": [1, 1, 1], \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}}}", MAT_PBR, 1.5f, 0, 0},
      {"{" PBR("1, 1, 1", 0, 0) ", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 0.9}}}",
       MAT_THIN_DIELECTRIC, 1.5f, 0, 0}};
#undef PBR
  static const char *const used = "[\"KHR_materials_transmission\", \"KHR_materials_ior\", \"KHR_materials_volume\"]";
  valo_error err;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char name[32], path[64];
    snprintf(name, sizeof name, "tr%zu", i);
    snprintf(path, sizeof path, "%s.gltf", name);
    CHECK(gltf_quad(name, 0, 0, NULL, cases[i].mat, used, 0), "write");
    scene *s = scene_new(scratch_path(path));
    warnings_capture(1);
    valo_status st = load_mesh(s, scratch_path(path), NULL, UINT32_MAX, 0, NULL, &err);
    char said[1024];
    snprintf(said, sizeof said, "%s", warnings_text());
    warnings_capture(0);
    CHECK(st == VALO_OK, "%s", err.message);
    const material *m = &s->mats[s->tri_mat[0]], *g = m;
    CHECK(m->type == cases[i].type, "case %zu: material type %d, expected %d", i, (int)m->type, (int)cases[i].type);
    if (m->type == MAT_BLEND) {
      const material *o = &s->mats[m->blend[0]];
      g = &s->mats[m->blend[1]];
      CHECK(fabsf(m->weight - cases[i].weight) < 1e-6f && o->type == MAT_PBR && fabsf(o->metallic - 0.2f / 0.6f) < 1e-6f && fabsf(o->roughness - 0.4f) < 1e-6f &&
                g->type == MAT_THIN_DIELECTRIC,
            "case %zu: blend weight %g of %d (metallic %g) and %d", i, m->weight, (int)o->type, o->metallic, (int)g->type);
    }
    if (g->type == MAT_DIELECTRIC || g->type == MAT_THIN_DIELECTRIC) {
      rgb base = i == 1 || i == 5 ? c3(1, 1, 1) : c3(0.9f, 0.6f, 0.3f);
      CHECK(fabsf(g->ior - cases[i].ior) < 1e-6f && fabsf(g->roughness - cases[i].rough) < 1e-6f && fabsf(g->transmittance.r - base.r) < 1e-6f &&
                fabsf(g->transmittance.g - base.g) < 1e-6f && fabsf(g->transmittance.b - base.b) < 1e-6f && c3_black(g->kd),
            "case %zu: glass of ior %g, roughness %g, transmittance (%g %g %g)", i, g->ior, g->roughness, g->transmittance.r, g->transmittance.g, g->transmittance.b);
    }
    int warned = strstr(said, "transmission is not read") != NULL || strstr(said, "ior 0.9 is read as 1.5") != NULL;
    CHECK(warned == (i >= 4), "case %zu: warnings \"%s\"", i, said);
    scene_free(s);
  }
  /* the thin pane face on (a 2 degree field) under a white sky: R + (1 - R) tint */
  const double r = 0.04, R = 2 * r / (1 + r), tint[3] = {0.9, 0.6, 0.3};
  static const char *const pane =
      "{ \"camera\": {\"position\": [0, 5, 0.0001], \"look_at\": [0,0,0], \"fov\": 2},\n"
      "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 256},\n"
      "  \"environment\": {\"type\": \"constant\", \"radiance\": 1},\n"
      "  \"shapes\": [{\"file\": \"tr0.gltf\"}] }\n";
  int w, h;
  float *px = render_json_text(pane, NULL, &w, &h);
  CHECK(px, "render failed");
  for (int c = 0; c < 3; c++) {
    double mean = 0;
    for (int i = 0; i < w * h; i++) mean += px[3 * i + c];
    mean /= w * h;
    double want = R + (1 - R) * tint[c];
    fprintf(stderr, "pane channel %d: %.5f, R + (1 - R) tint %.5f\n", c, mean, want);
    CHECK(fabs(mean - want) < 0.01 * want, "pane channel %d: %g, expected %g", c, mean, want);
  }
  free(px);
  /* the blend against the JSON blend of the same two materials, on the same quad */
  double mean[2];
  for (int k = 0; k < 2; k++) {
    char scn[1400];
    snprintf(scn, sizeof scn,
             "{ \"camera\": {\"position\": [0, 3, 2], \"look_at\": [0,0,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 64},\n"
             "  \"environment\": {\"type\": \"constant\", \"radiance\": 0.5},\n"
             "  \"materials\": {\"o\": {\"type\": \"pbr\", \"base_color\": [0.9, 0.6, 0.3], \"metallic\": %.9g, \"roughness\": 0.4},\n"
             "    \"g\": {\"type\": \"thindielectric\", \"transmittance\": [0.9, 0.6, 0.3]},\n"
             "    \"b\": {\"type\": \"blend\", \"materials\": [\"o\", \"g\"], \"weight\": 0.4}},\n"
             "  \"shapes\": [{\"file\": \"tr2.gltf\"%s}, {\"type\": \"rectangle\", \"transform\": {\"rotate_x\": -90, \"translate\": [0, -1, 0]}}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n",
             (double)(0.2f / 0.6f), k ? ", \"material\": \"b\"" : "");
    mean[k] = render_json_mean_green(scn);
    CHECK(mean[k] > 0, "render failed");
  }
  fprintf(stderr, "partial transmission: glTF %.6f, JSON blend %.6f\n", mean[0], mean[1]);
  CHECK(fabs(mean[0] - mean[1]) < 1e-4 * mean[1], "glTF %g against the JSON blend %g", mean[0], mean[1]);
  /* a volume's attenuation: an absorbing medium inside the mesh. A cube of side 2 of ior 1
   * (no reflection, no bending) seen face on under a white sky shows colour^(2 / distance) */
  static const float cpos[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
  static const uint16_t cidx[36] = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  FILE *f = fopen(scratch_path("cube.bin"), "wb");
  CHECK(f && fwrite(cpos, 1, 96, f) == 96 && fwrite(cidx, 1, 72, f) == 72 && !fclose(f), "write");
  char cube[2048];
  snprintf(cube, sizeof cube,
           "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": %s, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
           " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 0}]}],\n"
           " \"materials\": [{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"roughnessFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1},\n"
           "   \"KHR_materials_ior\": {\"ior\": 1}, \"KHR_materials_volume\": {\"thicknessFactor\": 2, \"attenuationColor\": [0.5, 0.7, 0.9], \"attenuationDistance\": 0.5}}}],\n"
           " \"buffers\": [{\"byteLength\": 168, \"uri\": \"cube.bin\"}],\n"
           " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 96}, {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 72}],\n"
           " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 8, \"type\": \"VEC3\", \"min\": [-1, -1, -1], \"max\": [1, 1, 1]},\n"
           "   {\"bufferView\": 1, \"componentType\": 5123, \"count\": 36, \"type\": \"SCALAR\"}]}\n",
           used);
  CHECK(scratch_file("cube.gltf", cube), "write");
  scene *s = scene_new(scratch_path("cube.gltf"));
  CHECK(load_mesh(s, scratch_path("cube.gltf"), NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  const double att[3] = {0.5, 0.7, 0.9};
  CHECK(s->nmedia == 1 && s->nshape_media == 1 && s->shape_media[0].interior == 0 && s->shape_media[0].exterior == MEDIUM_NONE, "%u media, %u boundaries",
        s->nmedia, s->nshape_media);
  CHECK(fabs(s->media[0].sigma_a.r + log(att[0]) / 0.5) < 1e-5 && fabs(s->media[0].sigma_a.b + log(att[2]) / 0.5) < 1e-5 && c3_black(s->media[0].sigma_s),
        "sigma_a (%g %g %g)", s->media[0].sigma_a.r, s->media[0].sigma_a.g, s->media[0].sigma_a.b);
  scene_free(s);
  static const char *const through =
      "{ \"camera\": {\"position\": [0, 0, 6], \"look_at\": [0,0,0], \"fov\": 5},\n"
      "  \"film\": {\"width\": 8, \"height\": 8}, \"render\": {\"spp\": 256},\n"
      "  \"environment\": {\"type\": \"constant\", \"radiance\": 1},\n"
      "  \"shapes\": [{\"file\": \"cube.gltf\"}] }\n";
  px = render_json_text(through, NULL, &w, &h);
  CHECK(px, "render failed");
  for (int c = 0; c < 3; c++) {
    double avg = 0, want = pow(att[c], 2 / 0.5), sd = sqrt(want * (1 - want) / (w * h * 256.0));
    for (int i = 0; i < w * h; i++) avg += px[3 * i + c];
    avg /= w * h;
    fprintf(stderr, "through the cube, channel %d: %.5f, colour^4 %.5f (sd %.5f)\n", c, avg, want, sd);
    CHECK(fabs(avg - want) < 5 * sd, "through the cube, channel %d: %g, expected %g", c, avg, want);
  }
  free(px);
  /* extensions: used and not read, a warning; required and not read, refused */
  CHECK(gltf_quad("trx", 0, 0, NULL, NULL, "[\"KHR_materials_iridescence\"]", 0), "write");
  s = scene_new(scratch_path("trx.gltf"));
  warnings_capture(1);
  valo_status st = load_mesh(s, scratch_path("trx.gltf"), NULL, UINT32_MAX, 0, NULL, &err);
  int used_said = strstr(warnings_text(), "uses KHR_materials_iridescence, which valo does not read") != NULL;
  warnings_capture(0);
  scene_free(s);
  CHECK(st == VALO_OK && used_said, "a file using KHR_materials_iridescence: %s", st ? err.message : "no warning");
  char *text = read_text_file(scratch_path("trx.gltf"));
  CHECK(text, "read");
  char req[4096]; /* the same file, requiring what it uses */
  snprintf(req, sizeof req, "{\"extensionsRequired\": [\"KHR_materials_iridescence\"], %s", text + 1);
  free(text);
  scratch_file("trr.gltf", req);
  s = scene_new(scratch_path("trr.gltf"));
  st = load_mesh(s, scratch_path("trr.gltf"), NULL, UINT32_MAX, 0, NULL, &err);
  scene_free(s);
  CHECK(st != VALO_OK && strstr(err.message, "requires the extension KHR_materials_iridescence") && strstr(err.message, "trr.gltf"), "required: %s",
        st ? err.message : "loaded");
  return 0;
}

/* Integer vertex attributes (glTF's normalized texture coordinates, KHR_mesh_quantization's
 * positions, normals and tangents; Assimp 5.2 read their bytes as floats: texture
 * coordinates of NaN): a quad of unsigned-short positions (one replaced by a sparse
 * part) under a node's scale and translation, byte normals and tangents and
 * unsigned-short texture coordinates, normalized, loads bit for bit as the same quad given
 * as the floats glTF's rules make of them (c/65535, max(c/127, -1)), from a .gltf and a
 * .glb; normalized texture coordinates alone, without the extension, too; a normal of
 * unsigned shorts and indices of 32-bit floats' kind in a position are refused. */
static const char *quant_json(const char *attrs, const char *ext, const char *buffer) {
  static char json[4096];
  snprintf(json, sizeof json,
           "{\"asset\": {\"version\": \"2.0\"}, %s \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n"
           " \"nodes\": [{\"mesh\": 0, \"scale\": [0.5, 0.25, 0.25], \"translation\": [-1, -0.5, -0.5]}],\n"
           " \"meshes\": [{\"primitives\": [{\"attributes\": {%s}, \"indices\": 8}]}],\n"
           " \"buffers\": [{\"byteLength\": 296%s}],\n"
           " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 48},\n"
           "   {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 32}, {\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 64},\n"
           "   {\"buffer\": 0, \"byteOffset\": 192, \"byteLength\": 32, \"byteStride\": 8}, {\"buffer\": 0, \"byteOffset\": 224, \"byteLength\": 16, \"byteStride\": 4},\n"
           "   {\"buffer\": 0, \"byteOffset\": 240, \"byteLength\": 16}, {\"buffer\": 0, \"byteOffset\": 256, \"byteLength\": 16},\n"
           "   {\"buffer\": 0, \"byteOffset\": 272, \"byteLength\": 12}, {\"buffer\": 0, \"byteOffset\": 284, \"byteLength\": 2},\n"
           "   {\"buffer\": 0, \"byteOffset\": 288, \"byteLength\": 6}],\n"
           " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 6, 3]},\n"
           "   {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},\n"
           "   {\"bufferView\": 3, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC4\"},\n"
           "   {\"bufferView\": 4, \"componentType\": 5123, \"count\": 4, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 6, 3],\n"
           "    \"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 9, \"componentType\": 5123}, \"values\": {\"bufferView\": 10}}},\n"
           "   {\"bufferView\": 5, \"componentType\": 5120, \"normalized\": true, \"count\": 4, \"type\": \"VEC3\"},\n"
           "   {\"bufferView\": 6, \"componentType\": 5123, \"normalized\": true, \"count\": 4, \"type\": \"VEC2\"},\n"
           "   {\"bufferView\": 7, \"componentType\": 5120, \"normalized\": true, \"count\": 4, \"type\": \"VEC4\"},\n"
           "   {\"bufferView\": 8, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n",
           ext, attrs, buffer);
  return json;
}
static int same_arrays(const scene *a, const scene *b, const char *what) {
  CHECK(a->nverts == b->nverts && a->ntris == b->ntris && a->nverts == 4, "%s: %u and %u vertices", what, a->nverts, b->nverts);
  CHECK(!memcmp(a->pos, b->pos, 4 * sizeof *a->pos), "%s: positions differ", what);
  CHECK(!memcmp(a->nrm, b->nrm, 4 * sizeof *a->nrm), "%s: normals differ", what);
  CHECK(!memcmp(a->uv, b->uv, 8 * sizeof *a->uv), "%s: texture coordinates differ (%g %g against %g %g)", what, a->uv[2], a->uv[3], b->uv[2], b->uv[3]);
  CHECK((a->tan_file == NULL) == (b->tan_file == NULL) && (!a->tan_file || !memcmp(a->tan_file, b->tan_file, 16 * sizeof(float))), "%s: tangents differ", what);
  return 0;
}
static scene *quant_load(const char *name, const char *text, size_t len, valo_error *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", scratch_dir(), name);
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(text, 1, len, f) != len || fclose(f)) return NULL;
  scene *s = scene_new(path);
  if (load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, err) != VALO_OK) { scene_free(s); return NULL; }
  return s;
}
static int gltf_quantized(void) {
  unsigned char bin[296] = {0};
  static const uint16_t qpos[4][4] = {{0, 0, 3}, {5, 0, 3}, {5, 6, 0}, {0, 6, 0}}, sparse_ix = 2, sparse_pos[3] = {4, 6, 1};
  static const int8_t qn[4][4] = {{0, 76, 102}, {0, -128, 0}, {127, 0, 0}, {-60, 90, 30}}, qt[4][4] = {{127, 0, 0, 127}, {0, 127, 0, -127}, {0, 0, -128, 127}, {90, 90, 0, 127}};
  static const uint16_t quv[4][2] = {{0, 65535}, {65535, 65535}, {32768, 13107}, {1, 0}}, idx[6] = {0, 1, 2, 0, 2, 3};
  float fpos[12], fn[12], fuv[8], ft[16];
  for (int v = 0; v < 4; v++) {
    for (int k = 0; k < 3; k++) {
      fpos[3 * v + k] = v == sparse_ix ? sparse_pos[k] : qpos[v][k];
      fn[3 * v + k] = (float)fmax(qn[v][k] / 127.0, -1.0);
    }
    for (int k = 0; k < 4; k++) ft[4 * v + k] = (float)fmax(qt[v][k] / 127.0, -1.0);
    for (int k = 0; k < 2; k++) fuv[2 * v + k] = (float)(quv[v][k] / 65535.0);
  }
  memcpy(bin, fpos, 48); memcpy(bin + 48, fn, 48); memcpy(bin + 96, fuv, 32); memcpy(bin + 128, ft, 64);
  for (int v = 0; v < 4; v++) {
    memcpy(bin + 192 + 8 * v, qpos[v], 6);
    memcpy(bin + 224 + 4 * v, qn[v], 3);
    memcpy(bin + 240 + 4 * v, quv[v], 4);
    memcpy(bin + 256 + 4 * v, qt[v], 4);
  }
  memcpy(bin + 272, idx, 12); memcpy(bin + 284, &sparse_ix, 2); memcpy(bin + 288, sparse_pos, 6);
  FILE *f = fopen(scratch_path("quant.bin"), "wb");
  CHECK(f && fwrite(bin, 1, sizeof bin, f) == sizeof bin && !fclose(f), "write");
  static const char *const ref_attrs = "\"POSITION\": 0, \"NORMAL\": 1, \"TEXCOORD_0\": 2, \"TANGENT\": 3";
  static const char *const q_attrs = "\"POSITION\": 4, \"NORMAL\": 5, \"TEXCOORD_0\": 6, \"TANGENT\": 7";
  static const char *const q_ext = "\"extensionsUsed\": [\"KHR_mesh_quantization\"], \"extensionsRequired\": [\"KHR_mesh_quantization\"],";
  valo_error err;
  const char *t = quant_json(ref_attrs, "", ", \"uri\": \"quant.bin\"");
  scene *ref = quant_load("qref.gltf", t, strlen(t), &err);
  CHECK(ref, "%s", err.message);
  t = quant_json(q_attrs, q_ext, ", \"uri\": \"quant.bin\"");
  scene *q = quant_load("quant.gltf", t, strlen(t), &err);
  CHECK(q, "%s", err.message);
  int rc = same_arrays(q, ref, "quant.gltf");
  scene_free(q);
  /* the same in a .glb: the JSON chunk, then the buffer as its BIN chunk */
  t = quant_json(q_attrs, q_ext, "");
  size_t jl = strlen(t), jp = (jl + 3) & ~(size_t)3, n = 12 + 8 + jp + 8 + sizeof bin;
  unsigned char *g = calloc(n, 1);
  CHECK(g, "memory");
  uint32_t head[5] = {0x46546C67u, 2, (uint32_t)n, (uint32_t)jp, 0x4E4F534Au}, chunk[2] = {(uint32_t)sizeof bin, 0x004E4942u};
  memcpy(g, head, 20); memcpy(g + 20, t, jl); memset(g + 20 + jl, ' ', jp - jl); memcpy(g + 20 + jp, chunk, 8); memcpy(g + 28 + jp, bin, sizeof bin);
  q = quant_load("quant.glb", (const char *)g, n, &err);
  free(g);
  CHECK(q, "%s", err.message);
  rc |= same_arrays(q, ref, "quant.glb");
  scene_free(q);
  /* normalized texture coordinates alone are core glTF: no extension needed */
  t = quant_json("\"POSITION\": 0, \"NORMAL\": 1, \"TEXCOORD_0\": 6, \"TANGENT\": 3", "", ", \"uri\": \"quant.bin\"");
  q = quant_load("quv.gltf", t, strlen(t), &err);
  CHECK(q, "%s", err.message);
  rc |= same_arrays(q, ref, "quv.gltf");
  scene_free(q);
  scene_free(ref);
  /* kinds no rule allows: a normal of unsigned shorts, a position of unsigned ints */
  static const struct { const char *attrs, *said; } bad[] = {{"\"POSITION\": 0, \"NORMAL\": 6", "NORMAL must be 3-component floats, or normalized bytes or shorts"},
                                                              {"\"POSITION\": 8", "POSITION must be 3-component floats"}};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    t = quant_json(bad[k].attrs, q_ext, ", \"uri\": \"quant.bin\"");
    q = quant_load("qbad.gltf", t, strlen(t), &err);
    CHECK(!q && strstr(err.message, bad[k].said), "%s: %s", bad[k].attrs, q ? "loaded" : err.message);
  }
  return rc;
}

/* KHR_draco_mesh_compression (tests/data/gltf-draco, scripts/gltf-draco.py): a UV sphere
 * Draco-compressed with 32-bit indices (which Assimp 5.2 loses: valo gives them to it as
 * 16-bit ones) and with 16-bit ones loads bit for bit as the same sphere in plain float
 * accessors holding what Draco decodes (DracoPy 2.2), and so does the first beside sixteen
 * buffer files, the most valo serves; a Draco primitive naming an
 * attribute it lacks, without its bufferView, with integer texture coordinates, or of
 * more than 65 536 vertices with 32-bit indices is refused, naming why. */
static int same_mesh(const scene *a, const scene *b, const char *what) {
  CHECK(a->nverts == b->nverts && a->ntris == b->ntris && a->ntris == 224, "%s: %u and %u vertices, %u and %u triangles", what, a->nverts, b->nverts, a->ntris, b->ntris);
  CHECK(!memcmp(a->pos, b->pos, a->nverts * sizeof *a->pos) && !memcmp(a->nrm, b->nrm, a->nverts * sizeof *a->nrm) &&
        !memcmp(a->uv, b->uv, 2 * a->nverts * sizeof *a->uv) && !memcmp(a->idx, b->idx, 3 * a->ntris * sizeof *a->idx), "%s: the meshes differ", what);
  return 0;
}
static int gltf_draco(void) {
  valo_error err;
  scene *s[3];
  static const char *const names[3] = {"sphere-float", "sphere-draco32", "sphere-draco16"};
  for (int k = 0; k < 3; k++) {
    char path[1024];
    snprintf(path, sizeof path, VALO_SOURCE_DIR "/tests/data/gltf-draco/%s.gltf", names[k]);
    s[k] = scene_new(path);
    CHECK(load_mesh(s[k], path, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  }
  int rc = same_mesh(s[1], s[0], names[1]) || same_mesh(s[2], s[0], names[2]);
  for (int k = 0; k < 3; k++) scene_free(s[k]);
  /* the 32-bit sphere beside sixteen buffer files, the most valo serves: its indices still
   * given as 16-bit ones (the JSON rewritten, no buffer added) */
  char *text = read_text_file(VALO_SOURCE_DIR "/tests/data/gltf-draco/sphere-draco32.gltf"), *pad = malloc(strlen(text ? text : "") + 1200);
  CHECK(text && pad, "read");
  char *close = strchr(strstr(text, "\"buffers\": ["), ']');
  CHECK(close, "the fixture's buffers");
  size_t at = (size_t)(close - text);
  memcpy(pad, text, at);
  pad[at] = 0;
  for (int k = 0; k < 16; k++) {
    char name[32];
    snprintf(name, sizeof name, "pad%d.bin", k);
    CHECK(scratch_file(name, "abcd"), "write");
    snprintf(pad + strlen(pad), 64, ", {\"byteLength\": 4, \"uri\": \"%s\"}", name);
  }
  strcat(pad, close);
  scene *sp = quant_load("dpad.gltf", pad, strlen(pad), &err);
  free(text);
  free(pad);
  CHECK(sp && sp->ntris == 224, "sixteen buffer files: %s", sp ? "wrong triangles" : err.message);
  scene_free(sp);
  static const char *const head = "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
                                  " \"nodes\": [{\"mesh\": 0}], \"buffers\": [{\"byteLength\": 4, \"uri\": \"data:application/octet-stream;base64,AAAAAA==\"}],"
                                  " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 4}],";
  static const struct { const char *rest, *said; } bad[] = {
      {"\"accessors\": [{\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0},"
       " \"extensions\": {\"KHR_draco_mesh_compression\": {\"bufferView\": 0, \"attributes\": {\"POSITION\": 0, \"TEXCOORD_1\": 1}}}}]}]}",
       "compresses TEXCOORD_1, which the primitive's attributes lack"},
      {"\"accessors\": [{\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0},"
       " \"extensions\": {\"KHR_draco_mesh_compression\": {\"attributes\": {\"POSITION\": 0}}}}]}]}",
       "\"bufferView\""},
      {"\"accessors\": [{\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}, {\"componentType\": 5123, \"normalized\": true, \"count\": 3, \"type\": \"VEC2\"}],"
       " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1},"
       " \"extensions\": {\"KHR_draco_mesh_compression\": {\"bufferView\": 0, \"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}}}}]}]}",
       "a Draco-compressed TEXCOORD_0 of integers is not read"},
      {"\"accessors\": [{\"componentType\": 5126, \"count\": 70000, \"type\": \"VEC3\"}, {\"componentType\": 5125, \"count\": 6, \"type\": \"SCALAR\"}],"
       " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1,"
       " \"extensions\": {\"KHR_draco_mesh_compression\": {\"bufferView\": 0, \"attributes\": {\"POSITION\": 0}}}}]}]}",
       "Draco-compressed primitive of 70000 vertices with 32-bit indices is not read"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    char json[2048];
    snprintf(json, sizeof json, "%s %s", head, bad[k].rest);
    scene *q = quant_load("dbad.gltf", json, strlen(json), &err);
    CHECK(!q && strstr(err.message, bad[k].said), "case %zu: %s", k, q ? "loaded" : err.message);
  }
  return rc;
}

/* The quad y = 0, x and z in [-1, 1], with texture coordinates over [0, 1]^2 and two
 * triangles (positions, coordinates, 16-bit indices: 92 bytes) as the scratch file name. */
static int uv_quad_bin(const char *name) {
  static const float pos[12] = {-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1}, uv[8] = {0, 0, 0, 1, 1, 1, 1, 0};
  static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  unsigned char buf[92];
  memcpy(buf, pos, 48); memcpy(buf + 48, uv, 32); memcpy(buf + 80, idx, 12);
  FILE *f = fopen(scratch_path(name), "wb");
  return f && fwrite(buf, 1, 92, f) == 92 && !fclose(f);
}

/* glTF's KHR_texture_transform: a quad with texture coordinates whose base colour,
 * metallic-roughness, normal and emissive textures each carry a transform; looked up at
 * points of the quad, each equals its image looked up where the extension's formula
 * sends the point (uv' = offset + R (scale uv), R = [cos sin; -sin cos], in glTF's v-down
 * space); the extension's own example (offset (0, 1), a quarter turn, scale 0.5) maps
 * the quad onto the image's lower left quadrant; a texture on coordinate set 1 is warned
 * about; the image used through a clamping and a repeating sampler keeps both wraps. */
static int gltf_texture_transform(void) {
  unsigned char ramp[16 * 16 * 3];
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 16; x++) { unsigned char *p = &ramp[3 * (16 * y + x)]; p[0] = (unsigned char)(16 * x + 8); p[1] = (unsigned char)(16 * y + 8); p[2] = 128; }
  CHECK(scratch_png("uvramp.png", 16, 16, 3, ramp), "write");
  CHECK(uv_quad_bin("uvt.bin"), "write");
  static const struct { double off[2], rot, scale[2]; } tf[4] = {{{0.25, 0.1}, 0, {1, 1}}, {{0, 1}, M_PI / 2, {0.5, 0.5}}, {{0.3, -0.2}, 0.4, {0.7, 1.3}}, {{0.1, 0.2}, -1.1, {-0.6, 0.8}}};
  char ext[4][200];
  for (int k = 0; k < 4; k++)
    snprintf(ext[k], sizeof ext[k], "\"extensions\": {\"KHR_texture_transform\": {\"offset\": [%.17g, %.17g], \"rotation\": %.17g, \"scale\": [%.17g, %.17g]}}",
             tf[k].off[0], tf[k].off[1], tf[k].rot, tf[k].scale[0], tf[k].scale[1]);
  char json[4096];
  snprintf(json, sizeof json,
           "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_texture_transform\"], \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
           " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}, \"indices\": 2, \"material\": 0}]}],\n"
           " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, %s}, \"metallicRoughnessTexture\": {\"index\": 1, %s}},\n"
           "   \"normalTexture\": {\"index\": 0, %s}, \"emissiveTexture\": {\"index\": 0, %s}, \"emissiveFactor\": [1, 1, 1]},\n"
           "   {\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 1}}}, {\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"texCoord\": 1}}}],\n"
           " \"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 0, \"sampler\": 1}], \"images\": [{\"uri\": \"uvramp.png\"}],\n"
           " \"samplers\": [{\"wrapS\": 33071, \"wrapT\": 33071}, {\"wrapS\": 10497, \"wrapT\": 10497}],\n"
           " \"buffers\": [{\"byteLength\": 92, \"uri\": \"uvt.bin\"}],\n"
           " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 32},\n"
           "   {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 12}],\n"
           " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1, 0, -1], \"max\": [1, 0, 1]},\n"
           "   {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n",
           ext[0], ext[1], ext[2], ext[3]);
  const char *path = scratch_file("uvt.gltf", json);
  CHECK(path, "write");
  scene *s = scene_new(path);
  valo_error err;
  warnings_capture(1);
  valo_status st = load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, &err);
  int set1 = strstr(warnings_text(), "material 2: a texture reads texture coordinate set 1") != NULL;
  warnings_capture(0);
  CHECK(st == VALO_OK, "%s", err.message);
  CHECK(set1, "the texture on coordinate set 1 was not warned about");
  const material *m = &s->mats[s->tri_mat[0]];
  const int slots[4] = {m->tex_kd, m->tex_mr, m->tex_normal, m->tex_ke};
  /* one image through two samplers (the base colour clamps, the metallic-roughness repeats): each keeps its wrap */
  CHECK(s->tex[m->tex_kd].smp.wrap == TEX_CLAMP && s->tex[m->tex_mr].smp.wrap == TEX_REPEAT, "the image's two samplers: wraps %d and %d",
        (int)s->tex[m->tex_kd].smp.wrap, (int)s->tex[m->tex_mr].smp.wrap);
  for (int k = 0; k < 4; k++) {
    CHECK(slots[k] >= 0 && s->tex[slots[k]].smp.has_uvm, "slot %d: no transformed texture", k);
    texture base = s->tex[slots[k]];
    base.smp.has_uvm = 0;
    double c = cos(tf[k].rot), sn = sin(tf[k].rot);
    float lo[2] = {1, 1}, hi[2] = {0, 0};
    for (int i = 0; i < 9; i++) {
      float u = 0.05f + 0.45f * (float)(i % 3), v = 0.05f + 0.45f * (float)(i / 3); /* valo's (v up) */
      double gu = u, gv = 1 - v;                                                    /* glTF's (v down) */
      double su = tf[k].scale[0] * gu, sv = tf[k].scale[1] * gv;
      double tu = tf[k].off[0] + c * su + sn * sv, tv = tf[k].off[1] - sn * su + c * sv;
      float got[4], want[4];
      texture_lookup(&s->tex[slots[k]], u, v, got);
      texture_lookup(&base, (float)tu, (float)(1 - tv), want);
      for (int ch = 0; ch < 3; ch++)
        CHECK(fabsf(got[ch] - want[ch]) < 2e-3f, "slot %d at (%g, %g): %g, the image at glTF's (%g, %g): %g", k, u, v, got[ch], tu, tv, want[ch]);
      if (k == 1) { /* the example: inside the lower left quadrant (valo's v up) */
        float vu = (float)tu, vv = (float)(1 - tv);
        lo[0] = fminf(lo[0], vu); lo[1] = fminf(lo[1], vv); hi[0] = fmaxf(hi[0], vu); hi[1] = fmaxf(hi[1], vv);
      }
    }
    if (k == 1) CHECK(lo[0] >= -1e-6f && lo[1] >= -1e-6f && hi[0] <= 0.5f + 1e-6f && hi[1] <= 0.5f + 1e-6f, "the example reaches (%g, %g) to (%g, %g)", lo[0], lo[1], hi[0], hi[1]);
  }
  scene_free(s);
  return 0;
}

/* glTF's KHR_materials_ior, KHR_materials_specular, KHR_materials_clearcoat and
 * KHR_materials_sheen on the opaque model (pbr's "ior", "specular", "specular_color",
 * "clearcoat", "clearcoat_roughness", "sheen_color", "sheen_roughness"): F0 = min(((ior - 1) / (ior + 1))^2 colour, 1) factor and
 * F90 = factor; the specular lobe at normal incidence scales by F0 / 0.04 against the
 * default material, at grazing the dielectric's Fresnel reaches F90; the sheen alone is
 * colour D V as the extension's formulas give it; a glTF quad with the extensions gets
 * those values and renders as the JSON pbr material with the same keys;
 * KHR_materials_specular is no longer warned about. */
static int gltf_pbr_extensions(void) {
  material d = material_default(), m = material_default();
  d.type = m.type = MAT_PBR;
  d.kd = m.kd = c3(0, 0, 0);
  d.metallic = m.metallic = 0;
  d.roughness = m.roughness = 0.3f;
  material_pbr_specular(&m, 1.33f, 0.5f, c3(1, 0.5f, 0.25f));
  double r = 0.33 / 2.33, f0 = r * r;
  const double want[3] = {f0 * 0.5, f0 * 0.5 * 0.5, f0 * 0.25 * 0.5};
  CHECK(fabs(m.f0.r - want[0]) < 1e-7 && fabs(m.f0.g - want[1]) < 1e-7 && fabs(m.f0.b - want[2]) < 1e-7 && m.f90 == 0.5f, "F0 (%g %g %g), F90 %g", m.f0.r,
        m.f0.g, m.f0.b, m.f90);
  bsdf bd = bsdf_from_material(&d), bm = bsdf_from_material(&m);
  rgb ed = bsdf_eval(&bd, v3(0, 0, 1), v3(0, 0, 1)), em = bsdf_eval(&bm, v3(0, 0, 1), v3(0, 0, 1));
  CHECK(fabs(em.r / ed.r - want[0] / 0.04) < 1e-4 * want[0] / 0.04 && fabs(em.b / ed.b - want[2] / 0.04) < 1e-4 * want[2] / 0.04,
        "at normal incidence (%g %g %g) against the default's %g", em.r, em.g, em.b, ed.r);
  vec3 wo = v3(sinf(1.55f), 0, cosf(1.55f)), wi = v3(-wo.x, 0, wo.z); /* grazing mirror pair: v.h = cos 1.55 */
  rgb gd = bsdf_eval(&bd, wo, wi), gm = bsdf_eval(&bm, wo, wi);
  double s5 = pow(1 - cos(1.55), 5), Fd = 0.04 + 0.96 * s5, Fm = want[0] + (0.5 - want[0]) * s5;
  CHECK(fabs(gm.r / gd.r - Fm / Fd) < 1e-3 * Fm / Fd, "at grazing %g, the default %g: ratio %g, expected %g", gm.r, gd.r, gm.r / gd.r, Fm / Fd);
  /* the clearcoat at normal incidence: f (1 - c 0.04) + c 0.04 D(n) / 4, D(n) = 1 / (pi alpha^2), G = 1 there */
  material cm = d;
  cm.clearcoat = 0.8f;
  cm.clearcoat_roughness = 0.3f;
  bsdf bc = bsdf_from_material(&cm);
  rgb ec = bsdf_eval(&bc, v3(0, 0, 1), v3(0, 0, 1));
  double ac = 0.09, coat = ed.r * (1 - 0.8 * 0.04) + 0.8 * 0.04 / (4 * M_PI * ac * ac);
  CHECK(fabs(ec.r - coat) < 1e-4 * coat, "the clearcoat at normal incidence: %g, expected %g", ec.r, coat);
  /* the sheen alone (a black base of specular 0): colour D(h) V(o, i), the glTF spec's formulas */
  material sm = d;
  material_pbr_specular(&sm, 1.5f, 0, c3(1, 1, 1));
  sm.sheen_color = c3(0.9f, 0.6f, 0.3f);
  sm.sheen_roughness = 0.4f;
  sheen_prepare(&sm);
  bsdf bs = bsdf_from_material(&sm);
  vec3 so = v3(sinf(1.2f), 0, cosf(1.2f)), si = v3(-sinf(0.5f) * 0.6f, sinf(0.5f) * 0.8f, cosf(0.5f));
  vec3 sh = v3_norm(v3_add(so, si));
  double inv = 1 / 0.4, D = (2 + inv) * pow(1 - sh.z * sh.z, inv / 2) / (2 * M_PI), lam[2], mu[2] = {so.z, si.z};
  for (int k = 0; k < 2; k++) {
    double t = 0.36, x = mu[k] < 0.5 ? mu[k] : 0.5, l[2];
    for (int q = 0; q < 2; q++) {
      double xx = q ? 1 - mu[k] : x;
      l[q] = (21.5473 + 3.7772 * t) / (1 + (3.82987 - 0.50552 * t) * pow(xx, 0.19823 - 0.03022 * t)) + (-1.97760 + 0.70367 * t) * xx + (-4.32054 - 0.53913 * t);
    }
    double lhalf = (21.5473 + 3.7772 * t) / (1 + (3.82987 - 0.50552 * t) * pow(0.5, 0.19823 - 0.03022 * t)) + (-1.97760 + 0.70367 * t) * 0.5 + (-4.32054 - 0.53913 * t);
    lam[k] = mu[k] < 0.5 ? exp(l[0]) : exp(2 * lhalf - l[1]);
  }
  double V = 1 / ((1 + lam[0] + lam[1]) * 4 * mu[0] * mu[1]);
  rgb es = bsdf_eval(&bs, so, si);
  CHECK(fabs(es.r - 0.9 * D * V) < 1e-4 * 0.9 * D * V && fabs(es.b - 0.3 * D * V) < 1e-4 * 0.3 * D * V, "the sheen alone: %g %g %g, expected %g", es.r, es.g, es.b,
        0.9 * D * V);
  /* the same through a glTF file and a JSON material */
  /* the second of two materials, which Assimp, meeting it first, numbers 0 */
  static const char *const mat =
      "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.6, 0.4, 0.3, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.3}},\n"
      "   {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.6, 0.4, 0.2, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.3}, \"extensions\": {"
      "\"KHR_materials_ior\": {\"ior\": 1.33}, \"KHR_materials_specular\": {\"specularFactor\": 0.5, \"specularColorFactor\": [1, 0.5, 0.25]},"
      " \"KHR_materials_clearcoat\": {\"clearcoatFactor\": 0.8, \"clearcoatRoughnessFactor\": 0.3},"
      " \"KHR_materials_sheen\": {\"sheenColorFactor\": [0.9, 0.6, 0.3], \"sheenRoughnessFactor\": 0.4}}}";
  CHECK(gltf_quad("spec", 0, 0, NULL, mat, "[\"KHR_materials_ior\", \"KHR_materials_specular\", \"KHR_materials_clearcoat\", \"KHR_materials_sheen\"]", 1), "write");
  scene *s = scene_new(scratch_path("spec.gltf"));
  valo_error err;
  warnings_capture(1);
  valo_status st = load_mesh(s, scratch_path("spec.gltf"), NULL, UINT32_MAX, 0, NULL, &err);
  int warned = warnings_text()[0] != 0;
  warnings_capture(0);
  CHECK(st == VALO_OK, "%s", err.message);
  const material *g = &s->mats[s->tri_mat[0]];
  CHECK(!warned && g->type == MAT_PBR && fabs(g->f0.r - want[0]) < 1e-7 && fabs(g->f0.b - want[2]) < 1e-7 && g->f90 == 0.5f && g->clearcoat == 0.8f &&
            g->clearcoat_roughness == 0.3f && g->sheen_color.g == 0.6f && g->sheen_roughness == 0.4f && g->sheen_E[SHEEN_RES - 1] == sm.sheen_E[SHEEN_RES - 1],
        "glTF: F0 (%g %g %g), F90 %g, clearcoat %g of roughness %g, sheen %g of roughness %g%s", g->f0.r, g->f0.g, g->f0.b, g->f90, g->clearcoat,
        g->clearcoat_roughness, g->sheen_color.g, g->sheen_roughness, warned ? ", warned" : "");
  scene_free(s);
  double mean[2];
  for (int k = 0; k < 2; k++) {
    char scn[1200];
    snprintf(scn, sizeof scn,
             "{ \"camera\": {\"position\": [0, 3, 2], \"look_at\": [0,0,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16},\n"
             "  \"environment\": {\"type\": \"constant\", \"radiance\": 0.5},\n"
             "  \"materials\": {\"p\": {\"type\": \"pbr\", \"base_color\": [0.6, 0.4, 0.2], \"metallic\": 0, \"roughness\": 0.3, \"ior\": 1.33,\n"
             "    \"specular\": 0.5, \"specular_color\": [1, 0.5, 0.25], \"clearcoat\": 0.8, \"clearcoat_roughness\": 0.3,\n"
             "    \"sheen_color\": [0.9, 0.6, 0.3], \"sheen_roughness\": 0.4}},\n"
             "  \"shapes\": [{\"file\": \"spec.gltf\"%s}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n",
             k ? ", \"material\": \"p\"" : "");
    mean[k] = render_json_mean_green(scn);
    CHECK(mean[k] > 0, "render failed");
  }
  fprintf(stderr, "glTF %.7f, JSON %.7f\n", mean[0], mean[1]);
  CHECK(mean[0] == mean[1], "glTF %g against the JSON pbr %g", mean[0], mean[1]);
  return 0;
}

/* KHR_materials_clearcoat's textures (pbr's "clearcoat_map", R times clearcoat, and
 * "clearcoat_roughness_map", G times clearcoat_roughness) and KHR_materials_sheen's colour
 * texture ("sheen_map", sRGB, times sheen_color): a black glTF quad of specular 0 (only
 * its coat and sheen reflect), filling the view, whose coat, the coat's roughness and the
 * sheen colour come from a 1 x 1 image (128, 64, 0) loads the three slots without a
 * warning and renders bit for bit as the JSON pbr with the three maps, within 1e-5 of the
 * uniform coat 0.8 x 128/255 of roughness 0.6 x 64/255 and sheen 0.8 x the image's
 * decoded colour, and more than 1 % from the material without the maps. */
static int gltf_clearcoat_maps(void) {
  unsigned char px[3] = {128, 64, 0};
  CHECK(scratch_png("cc.png", 1, 1, 3, px), "write");
  CHECK(uv_quad_bin("ccq.bin"), "write");
  const char *path = scratch_file("ccq.gltf",
      "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_materials_clearcoat\", \"KHR_materials_specular\", \"KHR_materials_sheen\"], \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
      " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}, \"indices\": 2, \"material\": 0}]}],\n"
      " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.5},\n"
      "   \"extensions\": {\"KHR_materials_specular\": {\"specularFactor\": 0}, \"KHR_materials_clearcoat\": {\"clearcoatFactor\": 0.8, \"clearcoatTexture\": {\"index\": 0},\n"
      "     \"clearcoatRoughnessFactor\": 0.6, \"clearcoatRoughnessTexture\": {\"index\": 0}},\n"
      "     \"KHR_materials_sheen\": {\"sheenColorFactor\": [0.8, 0.8, 0.8], \"sheenRoughnessFactor\": 0.5, \"sheenColorTexture\": {\"index\": 0}}}}],\n"
      " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"cc.png\"}],\n"
      " \"buffers\": [{\"byteLength\": 92, \"uri\": \"ccq.bin\"}],\n"
      " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 32},\n"
      "   {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 12}],\n"
      " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1, 0, -1], \"max\": [1, 0, 1]},\n"
      "   {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n");
  CHECK(path, "write");
  scene *s = scene_new(path);
  valo_error err;
  warnings_capture(1);
  valo_status st = load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, &err);
  int warned = warnings_text()[0] != 0;
  warnings_capture(0);
  CHECK(st == VALO_OK, "%s", err.message);
  const material *g = &s->mats[s->tri_mat[0]];
  CHECK(!warned && g->tex_cc >= 0 && g->tex_ccr >= 0 && g->tex_sheen >= 0 && g->clearcoat == 0.8f && g->clearcoat_roughness == 0.6f,
        "glTF: slots %d %d %d, clearcoat %g of roughness %g%s", g->tex_cc, g->tex_ccr, g->tex_sheen, g->clearcoat, g->clearcoat_roughness, warned ? ", warned" : "");
  scene_free(s);
  char cc[64], ccr[160];
  snprintf(cc, sizeof cc, "%.9g", 0.8 * 128 / 255.0);
  snprintf(ccr, sizeof ccr, "%.9g, \"sheen_color\": [%.9g, %.9g, 0]", 0.6 * 64 / 255.0, 0.8 * pow((128 / 255.0 + 0.055) / 1.055, 2.4),
           0.8 * pow((64 / 255.0 + 0.055) / 1.055, 2.4));
  const char *mats[4][2] = {{NULL, NULL}, {"0.8, \"clearcoat_map\": \"cc.png\"", "0.6, \"clearcoat_roughness_map\": \"cc.png\", \"sheen_color\": 0.8, \"sheen_map\": \"cc.png\""},
                            {cc, ccr}, {"0.8", "0.6, \"sheen_color\": 0.8"}};
  double mean[4];
  for (int k = 0; k < 4; k++) {
    char scn[1400];
    snprintf(scn, sizeof scn,
             "{ \"camera\": {\"position\": [0, 2, 0.5], \"look_at\": [0,0,0], \"fov\": 40},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16},\n"
             "  \"environment\": {\"type\": \"constant\", \"radiance\": 1},\n"
             "  \"materials\": {\"p\": {\"type\": \"pbr\", \"base_color\": 0, \"specular\": 0, \"metallic\": 0, \"roughness\": 0.5,\n"
             "    \"sheen_roughness\": 0.5, \"clearcoat\": %s, \"clearcoat_roughness\": %s}},\n"
             "  \"shapes\": [{\"file\": \"ccq.gltf\"%s}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n",
             k ? mats[k][0] : "0", k ? mats[k][1] : "0", k ? ", \"material\": \"p\"" : "");
    mean[k] = render_json_mean_green(scn);
    CHECK(mean[k] > 0, "render %d failed", k);
  }
  fprintf(stderr, "glTF %.7f, JSON maps %.7f, JSON uniform %.7f, without maps %.7f\n", mean[0], mean[1], mean[2], mean[3]);
  CHECK(mean[0] == mean[1], "glTF %g against the JSON maps' %g", mean[0], mean[1]);
  CHECK(fabs(mean[1] - mean[2]) < 1e-5 * mean[2], "the maps %g against the uniform coat %g", mean[1], mean[2]);
  CHECK(fabs(mean[3] - mean[1]) > 0.01 * mean[1], "the maps make no difference (%g, %g)", mean[1], mean[3]);
  return 0;
}

/* Texture objects (docs/scene-format.md, "Textures"): nearest and bilinear lookups, a map
 * of the texture coordinates, the checkerboard; one image sampled two ways is two
 * textures sharing its pixels, the same way twice is one; bad objects are refused,
 * naming the key. */
static float lum_at(const scene *s, int t, float u, float v) {
  float o[4];
  texture_lookup(&s->tex[t], u, v, o);
  return o[0];
}

static int texture_objects(void) {
  /* a 4 x 1 ramp 0, 1, 2, 3 (as 8-bit 0, 60, 120, 180, read raw) */
  unsigned char g[4] = {0, 60, 120, 180};
  CHECK(scratch_png("ramp4.png", 4, 1, 1, g) && scratch_file("tfloor.obj", UV_QUAD_2), "write");
  const char *json =
      "{ \"materials\": {\n"
      "  \"near\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"ramp4.png\", \"raw\": true, \"filter\": \"nearest\", \"wrap\": \"clamp\"}},\n"
      "  \"near2\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"ramp4.png\", \"raw\": true, \"filter\": \"nearest\", \"wrap\": \"clamp\"}},\n"
      "  \"plain\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"ramp4.png\", \"raw\": true}},\n"
      "  \"moved\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"ramp4.png\", \"raw\": true, \"uv_scale\": [2, 1], \"uv_offset\": [0.125, 0]}},\n"
      "  \"turned\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"ramp4.png\", \"raw\": true, \"filter\": \"nearest\", \"uv_matrix\": [0, 1, 0, 1, 0, 0]}},\n"
      "  \"check\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"checkerboard\", \"color0\": 0.9, \"color1\": [0.1, 0.2, 0.3], \"uv_scale\": [4, 4]}}},\n"
      "  \"shapes\": [{\"file\": \"tfloor.obj\", \"material\": \"near\"}, {\"file\": \"tfloor.obj\", \"material\": \"near2\"},\n"
      "    {\"file\": \"tfloor.obj\", \"material\": \"plain\"}, {\"file\": \"tfloor.obj\", \"material\": \"moved\"},\n"
      "    {\"file\": \"tfloor.obj\", \"material\": \"turned\"}, {\"file\": \"tfloor.obj\", \"material\": \"check\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n";
  scene *s = NULL;
  valo_error err;
  valo_options file;
  CHECK(scene_load(scratch_file("texobj.json", json), NULL, &s, &file, &err) == VALO_OK, "%s", err.message);
  int t[6];
  for (int i = 0; i < 6; i++) {
    static const char *const names[6] = {"near", "near2", "plain", "moved", "turned", "check"};
    const material *m = material_named(s, names[i]);
    CHECK(m, "no material %s", names[i]);
    t[i] = m->tex_kd;
    CHECK(t[i] >= 0, "%s has no texture", names[i]);
  }
  float q = 60 / 255.0f;
  CHECK(t[0] == t[1], "the same sampling twice gave textures %d and %d", t[0], t[1]);
  CHECK(t[0] != t[2] && s->tex[t[0]].px == s->tex[t[2]].px && s->tex[t[0]].shares_px + s->tex[t[2]].shares_px == 1,
        "nearest and bilinear lookups of one image do not share its pixels once");
  /* nearest, clamped: u = 0.3 is texel 1 whole; u = 1.4 clamps to texel 3 */
  CHECK(fabsf(lum_at(s, t[0], 0.3f, 0.5f) - q) < 1e-5f && fabsf(lum_at(s, t[0], 1.4f, 0.5f) - 3 * q) < 1e-5f, "nearest/clamp: %g %g",
        lum_at(s, t[0], 0.3f, 0.5f), lum_at(s, t[0], 1.4f, 0.5f));
  /* bilinear, repeating: u = 0.25 is halfway between texels 0 and 1; u = 1.125 is texel 0 */
  CHECK(fabsf(lum_at(s, t[2], 0.25f, 0.5f) - q / 2) < 1e-5f && fabsf(lum_at(s, t[2], 1.125f, 0.5f)) < 1e-5f, "bilinear: %g %g",
        lum_at(s, t[2], 0.25f, 0.5f), lum_at(s, t[2], 1.125f, 0.5f));
  /* u' = 2u + 0.125: u = 0.25 looks up 0.625, texel 2's centre */
  CHECK(fabsf(lum_at(s, t[3], 0.25f, 0.5f) - 2 * q) < 1e-5f, "uv_scale and uv_offset: %g", lum_at(s, t[3], 0.25f, 0.5f));
  /* u' = v: v = 0.9 is texel 3 whatever u is */
  CHECK(fabsf(lum_at(s, t[4], 0.1f, 0.9f) - 3 * q) < 1e-5f, "uv_matrix: %g", lum_at(s, t[4], 0.1f, 0.9f));
  /* 8 x 8 squares: color0 where the square's u and v halves of a repeat differ (top-left
   * and bottom-right of each 2 x 2), color1 where they agree */
  float o[4];
  texture_lookup(&s->tex[t[5]], 0.05f, 0.2f, o);
  CHECK(fabsf(o[0] - 0.9f) < 1e-6f && fabsf(o[2] - 0.9f) < 1e-6f, "checkerboard at (0.05, 0.2): %g %g %g", o[0], o[1], o[2]);
  texture_lookup(&s->tex[t[5]], 0.05f, 0.05f, o);
  CHECK(fabsf(o[0] - 0.1f) < 1e-6f && fabsf(o[2] - 0.3f) < 1e-6f, "checkerboard at (0.05, 0.05): %g %g %g", o[0], o[1], o[2]);
  texture_lookup(&s->tex[t[5]], 0.2f, 0.05f, o);
  CHECK(fabsf(o[0] - 0.9f) < 1e-6f, "checkerboard at (0.2, 0.05): %g", o[0]);
  scene_free(s);
  static const struct { const char *tex, *says; } bad[] = {
      {"{\"file\": \"ramp4.png\", \"wrap\": \"tile\"}", "\"wrap\" must be"},
      {"{\"file\": \"ramp4.png\", \"filter\": \"cubic\"}", "\"filter\" must be"},
      {"{\"file\": \"ramp4.png\", \"uv_matrix\": [1, 0, 0, 0, 1, 0], \"uv_scale\": [2, 2]}", "not both"},
      {"{\"file\": \"ramp4.png\", \"uv_scale\": [2]}", "array of 2 numbers"},
      {"{\"file\": \"nothere.png\"}", "cannot open the normal map"},
      {"{\"raw\": true}", "needs \"file\""},
      {"{\"type\": \"checkerboard\", \"file\": \"ramp4.png\"}", "has no file"},
      {"{\"type\": \"checkerboard\", \"color0\": -1}", "must not be negative"},
      {"{\"type\": \"noise\"}", "\"type\" must be"},
      {"{\"file\": \"ramp4.png\", \"scale\": 2}", "unknown key"},
      {"[1, 2]", "must be a file name or a texture object"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char bj[1024];
    /* a normal map reads any texture value, a colour only an object or a string */
    snprintf(bj, sizeof bj, "{ \"materials\": {\"f\": {\"type\": \"diffuse\", \"normal_map\": %s}}, \"shapes\": [{\"file\": \"tfloor.obj\", \"material\": \"f\"}] }\n",
             bad[i].tex);
    valo_scene *sc = NULL;
    CHECK(valo_scene_load(scratch_file("bad-tex.json", bj), &sc, &err) != VALO_OK, "case %zu loaded", i);
    CHECK(strstr(err.message, bad[i].says) && strstr(err.message, "materials.f.normal_map"), "case %zu: \"%s\" does not say \"%s\"", i, err.message,
          bad[i].says);
  }
  return 0;
}

/* Roughness and metallic maps (JSON "roughness_map", "roughness_map_is_alpha",
 * "metallic_map") multiply their parameter: a rough aluminium floor whose map holds 0.302
 * renders as roughness 0.302 (or, read as alpha, as roughness sqrt(0.302)); a principled
 * metal map as that metallic. "smith": "separable" darkens a rough metal (Smith's separable
 * G is below the height-correlated one). Means of the same seed's renders within 0.3 %;
 * roughness 0.4 instead of 0.302 is several times that apart. */
static double floor_mean(const char *mat) {
  char json[1500];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0, 1.5, 2.5], \"look_at\": [0, 0, 0], \"fov\": 50},\n"
           "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 64, \"max_depth\": 1},\n"
           "  \"materials\": {\"f\": %s},\n  \"shapes\": [{\"file\": \"rfloor.obj\", \"material\": \"f\"}],\n"
           "  \"lights\": [{\"type\": \"point\", \"position\": [0, 2, -0.5], \"intensity\": 10}] }\n",
           mat);
  return render_json_mean_green(json);
}

static int roughness_maps(void) {
  unsigned char g = 77; /* 0.302, read raw */
  char png[1200];
  snprintf(png, sizeof png, "%s/r77.png", scratch_dir());
  CHECK(stbi_write_png(png, 1, 1, 1, &g, 1), "write");
  CHECK(scratch_file("rfloor.obj", UV_QUAD_10), "write");
  const double r = 77 / 255.0;
  char m[6][300];
  snprintf(m[0], sizeof m[0], "{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 1, \"roughness_map\": \"r77.png\"}");
  snprintf(m[1], sizeof m[1], "{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": %.9g}", r);
  snprintf(m[2], sizeof m[2], "{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 1, \"roughness_map\": \"r77.png\", \"roughness_map_is_alpha\": true}");
  snprintf(m[3], sizeof m[3], "{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": %.9g}", sqrt(r));
  snprintf(m[4], sizeof m[4], "{\"type\": \"principled\", \"base_color\": [0.8, 0.6, 0.4], \"roughness\": 0.4, \"metallic\": 1, \"metallic_map\": \"r77.png\"}");
  snprintf(m[5], sizeof m[5], "{\"type\": \"principled\", \"base_color\": [0.8, 0.6, 0.4], \"roughness\": 0.4, \"metallic\": %.9g}", r);
  double v[6];
  for (int i = 0; i < 6; i++) CHECK((v[i] = floor_mean(m[i])) > 0, "render %d failed", i);
  double other = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 0.4}");
  double corr = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 0.9}");
  double sep = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 0.9, \"smith\": \"separable\"}");
  fprintf(stderr, "map %.5f, number %.5f; as alpha %.5f, number %.5f; metallic map %.5f, number %.5f; roughness 0.4: %.5f; "
                  "roughness 0.9 correlated %.5f, separable %.5f\n", v[0], v[1], v[2], v[3], v[4], v[5], other, corr, sep);
  for (int i = 0; i < 6; i += 2) CHECK(fabs(v[i] / v[i + 1] - 1) < 0.003, "pair %d: %.5f against %.5f", i / 2, v[i], v[i + 1]);
  CHECK(fabs(other / v[1] - 1) > 0.01, "roughness 0.4 is not told from 0.302: %.5f against %.5f", other, v[1]);
  CHECK(sep < corr * 0.99, "the separable G is not darker: %.5f against %.5f", sep, corr);
  valo_scene *sc = NULL;
  valo_error err;
  const char *bad = scratch_file("bad-smith.json", "{ \"materials\": {\"f\": {\"type\": \"conductor\", \"preset\": \"Au\", \"smith\": \"joint\"}}, \"shapes\": [{\"file\": \"rfloor.obj\", \"material\": \"f\"}] }\n");
  CHECK(valo_scene_load(bad, &sc, &err) != VALO_OK && strstr(err.message, "materials.f") && strstr(err.message, "smith must be"), "%s", err.message);
  bad = scratch_file("bad-plastic-map.json", "{ \"materials\": {\"f\": {\"type\": \"plastic\", \"roughness_map\": \"r77.png\"}}, \"shapes\": [{\"file\": \"rfloor.obj\", \"material\": \"f\"}] }\n");
  CHECK(valo_scene_load(bad, &sc, &err) != VALO_OK && strstr(err.message, "unknown key \"roughness_map\""), "%s", err.message);
  return 0;
}

/* "luminance": a texture read as one number per texel, linear sRGB's Y in every channel
 * and alpha 1, as Mitsuba reads a bitmap given for a number: a red pixel (sRGB-decoded 1,
 * 0, 0) gives 0.212671; a white pixel of alpha 0 as an opacity map is opaque with it (its
 * alpha ignored, as Mitsuba does) and transparent without; the colour and luminance
 * readings of one file are two textures. */
static int luminance_textures(void) {
  unsigned char red[3] = {255, 0, 0}, clear[4] = {255, 255, 255, 0};
  CHECK(scratch_png("red1.png", 1, 1, 3, red) && scratch_png("clear1.png", 1, 1, 4, clear) && scratch_file("lfloor.obj", UV_QUAD_2), "write");
  const char *json =
      "{ \"materials\": {\n"
      "  \"colour\": {\"type\": \"diffuse\", \"reflectance\": \"red1.png\"},\n"
      "  \"y\": {\"type\": \"diffuse\", \"reflectance\": {\"file\": \"red1.png\", \"luminance\": true}},\n"
      "  \"holey\": {\"type\": \"diffuse\", \"opacity\": \"clear1.png\"},\n"
      "  \"solid\": {\"type\": \"diffuse\", \"opacity\": {\"file\": \"clear1.png\", \"luminance\": true}}},\n"
      "  \"shapes\": [{\"file\": \"lfloor.obj\", \"material\": \"colour\"}, {\"file\": \"lfloor.obj\", \"material\": \"y\"},\n"
      "    {\"file\": \"lfloor.obj\", \"material\": \"holey\"}, {\"file\": \"lfloor.obj\", \"material\": \"solid\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 10}] }\n";
  scene *s = NULL;
  valo_error err;
  valo_options file;
  CHECK(scene_load(scratch_file("lum.json", json), NULL, &s, &file, &err) == VALO_OK, "%s", err.message);
  const material *m[4];
  static const char *const names[4] = {"colour", "y", "holey", "solid"};
  for (int i = 0; i < 4; i++) CHECK((m[i] = material_named(s, names[i])), "no material %s", names[i]);
  float o[4], y[4];
  texture_lookup(&s->tex[m[0]->tex_kd], 0.5f, 0.5f, o);
  texture_lookup(&s->tex[m[1]->tex_kd], 0.5f, 0.5f, y);
  CHECK(m[0]->tex_kd != m[1]->tex_kd && o[0] == 1 && o[1] == 0, "the colour reading: texture %d (%g %g %g)", m[0]->tex_kd, o[0], o[1], o[2]);
  CHECK(fabsf(y[0] - 0.212671f) < 1e-6f && y[1] == y[0] && y[2] == y[0] && y[3] == 1, "luminance (%g %g %g %g), not 0.212671", y[0], y[1], y[2], y[3]);
  const texture *h = &s->tex[m[2]->tex_alpha], *so = &s->tex[m[3]->tex_alpha];
  CHECK(h->has_alpha && m[2]->alpha_channel && h->px[3] == 0, "without luminance the opacity map reads its alpha (0)");
  CHECK(!so->has_alpha && !m[3]->alpha_channel && so->px[0] == 1, "with luminance the opacity map reads %g from channel %d", so->px[0], m[3]->alpha_channel);
  scene_free(s);
  return 0;
}

/* Anisotropic roughness (roughness_u along the surface's u direction, roughness_v along
 * v) on a rough aluminium floor lit across it: equal values render bit for bit as
 * "roughness"; u 0.2, v 0.6 differs from its swap by more than 1 %; and on a floor whose
 * texture coordinates are turned by 90 degrees it renders as the swap does on the first
 * (within 0.3 %: the frame follows the UVs). One of the two alone, or with roughness, is
 * refused. */
static int anisotropic_roughness(void) {
  CHECK(scratch_file("rfloor.obj", UV_QUAD_10) &&
            scratch_file("rfloor-turned.obj", "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nvt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nf 1/1 2/2 3/3 4/4\n"),
        "write");
  double iso = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness\": 0.4}");
  double same = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness_u\": 0.4, \"roughness_v\": 0.4}");
  double a = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness_u\": 0.2, \"roughness_v\": 0.6}");
  double b = floor_mean("{\"type\": \"conductor\", \"preset\": \"Al\", \"roughness_u\": 0.6, \"roughness_v\": 0.2}");
  char json[1500];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0, 1.5, 2.5], \"look_at\": [0, 0, 0], \"fov\": 50},\n"
           "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 64, \"max_depth\": 1},\n"
           "  \"materials\": {\"f\": {\"type\": \"conductor\", \"preset\": \"Al\", \"roughness_u\": 0.2, \"roughness_v\": 0.6}},\n"
           "  \"shapes\": [{\"file\": \"rfloor-turned.obj\", \"material\": \"f\"}],\n"
           "  \"lights\": [{\"type\": \"point\", \"position\": [0, 2, -0.5], \"intensity\": 10}] }\n");
  double turned = render_json_mean_green(json);
  fprintf(stderr, "roughness 0.4 %.6f, u = v = 0.4 %.6f; u 0.2 v 0.6 %.6f, u 0.6 v 0.2 %.6f; u 0.2 v 0.6 on the turned UVs %.6f\n", iso, same, a, b, turned);
  CHECK(iso > 0 && same == iso, "u = v = 0.4 is not roughness 0.4");
  CHECK(a > 0 && b > 0 && fabs(a / b - 1) > 0.01, "u and v swapped render alike: %.6f, %.6f", a, b);
  CHECK(turned > 0 && fabs(turned / b - 1) < 0.003, "on turned UVs %.6f, the swap on the first %.6f", turned, b);
  static const struct { const char *mat, *says; } bad[] = {
      {"{\"type\": \"conductor\", \"preset\": \"Au\", \"roughness_u\": 0.2}", "give both roughness_u and roughness_v"},
      {"{\"type\": \"dielectric\", \"roughness\": 0.3, \"roughness_u\": 0.2, \"roughness_v\": 0.5}", "not both"},
      {"{\"type\": \"plastic\", \"roughness_u\": 0.2, \"roughness_v\": 0.5}", "unknown key \"roughness_u\""}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char mats[400];
    snprintf(mats, sizeof mats, "\"f\": %s", bad[i].mat);
    if (material_refused("rfloor.obj", mats, bad[i].says)) return 1;
  }
  return 0;
}

/* write_gltf_quad's .gltf with a flat grey base-colour texture beside it. */
static int write_plain_gltf_quad(const char *name) {
  unsigned char grey[64];
  memset(grey, 200, sizeof grey);
  char dp[1200];
  snprintf(dp, sizeof dp, "%s/quad-texture.png", scratch_dir());
  if (!stbi_write_png(dp, 4, 4, 4, grey, 16)) return -1;
  return write_gltf_quad(name, NULL, 0, "", 0);
}

/* Normal maps in shading: a map tilting the normal 30 degrees towards +T on a
 * diffuse quad (albedo 0.5) under a directional light of irradiance 2. Light along the
 * geometric normal: radiance 0.5 * 2 cos 30 / pi, whichever way the normal tilts; light
 * from 30 degrees off towards where the normal should tilt: 0.5 * 2 / pi (60 degrees
 * off if it tilted the other way: half that), under Mitsuba's conventions times the
 * shadowing term (0.99655 there). T is +x for plain UVs, -x for mirrored UVs (u -> 1 - u),
 * and +y for the glTF quad read with map_style "tangents", whose TANGENT attribute says +y.
 * Within 1e-3. */
static int normal_map_shading(void) {
  allow_shading_loss(TILT_LOSS);
  unsigned char bytes[4 * 4 * 3];
  const double th = 30 * M_PI / 180, nt[3] = {sin(th), 0, cos(th)};
  for (int i = 0; i < 16; i++)
    for (int c = 0; c < 3; c++) bytes[3 * i + c] = (unsigned char)lrint((nt[c] * 0.5 + 0.5) * 255);
  char png[1200];
  snprintf(png, sizeof png, "%s/tilt30.png", scratch_dir());
  CHECK(stbi_write_png(png, 4, 4, 3, bytes, 12), "png");
  /* the 8-bit map's own tilt: what the expected values use */
  double m[3], len = 0;
  for (int c = 0; c < 3; c++) { m[c] = bytes[c] / 255.0 * 2 - 1; len += m[c] * m[c]; }
  double cos_t = m[2] / sqrt(len), sin_t = m[0] / sqrt(len);
  CHECK(scratch_file("nq_plain.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n") &&
            scratch_file("nq_mirror.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nvt 1 0\nvt 0 0\nvt 0 1\nvt 1 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"),
        "write");
  CHECK(write_plain_gltf_quad("nq_tangent.gltf") == 0, "write glTF");
  const struct { const char *file; double tx, ty; const char *style; } quads[3] = {
      {"nq_plain.obj", 1, 0, "mitsuba"}, {"nq_mirror.obj", -1, 0, "mitsuba"}, {"nq_tangent.gltf", 0, 1, "tangents"}};
  for (int q = 0; q < 3; q++)
    for (int tilted = 0; tilted < 2; tilted++) {
      /* light travelling down -z, or from 30 degrees towards the expected tilt */
      double d[3] = {tilted ? -sin(th) * quads[q].tx : 0, tilted ? -sin(th) * quads[q].ty : 0, -(tilted ? cos(th) : 1)};
      char json[1024];
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0,0,4], \"look_at\": [0,0,0], \"up\": [0,1,0], \"fov\": 10}, \"film\": {\"width\": 8, \"height\": 8},\n"
               "  \"render\": {\"spp\": 1, \"max_depth\": 1},\n"
               "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, \"normal_map\": \"tilt30.png\", \"map_style\": \"%s\"}},\n"
               "  \"shapes\": [{\"file\": \"%s\", \"material\": \"m\"}],\n"
               "  \"lights\": [{\"type\": \"directional\", \"direction\": [%.9f, %.9f, %.9f], \"irradiance\": 2}] }\n",
               quads[q].style, quads[q].file, d[0], d[1], d[2]);
      int w, h;
      float *px = render_json_text(json, NULL, &w, &h);
      CHECK(px, "%s: render failed", quads[q].file);
      double got = px[3 * (4 * w + 4)];
      free(px);
      /* cos between the tilted normal (sin_t along T, cos_t along z) and the light */
      double cosl = -(sin_t * (quads[q].tx * d[0] + quads[q].ty * d[1]) + cos_t * d[2]);
      double want = 0.5 * 2 * cosl / M_PI;
      if (!strcmp(quads[q].style, "mitsuba")) { /* the shadowing term for mapped normals (Conty Estevez et al. 2019) */
        double a2 = fmin(0.125 * (sin_t * sin_t) / (cos_t * cos_t), 1), cl = -d[2];
        want *= 2 / (1 + sqrt(1 + a2 * (1 - cl * cl) / (cl * cl)));
      }
      fprintf(stderr, "%s, light %s: radiance %.5f, expected %.5f\n", quads[q].file, tilted ? "30 degrees off" : "along the normal", got, want);
      CHECK(fabs(got - want) <= 1e-3 * want, "%s: %.5f, expected %.5f", quads[q].file, got, want);
    }
  return 0;
}

/* The glTF quad (its TANGENT along +v) under a JSON material, whose maps follow
 * Mitsuba's conventions by default, renders as Mitsuba renders the same quad as OBJ
 * (tests/data/mitsuba-maps, test_mitsuba maps_minimal_xml): a map tilting along v, one
 * facing away from the viewer, a bump ramp, a twosided around the map seen from behind;
 * image means within 0.5 %. */
static int gltf_quad_mitsuba_maps(void) {
  CHECK(write_plain_gltf_quad("mq.gltf") == 0, "write glTF");
#define MAPS VALO_SOURCE_DIR "/tests/data/mitsuba-maps/"
  static const struct { const char *name, *map, *cam, *up, *light; } cases[] = {
      {"tilt-v", "\"normal_map\": \"" MAPS "tilt-v.png\"", "0, 0, 4", "0, 1, 0", "0, -0.642788, -0.766044"},
      {"tilt-away", "\"normal_map\": \"" MAPS "tilt-u.png\"", "-3.825200, 0, 1.169492", "0, 0, 1", "0, 0, -1"},
      {"bump-u", "\"bump_map\": \"" MAPS "ramp-u.png\", \"bump_scale\": 4", "0, 0, 4", "0, 1, 0", "-0.642788, 0, -0.766044"},
      {"back-mirror", "\"normal_map\": \"" MAPS "tilt-u.png\", \"map_back\": \"mirror\"", "1.5, 0, -4", "0, 1, 0", "0.5, 0, 0.866025"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char json[2048];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [%s], \"look_at\": [0, 0, 0], \"up\": [%s], \"fov\": 8}, \"film\": {\"width\": 16, \"height\": 16},\n"
             "  \"render\": {\"spp\": 16, \"max_depth\": 1},\n"
             "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, %s}},\n"
             "  \"shapes\": [{\"file\": \"mq.gltf\", \"material\": \"m\", \"transform\": {\"scale\": 4}}],\n"
             "  \"lights\": [{\"type\": \"directional\", \"direction\": [%s], \"irradiance\": 2}] }\n",
             cases[i].cam, cases[i].up, cases[i].map, cases[i].light);
    int w, h;
    float *px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "%s: render failed", cases[i].name);
    char ref_path[1200];
    snprintf(ref_path, sizeof ref_path, MAPS "%s-obj-mitsuba.exr", cases[i].name);
    image ref;
    valo_error err;
    CHECK(image_read(ref_path, &ref, &err) == VALO_OK, "%s", err.message);
    double a = 0, b = 0;
    for (int k = 0; k < w * h * 3; k++) { a += px[k]; b += ref.rgb[k]; }
    free(px);
    image_free(&ref);
    fprintf(stderr, "glTF quad, %s: mean %.5f, Mitsuba's OBJ quad %.5f\n", cases[i].name, a / (w * h * 3), b / (w * h * 3));
    CHECK(fabs(a / b - 1) < 0.005, "%s: %.5f against Mitsuba's %.5f", cases[i].name, a / (w * h * 3), b / (w * h * 3));
  }
#undef MAPS
  return 0;
}

/* ---- BRDFs in closed form: the radiance of the point at the origin of a large z = 0
 * quad, seen from direction v through a 1 x 1 film 0.05 degrees wide, lit by a
 * directional light of irradiance 2 arriving from direction l (one scattering event:
 * max_depth 1), is f(v, l) * 2 * cos(theta_l). f is written here from the documented
 * definitions (docs/scene-format.md): the glTF metallic-roughness BRDF (glTF 2.0
 * appendix B; valo's one documented departure, the diffuse base weighted by 1 - F(n.v))
 * and the normalised Phong BRDF kd/pi + ks (n+2)/(2 pi) cos^n alpha, with its exponent
 * from an MTL map_Ns. */
static int plane_radiance(const char *shape, const double v[3], const double l[3], double out[3]) {
  if (!scratch_file("bq.obj", "v -50 -50 0\nv 50 -50 0\nv 50 50 0\nv -50 50 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                              "f 1/1/1 2/2/1 3/3/1 4/4/1\n") ||
      !scratch_file("bqm.obj", "mtllib bq.mtl\nusemtl m\nv -50 -50 0\nv 50 -50 0\nv 50 50 0\nv -50 50 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                               "f 1/1/1 2/2/1 3/3/1 4/4/1\n"))
    return -1;
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [%.9f, %.9f, %.9f], \"look_at\": [0,0,0], \"up\": [0,1,0], \"fov\": 0.05},\n"
           "  \"film\": {\"width\": 1, \"height\": 1}, \"render\": {\"spp\": 16, \"max_depth\": 1},\n%s,\n"
           "  \"lights\": [{\"type\": \"directional\", \"direction\": [%.9f, %.9f, %.9f], \"irradiance\": 2}] }\n",
           3 * v[0], 3 * v[1], 3 * v[2], shape, -l[0], -l[1], -l[2]);
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  if (!px) return -1;
  for (int c = 0; c < 3; c++) out[c] = px[c];
  free(px);
  return 0;
}
static void unit_dir(double theta_deg, double phi_deg, double d[3]) {
  double t = theta_deg * M_PI / 180, p = phi_deg * M_PI / 180;
  d[0] = sin(t) * cos(p); d[1] = sin(t) * sin(p); d[2] = cos(t);
}
static double smith_lambda(double a, double c) { return 0.5 * (-1 + sqrt(1 + a * a * (1 - c * c) / (c * c))); }
static void pbr_brdf(const double base[3], double metal, double rough, const double v[3], const double l[3], double f[3]) {
  double a = fmax(rough * rough, 1e-3), h[3] = {v[0] + l[0], v[1] + l[1], v[2] + l[2]};
  double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  for (int i = 0; i < 3; i++) h[i] /= hl;
  double vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2], nh2 = h[2] * h[2];
  double D = a * a / (M_PI * pow(nh2 * (a * a - 1) + 1, 2)), G = 1 / (1 + smith_lambda(a, v[2]) + smith_lambda(a, l[2]));
  double spec = D * G / (4 * v[2] * l[2]), s5 = pow(1 - vh, 5);
  double Fvh = 0.04 + 0.96 * s5, Fnv = 0.04 + 0.96 * pow(1 - v[2], 5);
  for (int c = 0; c < 3; c++)
    f[c] = (1 - metal) * ((1 - Fnv) * base[c] / M_PI + Fvh * spec) + metal * (base[c] + (1 - base[c]) * s5) * spec;
}
static void phong_brdf(double kd, double ks, double n, const double v[3], const double l[3], double f[3]) {
  double ca = -v[0] * l[0] - v[1] * l[1] + v[2] * l[2]; /* the mirror direction of v against l */
  double lobe = ca > 0 ? (n + 2) / (2 * M_PI) * pow(ca, n) : 0;
  for (int c = 0; c < 3; c++) f[c] = kd / M_PI + ks * lobe;
}
static int brdf_closed_form(void) {
  /* viewer and light (theta, phi in degrees): head-on, the mirror direction at 40 and 75
   * degrees, off the mirror direction, and out of the plane of incidence */
  static const double geo[][4] = {{0, 0, 30, 0}, {40, 0, 40, 180}, {75, 0, 75, 180}, {60, 0, 30, 180}, {50, 0, 20, 90}, {30, 0, 35, 170}};
  const int ngeo = sizeof geo / sizeof geo[0];
  static const double pbr[][2] = {{0, 0.3}, {0, 0.7}, {0.5, 0.5}, {1, 0.4}, {0, 0.15}}; /* metallic, roughness */
  const double base[3] = {0.8, 0.3, 0.2};
  double worst = 0;
  for (size_t k = 0; k < sizeof pbr / sizeof pbr[0]; k++)
    for (int g = 0; g < ngeo; g++) {
      double v[3], l[3], f[3], got[3];
      unit_dir(geo[g][0], geo[g][1], v);
      unit_dir(geo[g][2], geo[g][3], l);
      char shape[600];
      snprintf(shape, sizeof shape,
               "  \"materials\": {\"m\": {\"type\": \"pbr\", \"base_color\": [0.8, 0.3, 0.2], \"metallic\": %g, \"roughness\": %g}},\n"
               "  \"shapes\": [{\"file\": \"bq.obj\", \"material\": \"m\"}]", pbr[k][0], pbr[k][1]);
      CHECK(plane_radiance(shape, v, l, got) == 0, "render failed");
      pbr_brdf(base, pbr[k][0], pbr[k][1], v, l, f);
      for (int c = 0; c < 3; c++) {
        double want = f[c] * 2 * l[2], e = fabs(got[c] - want) / want;
        worst = fmax(worst, e);
        CHECK(e < 2e-3, "pbr metallic %g roughness %g, view %g, light (%g, %g), channel %d: %.6f, closed form %.6f", pbr[k][0], pbr[k][1], geo[g][0],
              geo[g][2], geo[g][3], c, got[c], want);
      }
    }
  /* the same BRDF read from a glTF file: metallic 0, roughness 1, an sRGB base-colour texture */
  unsigned char rgb8[4 * 4 * 3];
  for (int i = 0; i < 16; i++) { rgb8[3 * i] = 204; rgb8[3 * i + 1] = 153; rgb8[3 * i + 2] = 102; }
  char texp[1200];
  snprintf(texp, sizeof texp, "%s/quad-texture.png", scratch_dir());
  CHECK(stbi_write_png(texp, 4, 4, 3, rgb8, 12) && write_gltf_quad("pbrq.gltf", NULL, 0, "", 0) == 0, "write");
  double lin[3];
  for (int c = 0; c < 3; c++) {
    double x = rgb8[c] / 255.0;
    lin[c] = x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
  }
  for (int g = 0; g < ngeo; g++) {
    double v[3], l[3], f[3], got[3];
    unit_dir(geo[g][0], geo[g][1], v);
    unit_dir(geo[g][2], geo[g][3], l);
    CHECK(plane_radiance("  \"shapes\": [{\"file\": \"pbrq.gltf\"}]", v, l, got) == 0, "render failed");
    pbr_brdf(lin, 0, 1, v, l, f);
    for (int c = 0; c < 3; c++) {
      double want = f[c] * 2 * l[2], e = fabs(got[c] - want) / want;
      worst = fmax(worst, e);
      CHECK(e < 2e-3, "glTF, view %g, light (%g, %g), channel %d: %.6f, closed form %.6f", geo[g][0], geo[g][2], geo[g][3], c, got[c], want);
    }
  }
  fprintf(stderr, "pbr: %d cases (JSON and glTF) within %.3f %% of the closed form\n", (int)(sizeof pbr / sizeof pbr[0] + 1) * ngeo, 100 * worst);
  /* Phong: JSON exponent 50, and an MTL exponent 250 times a map of 0.2 */
  unsigned char tex[4 * 4];
  memset(tex, 51, sizeof tex);
  char png[1200];
  snprintf(png, sizeof png, "%s/ns.png", scratch_dir());
  CHECK(stbi_write_png(png, 4, 4, 1, tex, 4), "png");
  CHECK(scratch_file("bq.mtl", "newmtl m\nKd 0.3 0.3 0.3\nKs 0.5 0.5 0.5\nillum 2\nNs 250\nmap_Ns ns.png\n"), "write");
  worst = 0;
  for (int mtl = 0; mtl < 2; mtl++)
    for (int g = 0; g < ngeo; g++) {
      double v[3], l[3], f[3], got[3];
      unit_dir(geo[g][0], geo[g][1], v);
      unit_dir(geo[g][2], geo[g][3], l);
      const char *shape = mtl ? "  \"shapes\": [{\"file\": \"bqm.obj\"}]"
                              : "  \"materials\": {\"m\": {\"type\": \"phong\", \"diffuse\": 0.3, \"specular\": 0.5, \"exponent\": 50}},\n"
                                "  \"shapes\": [{\"file\": \"bq.obj\", \"material\": \"m\"}]";
      CHECK(plane_radiance(shape, v, l, got) == 0, "render failed");
      phong_brdf(0.3, 0.5, mtl ? 250 * (51 / 255.0) : 50, v, l, f);
      double want = f[0] * 2 * l[2], e = fabs(got[0] - want) / want;
      worst = fmax(worst, e);
      CHECK(e < 2e-3, "phong (%s), view %g, light (%g, %g): %.6f, closed form %.6f", mtl ? "MTL map_Ns" : "JSON", geo[g][0], geo[g][2], geo[g][3], got[0], want);
    }
  fprintf(stderr, "phong: %d cases within %.3f %% of the closed form\n", 2 * ngeo, 100 * worst);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"helmet_glb_texels", helmet_glb_texels}, {"helmet_gltf_texels", helmet_gltf_texels},
                                    {"wrap_modes", wrap_modes}, {"alpha_cutout", alpha_cutout},
                                    {"normal_map", normal_map}, {"bump_map", bump_map}, {"gltf_quad_mitsuba_maps", gltf_quad_mitsuba_maps}, {"gltf_metallic_roughness", gltf_metallic_roughness},
                                    {"phong_exponent_map", phong_exponent_map},
                                    {"stress_no_nan", stress_no_nan}, {"uv_orientation", uv_orientation},
                                    {"alpha_cutoff", alpha_cutoff}, {"opacity_stochastic", opacity_stochastic}, {"gltf_blend", gltf_blend}, {"blend_mixes", blend_mixes}, {"texture_objects", texture_objects}, {"sided_material", sided_material}, {"black_back_material", black_back_material}, {"vertex_colors", vertex_colors}, {"gltf_transmission", gltf_transmission}, {"gltf_texture_transform", gltf_texture_transform}, {"gltf_quantized", gltf_quantized}, {"gltf_draco", gltf_draco}, {"gltf_clearcoat_maps", gltf_clearcoat_maps}, {"gltf_pbr_extensions", gltf_pbr_extensions}, {"roughness_maps", roughness_maps}, {"anisotropic_roughness", anisotropic_roughness}, {"luminance_textures", luminance_textures},
                                    {"normal_map_shading", normal_map_shading}, {"brdf_closed_form", brdf_closed_form}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
