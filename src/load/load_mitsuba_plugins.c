/* load_mitsuba_plugins.c — owns the translation of Mitsuba's BSDFs and emitters into
 * valo's materials, lights and environment (media: load_mitsuba_media.c;
 * docs/scene-format.md, "Mitsuba scenes", has the table); what has no valo equivalent
 * is an error naming the line, and an approximation is a warning that says what it
 * gives up. */
#include "load/mitsuba_internal.h"
#include "load/load_json_internal.h"
#include "core/error.h"
#include "core/grow.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NOMEM err_set(c->err, VALO_ERR_NOMEM, "out of memory")

/* Mitsuba's named indices of refraction (its documentation's table of common materials). */
static int named_ior(const char *s, double *v) {
  static const struct { const char *n; double v; } t[] = {
      {"vacuum", 1.0},       {"helium", 1.00004},   {"hydrogen", 1.00013},       {"air", 1.00028},
      {"carbon dioxide", 1.00045}, {"water", 1.3330}, {"acetone", 1.36},         {"ethanol", 1.361},
      {"carbon tetrachloride", 1.461}, {"glycerol", 1.4729}, {"benzene", 1.501}, {"silicone oil", 1.52045},
      {"bromine", 1.661},    {"water ice", 1.31},   {"fused quartz", 1.458},     {"pyrex", 1.470},
      {"acrylic glass", 1.49}, {"polypropylene", 1.49}, {"bk7", 1.5046},          {"sodium chloride", 1.544},
      {"amber", 1.55},       {"pet", 1.5750},       {"diamond", 2.419}};
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
    if (!strcmp(s, t[i].n)) { *v = t[i].v; return 1; }
  return 0;
}

/* An index: a number or a name (int_ior, ext_ior). */
static valo_status ior_prop(mctx *c, xml_node *b, const char *name, double *v) {
  xml_node *k = mi_prop(c, b, name);
  if (!k) return VALO_OK;
  const char *val = xml_attr_get(k, "value");
  if (!val) return mi_bad(c, k, "needs a value");
  if (!strcmp(k->name, "string")) {
    if (!named_ior(val, v)) return mi_bad(c, k, "unknown material name for an index of refraction (give the number)");
    return VALO_OK;
  }
  return mi_float(c, b, name, v);
}

static valo_status roughness_of(mctx *c, xml_node *b, double def_alpha, cJSON *m) {
  double a = def_alpha, au = -1, av = -1;
  for (const char *const *n = (const char *const[]){"alpha_u", "alpha_v", NULL}; *n; n++)
    if (mi_prop(c, b, *n) && !strcmp(mi_prop(c, b, *n)->name, "texture")) return mi_bad(c, b, "valo reads %s as a number, not a texture", *n);
  xml_node *ak = mi_prop(c, b, "alpha");
  if (ak && !strcmp(ak->name, "texture")) {
    /* valo's roughness 1 with a map multiplying alpha: alpha = the texture's value */
    const char *t = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "type"));
    if (t && !strcmp(t, "plastic")) return mi_bad(c, ak, "valo's plastic tabulates its coat for one roughness: an alpha texture is not read");
    cJSON *amap;
    TRY(mi_color(c, b, "alpha", MI_SCALAR, &amap));
    cJSON_AddItemToObject(m, "roughness_map", amap);
    if (!cJSON_AddTrueToObject(m, "roughness_map_is_alpha")) return NOMEM;
    a = 1;
  } else {
    TRY(mi_float(c, b, "alpha", &a));
  }
  TRY(mi_float(c, b, "alpha_u", &au));
  TRY(mi_float(c, b, "alpha_v", &av));
  const char *t = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "type"));
  int aniso = 0;
  if (au >= 0 || av >= 0) {
    if (!(au >= 0 && av >= 0)) return mi_bad(c, b, "give both alpha_u and alpha_v");
    if (cJSON_GetObjectItemCaseSensitive(m, "roughness_map")) return mi_bad(c, b, "an alpha texture and alpha_u, alpha_v: give one or the other");
    if (!(au <= 1 && av <= 1)) return mi_bad(c, b, "alpha_u and alpha_v must be in [0, 1]");
    aniso = au != av;
    /* valo's pbr metal (a conductor of material none) and plastic are isotropic */
    if (aniso && t && strcmp(t, "conductor") && strcmp(t, "dielectric")) return mi_bad(c, b, "valo's %s is isotropic: alpha_u and alpha_v must be equal", t);
    a = au;
  }
  if (!(a >= 0 && a <= 1)) return mi_bad(c, b, "alpha must be in [0, 1]");
  const char *dist = "beckmann";
  TRY(mi_string(c, b, "distribution", &dist));
  if (strcmp(dist, "ggx") && strcmp(dist, "beckmann")) return mi_bad(c, b, "distribution must be beckmann or ggx");
  if (t && !strcmp(t, "pbr")) {
    if (strcmp(dist, "ggx")) mi_warn(c, b, "rendered with GGX (valo's pbr material): this %s distribution of the same alpha is not", dist);
  } else if (!cJSON_AddStringToObject(m, "distribution", dist) || !cJSON_AddStringToObject(m, "smith", "separable")) {
    return NOMEM; /* Mitsuba's Smith G is the separable one */
  }
  (void)mi_prop(c, b, "sample_visible"); /* the sampling strategy changes the noise, not the image */
  if (aniso) { /* along the surface's u direction, and along v */
    if (!cJSON_AddNumberToObject(m, "roughness_u", sqrt(au)) || !cJSON_AddNumberToObject(m, "roughness_v", sqrt(av))) return NOMEM;
    return VALO_OK;
  }
  if (!cJSON_AddNumberToObject(m, "roughness", sqrt(a))) return NOMEM; /* valo's alpha = roughness^2 */
  return VALO_OK;
}

static valo_status set_color(mctx *c, xml_node *b, const char *mname, cJSON *m, const char *key, int rgb_only) {
  cJSON *v;
  TRY(mi_color(c, b, mname, rgb_only, &v));
  if (v) cJSON_AddItemToObject(m, key, v);
  return VALO_OK;
}

/* The reflection tint Mitsuba allows on its smooth and rough dielectrics: valo has none
 * (its transmission tint is valo's transmittance). */
static valo_status no_tint(mctx *c, xml_node *b, const char *name) {
  cJSON *v;
  TRY(mi_color(c, b, name, MI_RGB_ONLY, &v));
  if (!v) return VALO_OK;
  int one = 1;
  for (int i = 0; i < 3; i++) one &= cJSON_GetArrayItem(v, i)->valuedouble == 1;
  cJSON_Delete(v);
  if (!one) mi_warn(c, b, "%s is not read: valo's glass reflects what Fresnel gives", name);
  return VALO_OK;
}

static valo_status translate_bsdf(mctx *c, xml_node *b, cJSON *m);
static cJSON *vec3_json(double x, double y, double z) { return cJSON_CreateDoubleArray((double[]){x, y, z}, 3); }

/* A diffuse colour: a colour, a texture or the mesh's vertex colours (a mesh_attribute:
 * valo's "vertex_colors" over [scale, scale, scale]); def < 0: none when absent. */
static valo_status kd_color(mctx *c, xml_node *b, const char *mname, cJSON *m, const char *key, double def) {
  cJSON *v;
  c->vertex_color = 0;
  TRY(mi_color(c, b, mname, MI_VERTEX, &v));
  if (!v && def >= 0) v = vec3_json(def, def, def);
  if (v) cJSON_AddItemToObject(m, key, v);
  if (c->vertex_color) cJSON_AddTrueToObject(m, "vertex_colors");
  c->vertex_color = 0;
  return VALO_OK;
}

/* Mitsuba's diffuse, conductors, plastics, phong and principled without transmission are
 * black seen from behind, unless inside a twosided. */
static void one_sided(mctx *c, cJSON *m) {
  if (!c->twosided) cJSON_AddTrueToObject(m, "black_back");
}

static valo_status wrapped(mctx *c, xml_node *b, cJSON *m, const char *what) {
  xml_node *in = mi_child(c, b, "bsdf", 0);
  if (!in) return mi_bad(c, b, "needs the %s BSDF inside it", what);
  return translate_bsdf(c, in, m);
}

static valo_status translate_one(mctx *c, xml_node *b, cJSON *m);

/* translate_one within the bounds of mitsuba_internal.h: a BSDF inside itself through
 * <ref>s is a cycle, refused naming the chain's ids. */
static valo_status translate_bsdf(mctx *c, xml_node *b, cJSON *m) {
  for (int i = 0; i < c->nbsdf_stack; i++) {
    if (c->bsdf_stack[i] != b) continue;
    char chain[400] = "";
    size_t at = 0;
    for (int j = i; j <= c->nbsdf_stack && at + 1 < sizeof chain; j++) {
      const xml_node *k = j < c->nbsdf_stack ? c->bsdf_stack[j] : b;
      const char *id = xml_attr_get(k, "id");
      int w = snprintf(chain + at, sizeof chain - at, "%s%.60s", j > i ? " -> " : "", id ? id : "(no id)");
      at += w > 0 ? (size_t)w : 0;
    }
    return mi_bad(c, b, "BSDFs that refer to each other in a cycle (%s)", chain);
  }
  if (c->nbsdf_stack >= MI_BSDF_DEPTH) return mi_bad(c, b, "BSDFs nested more than %d deep through <ref>s", MI_BSDF_DEPTH);
  if (++c->bsdf_work > MI_BSDF_WORK)
    return mi_bad(c, b, "BSDFs that refer to others expand to more than %d translations (a chain whose links refer to the next twice?)", MI_BSDF_WORK);
  const xml_node **k = grow_for(c->bsdf_stack, (size_t)c->nbsdf_stack, sizeof *k);
  if (!k) return NOMEM;
  c->bsdf_stack = k;
  c->bsdf_stack[c->nbsdf_stack++] = b;
  valo_status st = translate_one(c, b, m);
  c->nbsdf_stack--;
  return st;
}

static valo_status translate_one(mctx *c, xml_node *b, cJSON *m) {
  const char *type = xml_attr_get(b, "type");
  if (!type) return mi_bad(c, b, "needs a type");
  b->used = 1;
#define TYPE(t) cJSON_AddStringToObject(m, "type", t)
  if (!strcmp(type, "twosided") && mi_child(c, b, "bsdf", 1)) {
    /* two BSDFs: valo's sided material of the two, the first seen from the front */
    xml_node *in[2] = {mi_child(c, b, "bsdf", 0), mi_child(c, b, "bsdf", 1)};
    cJSON *names = cJSON_AddArrayToObject(m, "materials");
    if (!names) return NOMEM;
    c->twosided++;
    for (int i = 0; i < 2; i++) {
      char name[160];
      TRY(mi_material(c, in[i], NULL, in[i], name, sizeof name));
      cJSON_AddItemToArray(names, cJSON_CreateString(name));
    }
    c->twosided--;
    TYPE("sided");
  } else if (!strcmp(type, "twosided")) {
    /* the BSDF inside, without its black back: valo's surfaces scatter from both sides */
    c->twosided++;
    TRY(wrapped(c, b, m, "front"));
    c->twosided--;
  } else if (!strcmp(type, "normalmap") || !strcmp(type, "bumpmap")) {
    int normal = type[0] == 'n';
    xml_node *tex = NULL;
    for (xml_node *k = b->child; k && !tex; k = k->next)
      if (!strcmp(k->name, "texture") || (!strcmp(k->name, "ref") && xml_attr_get(k, "name"))) tex = k;
    if (!tex) return mi_bad(c, b, "needs its map as a bitmap <texture>");
    const char *tname = xml_attr_get(tex, "name");
    cJSON *file;
    if (tname) TRY(mi_color(c, b, tname, normal ? 0 : MI_SCALAR, &file));
    else {
      /* an unnamed texture child: name it for the reader */
      return mi_bad(c, tex, "give the map texture a name (name=\"%s\")", normal ? "normalmap" : "bumpmap");
    }
    if (!cJSON_IsObject(file)) { cJSON_Delete(file); return mi_bad(c, tex, "must be a texture"); }
    double scale = 1;
    valo_status st = VALO_OK;
    if (!normal) st = mi_float(c, b, "scale", &scale);
    if (!st) st = wrapped(c, b, m, normal ? "mapped" : "bumped");
    if (st) { cJSON_Delete(file); return st; }
    cJSON_AddItemToObject(m, normal ? "normal_map" : "bump_map", file);
    if (!normal) cJSON_AddNumberToObject(m, "bump_scale", scale);
    if (c->twosided && !cJSON_GetObjectItemCaseSensitive(m, "map_back")) cJSON_AddStringToObject(m, "map_back", "mirror"); /* the twosided is around the map */
  } else if (!strcmp(type, "mask")) {
    /* Mitsuba's mask lets light through with probability 1 - opacity: valo's "opacity",
     * a number (Mitsuba's default 0.5) or a texture (a bitmap sRGB-decoded unless raw). */
    cJSON *op;
    TRY(mi_color(c, b, "opacity", MI_SCALAR, &op));
    if (!op) op = cJSON_CreateNumber(0.5);
    else if (cJSON_IsArray(op)) {
      cJSON *a = cJSON_CreateNumber(cJSON_GetArrayItem(op, 0)->valuedouble);
      cJSON_Delete(op);
      op = a;
    }
    if (!op) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    valo_status st = wrapped(c, b, m, "masked");
    if (st) { cJSON_Delete(op); return st; }
    cJSON *inner = cJSON_GetObjectItemCaseSensitive(m, "opacity"); /* a mask inside: the two multiply */
    if (inner && !(cJSON_IsNumber(inner) && cJSON_IsNumber(op))) {
      cJSON_Delete(op);
      return mi_bad(c, b, "valo multiplies masks inside masks only when both opacities are numbers");
    }
    if (inner) cJSON_SetNumberValue(op, op->valuedouble * inner->valuedouble);
    cJSON_DeleteItemFromObject(m, "opacity");
    cJSON_AddItemToObject(m, "opacity", op);
  } else if (!strcmp(type, "blendbsdf")) {
    /* valo's blend of the two BSDFs inside, each its own material; weight: the second's
     * share (a number or a texture: a bitmap sRGB-decoded unless raw) */
    xml_node *in[2] = {mi_child(c, b, "bsdf", 0), mi_child(c, b, "bsdf", 1)};
    if (!in[0] || !in[1]) return mi_bad(c, b, "needs two BSDFs inside it");
    cJSON *w, *names = cJSON_AddArrayToObject(m, "materials");
    if (!names) return NOMEM;
    for (int i = 0; i < 2; i++) {
      char name[160];
      TRY(mi_material(c, in[i], NULL, in[i], name, sizeof name));
      cJSON_AddItemToArray(names, cJSON_CreateString(name));
    }
    TRY(mi_color(c, b, "weight", MI_SCALAR, &w));
    if (!w) return mi_bad(c, b, "needs its weight (a number or a texture), as Mitsuba does");
    if (cJSON_IsArray(w)) {
      double x = cJSON_GetArrayItem(w, 0)->valuedouble;
      cJSON_Delete(w);
      w = cJSON_CreateNumber(x);
    }
    TYPE("blend");
    cJSON_AddItemToObject(m, "weight", w);
  } else if (!strcmp(type, "diffuse")) {
    TYPE("diffuse");
    one_sided(c, m);
    TRY(kd_color(c, b, "reflectance", m, "reflectance", 0.5));
  } else if (!strcmp(type, "dielectric") || !strcmp(type, "roughdielectric") || !strcmp(type, "thindielectric")) {
    double in = 1.5046, out = 1.00028; /* bk7 in air, Mitsuba's defaults */
    TRY(ior_prop(c, b, "int_ior", &in));
    TRY(ior_prop(c, b, "ext_ior", &out));
    if (!(in > 0 && out > 0)) return mi_bad(c, b, "indices of refraction must be positive");
    if (in < out) return mi_bad(c, b, "valo's glass is denser than outside (int_ior >= ext_ior): flip the shape's normals and swap them");
    TYPE(type[0] == 't' ? "thindielectric" : "dielectric");
    cJSON_AddNumberToObject(m, "ior", in / out);
    if (type[0] == 'r') TRY(roughness_of(c, b, 0.1, m));
    TRY(no_tint(c, b, "specular_reflectance"));
    TRY(set_color(c, b, "specular_transmittance", m, "transmittance", MI_RGB_ONLY));
  } else if (!strcmp(type, "conductor") || !strcmp(type, "roughconductor")) {
    const char *mat = "none";
    TRY(mi_string(c, b, "material", &mat));
    cJSON *eta = NULL, *k = NULL;
    TRY(mi_color(c, b, "eta", MI_RGB_ONLY, &eta));
    valo_status st = mi_color(c, b, "k", MI_RGB_ONLY, &k);
    if (st) { cJSON_Delete(eta); return st; }
    if (eta || k) {
      if (!eta || !k) { cJSON_Delete(eta); cJSON_Delete(k); return mi_bad(c, b, "give both eta and k"); }
      TYPE("conductor");
      cJSON_AddItemToObject(m, "eta", eta);
      cJSON_AddItemToObject(m, "k", k);
    } else if (!strcmp(mat, "none")) {
      /* Mitsuba's "none": F = 1. Smooth, valo's mirror; rough, its pbr metal of base
       * colour 1 (Schlick's F is then 1) with the same GGX, tinted by base_color. */
      if (type[0] == 'r') {
        TYPE("pbr");
        cJSON_AddNumberToObject(m, "metallic", 1);
        TRY(set_color(c, b, "specular_reflectance", m, "base_color", 1));
        if (!cJSON_GetObjectItemCaseSensitive(m, "base_color")) cJSON_AddItemToObject(m, "base_color", vec3_json(1, 1, 1));
        TRY(roughness_of(c, b, 0.1, m));
        one_sided(c, m);
        mi_warn_unused(c, b);
        return VALO_OK;
      }
      TYPE("mirror");
    } else if (!conductor_preset(mat, &(rgb){0}, &(rgb){0})) {
      TYPE("conductor");
      cJSON_AddStringToObject(m, "preset", mat);
    } else {
      return mi_bad(c, b, "valo has no conductor preset \"%s\" (it has Mitsuba's others but AlSb): give eta and k", mat);
    }
    (void)mi_prop(c, b, "ext_eta");
    TRY(set_color(c, b, "specular_reflectance", m, "reflectance", 1));
    if (type[0] == 'r') TRY(roughness_of(c, b, 0.1, m));
    one_sided(c, m);
  } else if (!strcmp(type, "plastic") || !strcmp(type, "roughplastic")) {
    double in = 1.49, out = 1.000277; /* polypropylene in air, Mitsuba's defaults */
    TRY(ior_prop(c, b, "int_ior", &in));
    TRY(ior_prop(c, b, "ext_ior", &out));
    if (!(in > 0 && out > 0)) return mi_bad(c, b, "indices of refraction must be positive");
    if (in < out) return mi_bad(c, b, "valo's plastic coat is denser than outside (int_ior >= ext_ior)");
    TYPE("plastic");
    cJSON_AddNumberToObject(m, "ior", in / out);
    TRY(kd_color(c, b, "diffuse_reflectance", m, "diffuse", 0.5));
    TRY(set_color(c, b, "specular_reflectance", m, "specular", 1));
    int nonlinear = 0;
    TRY(mi_bool(c, b, "nonlinear", &nonlinear));
    cJSON_AddBoolToObject(m, "nonlinear", nonlinear);
    if (type[0] == 'r') TRY(roughness_of(c, b, 0.1, m));
    one_sided(c, m);
  } else if (!strcmp(type, "principled")) {
    /* valo's principled: Mitsuba's lobes */
    TYPE("principled");
    TRY(kd_color(c, b, "base_color", m, "base_color", -1));
    static const char *const keys[] = {"metallic", "roughness", "spec_tint", "sheen", "sheen_tint", "flatness", "clearcoat", "clearcoat_gloss", "specular",
                                       "spec_trans"};
    for (int k = 0; k < 10; k++) {
      double x = -1;
      xml_node *tk = mi_prop(c, b, keys[k]);
      if (tk && !strcmp(tk->name, "texture")) {
        /* valo's principled reads maps for roughness and metallic: the value 1 times the map */
        if (k > 1) return mi_bad(c, tk, "valo reads textures for principled's roughness and metallic, not for %s", keys[k]);
        cJSON *map;
        TRY(mi_color(c, b, keys[k], MI_SCALAR, &map));
        cJSON_AddItemToObject(m, k ? "roughness_map" : "metallic_map", map);
        x = 1;
      } else {
        TRY(mi_float(c, b, keys[k], &x));
      }
      if (x != -1) cJSON_AddNumberToObject(m, keys[k], x);
    }
    double eta = 0, an = 0;
    TRY(mi_float(c, b, "eta", &eta));
    if (eta > 0) {
      if (cJSON_GetObjectItemCaseSensitive(m, "specular")) return mi_bad(c, b, "give eta or specular, not both (as Mitsuba asks)");
      cJSON_AddNumberToObject(m, "ior", eta);
    }
    TRY(mi_float(c, b, "anisotropic", &an));
    if (!(an >= 0 && an <= 1)) return mi_bad(c, b, "anisotropic must be in [0, 1]");
    if (an > 0) cJSON_AddNumberToObject(m, "anisotropic", an);
    double rate;
    static const char *const rates[] = {"main_specular_sampling_rate", "clearcoat_sampling_rate", "diffuse_reflectance_sampling_rate"};
    for (int k = 0; k < 3; k++) TRY(mi_float(c, b, rates[k], &rate)); /* how Mitsuba samples: valo's own choice */
    const cJSON *trans = cJSON_GetObjectItemCaseSensitive(m, "spec_trans");
    if (!trans || trans->valuedouble == 0) one_sided(c, m); /* with transmission it scatters from behind too */
  } else if (!strcmp(type, "phong")) {
    TYPE("phong");
    TRY(kd_color(c, b, "diffuse_reflectance", m, "diffuse", -1));
    TRY(set_color(c, b, "specular_reflectance", m, "specular", 0));
    double e = 30;
    TRY(mi_float(c, b, "exponent", &e));
    cJSON_AddNumberToObject(m, "exponent", e);
    one_sided(c, m);
  } else if (!strcmp(type, "null")) {
    TYPE("null");
  } else {
    return mi_bad(c, b, "valo has no such BSDF (diffuse, dielectric, roughdielectric, thindielectric, conductor, roughconductor, "
                        "plastic, roughplastic, principled, phong, twosided, normalmap, bumpmap, mask, blendbsdf, null)");
  }
#undef TYPE
  mi_warn_unused(c, b);
  return VALO_OK;
}

static valo_status add_material(mctx *c, cJSON *m, const char *name) {
  if (strmap_get(&c->material_names, name) >= 0) { cJSON_Delete(m); return VALO_OK; }
  if (!cJSON_AddItemToObject(c->materials, name, m)) { cJSON_Delete(m); return NOMEM; }
  return strmap_put(&c->material_names, m->string, 1) ? NOMEM : VALO_OK; /* the item's own copy of the name */
}

valo_status mi_material(mctx *c, xml_node *b, cJSON *emit, const xml_node *at, char *name, size_t n) {
  const char *id = b ? xml_attr_get(b, "id") : NULL;
  if (b && id && !emit && !c->twosided) {
    long i = strmap_get(&c->bsdf_ids, id);
    if (i >= 0) { snprintf(name, n, "%s", c->bsdf_names[i].name); return VALO_OK; }
  }
  cJSON *m = cJSON_CreateObject();
  if (!m) return NOMEM;
  valo_status st = VALO_OK;
  char base[96], where[96];
  if (b) {
    st = translate_bsdf(c, b, m);
    if (id) snprintf(base, sizeof base, c->twosided ? "%.60s+twosided" : "%.60s", id); /* twosided: without its black back */
    else snprintf(base, sizeof base, "bsdf@%s", mi_place(c, b, where, sizeof where));
  } else {
    /* Mitsuba's default BSDF: diffuse, reflectance 0.5, or 0 on a shape that emits */
    double r = emit ? 0 : 0.5;
    cJSON_AddStringToObject(m, "type", "diffuse");
    cJSON_AddItemToObject(m, "reflectance", cJSON_CreateDoubleArray((double[]){r, r, r}, 3));
    one_sided(c, m);
    snprintf(base, sizeof base, emit ? "mitsuba-default-black" : "mitsuba-default");
  }
  if (st) { cJSON_Delete(m); return st; }
  if (emit) {
    const char *t = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "type"));
    if (t && !strcmp(t, "null")) {
      /* valo's null surface carries nothing; an emitter on Mitsuba's null BSDF is a black
       * diffuse light */
      cJSON_DeleteItemFromObject(m, "type");
      cJSON_AddStringToObject(m, "type", "diffuse");
      cJSON_AddItemToObject(m, "reflectance", cJSON_CreateDoubleArray((double[]){0, 0, 0}, 3));
    }
    cJSON_AddItemToObject(m, "emission", cJSON_Duplicate(emit, 1));
    snprintf(name, n, "%s+area@%s", base, mi_place(c, at, where, sizeof where));
  } else {
    snprintf(name, n, "%s", base);
  }
  TRY(add_material(c, m, name));
  if (b && id && !emit && !c->twosided) {
    void *q = grow_for(c->bsdf_names, (size_t)c->nbsdf_names, sizeof *c->bsdf_names);
    if (!q) return NOMEM;
    c->bsdf_names = q;
    c->bsdf_names[c->nbsdf_names].id = id;
    snprintf(c->bsdf_names[c->nbsdf_names].name, sizeof c->bsdf_names[0].name, "%s", name);
    if (strmap_put(&c->bsdf_ids, id, c->nbsdf_names++)) return NOMEM;
  }
  return VALO_OK;
}

/* ---- emitters ---- */

/* An emitter's constant colour `name` as o's `key`; Mitsuba's default is 1. */
static valo_status color_or_one(mctx *c, xml_node *e, const char *name, cJSON *o, const char *key) {
  cJSON *v;
  TRY(mi_color(c, e, name, MI_RGB_ONLY | MI_EMITTER, &v));
  if (!v && !(v = vec3_json(1, 1, 1))) return NOMEM;
  cJSON_AddItemToObject(o, key, v);
  return VALO_OK;
}

valo_status mi_emitter(mctx *c, xml_node *e) {
  const char *type = xml_attr_get(e, "type");
  if (!type) return mi_bad(c, e, "needs a type");
  double m[16];
  int has_xf;
  TRY(mi_transform(c, e, "to_world", m, &has_xf));
  if (!strcmp(type, "constant") || !strcmp(type, "envmap")) {
    if (cJSON_GetObjectItemCaseSensitive(c->out, "environment")) return mi_bad(c, e, "valo has one environment: a second is not read");
    cJSON *env = cJSON_AddObjectToObject(c->out, "environment");
    if (!env) return NOMEM;
    if (type[0] == 'c') {
      cJSON_AddStringToObject(env, "type", "constant");
      TRY(color_or_one(c, e, "radiance", env, "radiance"));
    } else {
      const char *file = NULL;
      double scale = 1;
      TRY(mi_string(c, e, "filename", &file));
      TRY(mi_float(c, e, "scale", &scale));
      if (!file) return mi_bad(c, e, "needs <string name=\"filename\">");
      /* Mitsuba's map has u = 0 at -z, valo's centre looks down -z: a turn of theta about
       * +y there is theta - 180 degrees here; any other turn (a z-up world's, say) is the
       * frame M diag(-1, 1, -1), M the to_world's 3x3 part with its columns made unit
       * (Mitsuba normalises the direction it turns back). */
      double ang = 180, fr[9];
      int general = 0;
      if (has_xf) {
        double off = fabs(m[1]) + fabs(m[4]) + fabs(m[6]) + fabs(m[9]);
        double len[3];
        for (int j = 0; j < 3; j++) len[j] = sqrt(m[j] * m[j] + m[4 + j] * m[4 + j] + m[8 + j] * m[8 + j]);
        if (!(len[0] > 0 && len[1] > 0 && len[2] > 0)) return mi_bad(c, e, "to_world flattens the environment");
        if (off < 1e-4 && fabs(m[5] - 1) < 1e-4 && fabs(m[0] - m[10]) < 1e-4 && fabs(m[2] + m[8]) < 1e-4 && fabs(m[0] * m[0] + m[2] * m[2] - 1) < 1e-4) {
          ang = atan2(m[2], m[0]) * 180 / M_PI;
        } else {
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) fr[3 * i + j] = m[4 * i + j] / len[j] * (j == 1 ? 1 : -1);
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < i; j++)
              if (fabs(fr[i] * fr[j] + fr[3 + i] * fr[3 + j] + fr[6 + i] * fr[6 + j]) > 1e-3)
                return mi_bad(c, e, "to_world may turn the environment (or mirror it), not shear it");
          general = 1;
        }
      }
      if (!(file = mi_found(c, file))) return NOMEM;
      cJSON_AddStringToObject(env, "type", "map");
      cJSON_AddStringToObject(env, "file", file);
      cJSON_AddNumberToObject(env, "scale", scale);
      cJSON_AddTrueToObject(env, "mitsuba_rows"); /* its rows where Mitsuba looks them up */

      if (general) {
        cJSON *fm = cJSON_CreateDoubleArray(fr, 9);
        if (!fm) return NOMEM;
        cJSON_AddItemToObject(env, "matrix", fm);
      } else {
        cJSON_AddNumberToObject(env, "rotation", ang - 180);
      }
    }
    mi_warn_unused(c, e);
    return VALO_OK;
  }
  cJSON *l = cJSON_CreateObject();
  if (!l) return NOMEM;
  cJSON_AddItemToArray(c->lights, l);
  const xml_node **ln = grow_for(c->light_at, (size_t)c->nlight_at, sizeof *ln);
  if (!ln) return NOMEM;
  c->light_at = ln;
  ln[c->nlight_at++] = e;
  double org[3] = {m[3], m[7], m[11]}, dir[3] = {m[2], m[6], m[10]};
  if (!strcmp(type, "point")) {
    vec3 p = v3((float)org[0], (float)org[1], (float)org[2]);
    TRY(mi_point(c, e, "position", &p));
    cJSON_AddStringToObject(l, "type", "point");
    cJSON_AddItemToObject(l, "position", vec3_json(p.x, p.y, p.z));
    TRY(color_or_one(c, e, "intensity", l, "intensity"));
  } else if (!strcmp(type, "spot")) {
    double cutoff = 20, beam = -1;
    TRY(mi_float(c, e, "cutoff_angle", &cutoff));
    TRY(mi_float(c, e, "beam_width", &beam));
    if (beam < 0) beam = cutoff * 3 / 4;
    if (mi_prop(c, e, "texture")) return mi_bad(c, e, "a spot light's texture is not read");
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(dl > 0)) return mi_bad(c, e, "to_world flattens the light");
    cJSON_AddStringToObject(l, "type", "spot");
    cJSON_AddItemToObject(l, "position", vec3_json(org[0], org[1], org[2]));
    cJSON_AddItemToObject(l, "look_at", vec3_json(org[0] + dir[0] / dl, org[1] + dir[1] / dl, org[2] + dir[2] / dl));
    TRY(color_or_one(c, e, "intensity", l, "intensity"));
    cJSON_AddNumberToObject(l, "cone_angle", cutoff);
    cJSON_AddNumberToObject(l, "cone_delta_angle", beam < cutoff ? cutoff - beam : 0);
    cJSON_AddStringToObject(l, "falloff", "linear");
  } else if (!strcmp(type, "directional")) {
    vec3 d = v3((float)dir[0], (float)dir[1], (float)dir[2]);
    TRY(mi_point(c, e, "direction", &d));
    cJSON_AddStringToObject(l, "type", "directional");
    cJSON_AddItemToObject(l, "direction", vec3_json(d.x, d.y, d.z));
    TRY(color_or_one(c, e, "irradiance", l, "irradiance"));
  } else if (!strcmp(type, "area")) {
    return mi_bad(c, e, "an area emitter belongs inside the <shape> that emits");
  } else {
    return mi_bad(c, e, "valo reads point, spot, directional, constant, envmap and (in shapes) area emitters");
  }
  mi_warn_unused(c, e);
  return VALO_OK;
}
