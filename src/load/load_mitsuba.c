/* load_mitsuba.c — owns reading Mitsuba scene files (.xml, Mitsuba 3 and 0.6): the sensor,
 * film, sampler, integrator and shapes (instances included) of a document that
 * load_mitsuba_doc.c has prepared (<include>, defaults and $substitution, refs, 0.6's
 * names); load_mitsuba_props.c reads properties and transforms, load_mitsuba_plugins.c
 * translates BSDFs, media and emitters.
 * The result is a valo JSON scene tree read by load_json_tree (docs/scene-format.md,
 * "Mitsuba scenes", lists what is read and how). */
#include "load/load.h"
#include "load/load_json_internal.h"
#include "load/mitsuba_internal.h"
#include "core/error.h"
#include "core/atomicfile.h"
#include "core/grow.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- sensor, film, sampler, integrator ---- */

static valo_status put_num(mctx *c, cJSON *o, const char *key, double v) {
  if (!cJSON_AddNumberToObject(o, key, v)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  return VALO_OK;
}
static cJSON *put_obj(cJSON *o, const char *key) {
  cJSON *x = cJSON_GetObjectItemCaseSensitive(o, key);
  return x ? x : cJSON_AddObjectToObject(o, key);
}
static cJSON *vec_json(double x, double y, double z) { return cJSON_CreateDoubleArray((double[]){x, y, z}, 3); }

static valo_status read_film(mctx *c, xml_node *film, int *w, int *h) {
  *w = 768; *h = 576; /* Mitsuba's defaults */
  cJSON *f = put_obj(c->out, "film");
  if (!f) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  const char *rf = "gaussian";
  double radius = 2;
  if (film) {
    const char *type = xml_attr_get(film, "type");
    if (type && strcmp(type, "hdrfilm") && strcmp(type, "specfilm") && strcmp(type, "ldrfilm"))
      mi_warn(c, film, "read as an hdrfilm");
    TRY(mi_int(c, film, "width", w));
    TRY(mi_int(c, film, "height", h));
    if (*w < 1 || *h < 1 || *w > 16384 || *h > 16384) return mi_bad(c, film, "width and height must be 1 to 16384");
    static const char *const crop[4][2] = {{"crop_offset_x", "crop_x"}, {"crop_offset_y", "crop_y"}, {"crop_width", "crop_width"}, {"crop_height", "crop_height"}};
    for (int i = 0; i < 4; i++) {
      int v = -1;
      TRY(mi_int(c, film, crop[i][0], &v));
      if (v >= 0) TRY(put_num(c, f, crop[i][1], v));
    }
    /* What valo writes is chosen on its command line: the film's file settings are not read. */
    static const char *const quiet[] = {"file_format", "pixel_format", "component_format", "banner", "high_quality_edges", "sample_border", NULL};
    for (int i = 0; quiet[i]; i++) (void)mi_prop(c, film, quiet[i]);
    xml_node *r = mi_child(c, film, "rfilter", 0);
    if (r) {
      const char *t = xml_attr_get(r, "type");
      if (t && (!strcmp(t, "box") || !strcmp(t, "tent") || !strcmp(t, "gaussian"))) {
        rf = t;
        radius = !strcmp(t, "box") ? 0.5 : !strcmp(t, "tent") ? 1 : 2;
        if (!strcmp(t, "gaussian")) {
          double sd = 0.5;
          TRY(mi_float(c, r, "stddev", &sd));
          radius = 4 * sd; /* valo's Gaussian has standard deviation radius / 4 */
        } else {
          TRY(mi_float(c, r, "radius", &radius));
        }
        if (!(radius >= 0.1 && radius <= 16)) return mi_bad(c, r, "valo's filter radius is 0.1 to 16 pixels");
        mi_warn_unused(c, r);
      } else if (t && (!strcmp(t, "mitchell") || !strcmp(t, "catmullrom") || !strcmp(t, "lanczos"))) {
        /* Mitsuba's cubics have radius 2; its Lanczos has radius "lobes" (default 3) */
        radius = 2;
        rf = t[0] == 'c' ? "catmull-rom" : t;
        if (t[0] == 'l') {
          int lobes = 3;
          TRY(mi_int(c, r, "lobes", &lobes));
          if (lobes < 1 || lobes > 16) return mi_bad(c, r, "valo's Lanczos filter has 1 to 16 lobes");
          radius = lobes;
        } else if (t[0] == 'm') {
          double b = 1.0 / 3, cc = 1.0 / 3;
          TRY(mi_float(c, r, "B", &b));
          TRY(mi_float(c, r, "C", &cc));
          if (fabs(b) < 1e-4 && fabs(cc - 0.5) < 1e-4) rf = "catmull-rom";
          else if (fabs(b - 1.0 / 3) > 1e-4 || fabs(cc - 1.0 / 3) > 1e-4)
            mi_warn(c, r, "valo's cubic filters are Mitchell's B = C = 1/3 and Catmull-Rom's B = 0, C = 1/2: read as Mitchell's");
        }
        mi_warn_unused(c, r);
      } else {
        mi_warn(c, r, "valo has no such filter (box, tent, gaussian, mitchell, catmullrom, lanczos): it uses Mitsuba's default, a Gaussian of standard deviation 0.5");
      }
    }
    mi_warn_unused(c, film);
  }
  TRY(put_num(c, f, "width", *w));
  TRY(put_num(c, f, "height", *h));
  if (!cJSON_AddStringToObject(f, "filter", rf)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  /* Mitsuba's film splats each sample into the pixels its filter reaches */
  if (!cJSON_AddBoolToObject(f, "splat", 1)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  return put_num(c, f, "filter_radius", radius);
}

static valo_status read_sensor(mctx *c, xml_node *s) {
  const char *type = xml_attr_get(s, "type");
  int persp = type && (!strcmp(type, "perspective") || !strcmp(type, "thinlens"));
  int ortho = type && (!strcmp(type, "orthographic") || !strcmp(type, "telecentric"));
  if (!persp && !ortho) return mi_bad(c, s, "valo reads perspective, thinlens and orthographic sensors");
  int w, h;
  TRY(read_film(c, mi_child(c, s, "film", 0), &w, &h));
  xml_node *smp = mi_child(c, s, "sampler", 0);
  cJSON *render = put_obj(c->out, "render");
  if (!render) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  if (smp) {
    int spp = -1, seed = -1;
    TRY(mi_int(c, smp, "sample_count", &spp));
    TRY(mi_int(c, smp, "seed", &seed));
    if (spp > 0) TRY(put_num(c, render, "spp", spp));
    if (seed >= 0) TRY(put_num(c, render, "seed", seed));
    const char *st = xml_attr_get(smp, "type");
    if (st && !strcmp(st, "independent") && !cJSON_AddStringToObject(render, "sampler", "independent"))
      return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    mi_warn_unused(c, smp);
  }
  double m[16];
  TRY(mi_transform(c, s, "to_world", m, NULL));
  cJSON *cam = put_obj(c->out, "camera");
  if (!cam) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  /* Mitsuba's camera looks down its +z with +y up; its +x is the image's left. */
  double pos[3] = {m[3], m[7], m[11]}, fwd[3] = {m[2], m[6], m[10]}, up[3] = {m[1], m[5], m[9]}, lft[3] = {m[0], m[4], m[8]};
  double fl = sqrt(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]), ul = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
  if (!(fl > 0) || !(ul > 0)) return mi_bad(c, s, "to_world flattens the camera");
  double det = lft[0] * (up[1] * fwd[2] - up[2] * fwd[1]) - lft[1] * (up[0] * fwd[2] - up[2] * fwd[0]) + lft[2] * (up[0] * fwd[1] - up[1] * fwd[0]);
  if (det < 0) mi_warn(c, s, "to_world mirrors the camera; valo's image is not mirrored");
  cJSON_AddItemToObject(cam, "position", vec_json(pos[0], pos[1], pos[2]));
  cJSON_AddItemToObject(cam, "look_at", vec_json(pos[0] + fwd[0] / fl, pos[1] + fwd[1] / fl, pos[2] + fwd[2] / fl));
  cJSON_AddItemToObject(cam, "up", vec_json(up[0] / ul, up[1] / ul, up[2] / ul));
  double aspect = (double)w / h;
  if (ortho) {
    /* Mitsuba's orthographic camera sees x in [-1, 1] and y in [-1/aspect, 1/aspect] of its space. */
    if (!cJSON_AddStringToObject(cam, "type", "orthographic")) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    TRY(put_num(c, cam, "height", 2 * ul / aspect));
  } else {
    double fov = -1;
    TRY(mi_float(c, s, "fov", &fov));
    const char *axis = "x", *focal = NULL;
    TRY(mi_string(c, s, "fov_axis", &axis));
    TRY(mi_string(c, s, "focal_length", &focal));
    if (fov >= 0 && focal) return mi_bad(c, s, "give fov or focal_length, not both");
    if (fov < 0) {
      /* A 35 mm film's focal length (Mitsuba's default 50mm): the diagonal's field of view. */
      char *end;
      double f = strtod(focal ? focal : "50", &end);
      if (!(f > 0) || (*end && strcmp(end, "mm"))) return mi_bad(c, s, "focal_length \"%s\" must be a length in mm (\"50mm\")", focal);
      fov = 360 / M_PI * atan(sqrt(36.0 * 36 + 24 * 24) / (2 * f));
      axis = "diagonal";
    }
    if (!(fov > 0 && fov < 180)) return mi_bad(c, s, "fov must be in (0, 180) degrees");
    double t = tan(fov * M_PI / 360), scale; /* tan(vertical / 2) = t * scale */
    if (!strcmp(axis, "x")) scale = 1 / aspect;
    else if (!strcmp(axis, "y")) scale = 1;
    else if (!strcmp(axis, "diagonal")) scale = 1 / sqrt(aspect * aspect + 1);
    else if (!strcmp(axis, "smaller")) scale = aspect < 1 ? 1 / aspect : 1;
    else if (!strcmp(axis, "larger")) scale = aspect > 1 ? 1 / aspect : 1;
    else return mi_bad(c, s, "fov_axis must be x, y, diagonal, smaller or larger");
    TRY(put_num(c, cam, "fov", 360 / M_PI * atan(t * scale)));
  }
  double ar = 0, fd = -1;
  TRY(mi_float(c, s, "aperture_radius", &ar));
  TRY(mi_float(c, s, "focus_distance", &fd));
  if (ar > 0) TRY(put_num(c, cam, "aperture_radius", ar));
  if (fd > 0) TRY(put_num(c, cam, "focus_distance", fd));
  (void)mi_prop(c, s, "near_clip");
  (void)mi_prop(c, s, "far_clip");
  xml_node *med = mi_child(c, s, "medium", 0);
  if (med) {
    char name[192];
    TRY(mi_medium(c, med, name, sizeof name));
    if (!cJSON_AddStringToObject(cam, "medium", name)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  }
  mi_warn_unused(c, s);
  return VALO_OK;
}

static valo_status read_integrator(mctx *c, xml_node *n) {
  const char *type = xml_attr_get(n, "type");
  cJSON *render = put_obj(c->out, "render");
  if (!render) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  int depth = -1, rr = -1, direct = type && !strcmp(type, "direct");
  /* the path-guiding lab's integrator and Müller's Mitsuba 0.6 guided_path: valo's guided
   * (their other parameters -- budgets, tree thresholds -- are not read) */
  int guided = type && (!strcmp(type, "path_guiding_integrator") || !strcmp(type, "guided_path"));
  if (guided) {
    TRY(mi_int(c, n, "max_depth", &depth));
    (void)mi_int(c, n, "rr_depth", &rr);
    (void)mi_int(c, n, "rrDepth", &rr);
    (void)mi_int(c, n, "maxDepth", &depth);
    for (xml_node *k = n->child; k; k = k->next)
      if (!k->used) mi_warn(c, k, "guided does not read this parameter of %s", type);
    for (xml_node *k = n->child; k; k = k->next) k->used = 1;
  } else if (type && (!strcmp(type, "path") || !strcmp(type, "volpath") || !strcmp(type, "volpathmis") || !strcmp(type, "prb") || direct)) {
    TRY(mi_int(c, n, "max_depth", &depth));
    TRY(mi_int(c, n, "rr_depth", &rr));
    int hide = 0;
    TRY(mi_bool(c, n, "hide_emitters", &hide));
    if (hide && !cJSON_AddTrueToObject(render, "hide_emitters")) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    if (direct) { depth = 2; (void)mi_prop(c, n, "emitter_samples"); (void)mi_prop(c, n, "bsdf_samples"); }
  } else {
    mi_warn(c, n, "not an integrator valo has: rendered by path (valo render --integrator chooses another)");
    (void)mi_int(c, n, "max_depth", &depth);
    (void)mi_int(c, n, "rr_depth", &rr);
    for (xml_node *k = n->child; k; k = k->next) k->used = 1;
  }
  /* Mitsuba counts the camera ray as a depth (max_depth 2 = direct light); valo counts bounces. */
  if (depth == 0) mi_warn(c, n, "max_depth 0 renders nothing in Mitsuba; valo renders the emitters seen directly");
  if (!cJSON_AddStringToObject(render, "integrator", guided ? "guided" : "path")) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  if (depth >= 0) TRY(put_num(c, render, "max_depth", depth > 0 ? depth - 1 : 0));
  if (rr >= 0) TRY(put_num(c, render, "rr_depth", rr > 0 ? rr - 1 : 0)); /* the same count */
  mi_warn_unused(c, n);
  return VALO_OK;
}

/* ---- shapes ---- */

static valo_status matrix_json(mctx *c, const double m[16], cJSON *shape) {
  cJSON *t = cJSON_AddObjectToObject(shape, "transform");
  cJSON *a = t ? cJSON_CreateDoubleArray(m, 16) : NULL;
  if (!a) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  cJSON_AddItemToObject(t, "matrix", a);
  return VALO_OK;
}

static valo_status read_shape(mctx *c, xml_node *n) {
  const char *type = xml_attr_get(n, "type");
  if (!type) return mi_bad(c, n, "needs a type");
  cJSON *sh = cJSON_CreateObject();
  if (!sh) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  cJSON_AddItemToArray(c->shapes, sh);
  const xml_node **l = grow_for(c->shape_at, (size_t)c->nshape_at, sizeof *l);
  if (!l) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->shape_at = l;
  l[c->nshape_at++] = n;
  double m[16];
  int has_xf;
  TRY(mi_transform(c, n, "to_world", m, &has_xf));
  if (c->outer) { /* an instance's shape: the instance's to_world after the shape's own */
    mi_mat_mul(m, c->outer, m);
    has_xf = 1;
  }
  int flip = 0;
  TRY(mi_bool(c, n, "flip_normals", &flip));
  int serialized = !strcmp(type, "serialized");
  if (!strcmp(type, "obj") || !strcmp(type, "ply") || serialized) {
    const char *file = NULL;
    TRY(mi_string(c, n, "filename", &file));
    if (!file) return mi_bad(c, n, "needs <string name=\"filename\">");
    if (flip) return mi_bad(c, n, "flip_normals is not read for meshes (the file's winding sets the front side)");
    int fn = 0;
    TRY(mi_bool(c, n, "face_normals", &fn));
    if (fn) cJSON_AddTrueToObject(sh, "face_normals");
    else cJSON_AddTrueToObject(sh, "smooth_normals"); /* Mitsuba computes normals a file lacks */
    /* Mitsuba turns an OBJ's v over (flip_tex_coords, default true), which undoes OBJ's
     * bottom-up v as valo reads it; a PLY's it reads as it stands, running down the image. */
    int turn = 1;
    if (!strcmp(type, "obj")) TRY(mi_bool(c, n, "flip_tex_coords", &turn));
    if (!serialized && (!strcmp(type, "ply") || !turn)) cJSON_AddTrueToObject(sh, "flip_v");
    if (!(file = mi_found(c, file))) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    cJSON_AddStringToObject(sh, "file", file);
    int index = 0;
    if (serialized) {
      TRY(mi_int(c, n, "shape_index", &index));
      if (index < 0) return mi_bad(c, n, "shape_index must not be negative");
      cJSON_AddNumberToObject(sh, "shape_index", index);
    }
    if (has_xf) TRY(matrix_json(c, m, sh));
  } else if (!strcmp(type, "sphere")) {
    vec3 ctr = v3(0, 0, 0);
    double r = 1;
    TRY(mi_point(c, n, "center", &ctr));
    TRY(mi_float(c, n, "radius", &r));
    double rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}; /* the turn of its to_world, which places its textures */
    if (has_xf) {
      /* A sphere moved and scaled evenly stays a sphere; anything else is not read. */
      double sx = sqrt(m[0] * m[0] + m[4] * m[4] + m[8] * m[8]), sy = sqrt(m[1] * m[1] + m[5] * m[5] + m[9] * m[9]),
             sz = sqrt(m[2] * m[2] + m[6] * m[6] + m[10] * m[10]);
      double d01 = m[0] * m[1] + m[4] * m[5] + m[8] * m[9], d02 = m[0] * m[2] + m[4] * m[6] + m[8] * m[10], d12 = m[1] * m[2] + m[5] * m[6] + m[9] * m[10];
      if (fabs(sx - sy) > 1e-5 * sx || fabs(sx - sz) > 1e-5 * sx || fabs(d01) + fabs(d02) + fabs(d12) > 1e-5 * sx * sx)
        return mi_bad(c, n, "a sphere's to_world must move, turn and scale it evenly (valo has no ellipsoids)");
      vec3 p = ctr;
      ctr = v3((float)(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3]), (float)(m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7]),
               (float)(m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]));
      r *= sx;
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) rot[3 * i + j] = m[4 * i + j] / sx;
    }
    cJSON_AddStringToObject(sh, "type", "sphere");
    cJSON_AddItemToObject(sh, "center", vec_json(ctr.x, ctr.y, ctr.z));
    TRY(put_num(c, sh, "radius", r));
    if (flip) cJSON_AddTrueToObject(sh, "flip_normals");
    cJSON_AddTrueToObject(sh, "mitsuba_uv"); /* its textures where Mitsuba puts them */
    if (has_xf) {
      cJSON *fr = cJSON_CreateDoubleArray(rot, 9);
      if (!fr || !cJSON_AddItemToObject(sh, "uv_frame", fr)) { cJSON_Delete(fr); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
    }
  } else if (!strcmp(type, "rectangle") || !strcmp(type, "cube") || !strcmp(type, "disk")) {
    cJSON_AddStringToObject(sh, "type", type);
    if (has_xf) TRY(matrix_json(c, m, sh));
    if (flip) cJSON_AddTrueToObject(sh, "flip_normals");
    cJSON_AddTrueToObject(sh, "mitsuba_uv"); /* its textures where Mitsuba puts them */
  } else if (!strcmp(type, "cylinder")) {
    vec3 p0 = v3(0, 0, 0), p1 = v3(0, 0, 1);
    double r = 1;
    TRY(mi_point(c, n, "p0", &p0));
    TRY(mi_point(c, n, "p1", &p1));
    TRY(mi_float(c, n, "radius", &r));
    cJSON_AddStringToObject(sh, "type", "cylinder");
    cJSON_AddItemToObject(sh, "p0", vec_json(p0.x, p0.y, p0.z));
    cJSON_AddItemToObject(sh, "p1", vec_json(p1.x, p1.y, p1.z));
    TRY(put_num(c, sh, "radius", r));
    if (has_xf) TRY(matrix_json(c, m, sh));
    if (flip) cJSON_AddTrueToObject(sh, "flip_normals");
    cJSON_AddTrueToObject(sh, "mitsuba_uv"); /* its textures where Mitsuba puts them */
  } else {
    return mi_bad(c, n, "valo reads obj, ply, serialized, sphere, rectangle, cube, disk and cylinder shapes");
  }
  /* Material: the shape's BSDF (or Mitsuba's default), with its area emitter's radiance. */
  xml_node *b = mi_child(c, n, "bsdf", 0);
  xml_node *e = mi_child(c, n, "emitter", 0);
  cJSON *emit = NULL;
  if (e) {
    const char *et = xml_attr_get(e, "type");
    if (!et || strcmp(et, "area")) return mi_bad(c, e, "a shape's emitter must be an area emitter");
    TRY(mi_color(c, e, "radiance", MI_EMITTER, &emit));
    if (!emit && !(emit = vec_json(1, 1, 1))) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    mi_warn_unused(c, e);
    /* An emitting sphere gives Mitsuba's exact sphere's power: valo's 5 120 triangles
     * scaled to its area (unscaled they have 0.12 % less area, and power). */
    if (!strcmp(type, "sphere") && !cJSON_AddTrueToObject(sh, "exact_area")) { cJSON_Delete(emit); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
  }
  char name[192];
  valo_status st = mi_material(c, b, emit, n, name, sizeof name);
  cJSON_Delete(emit);
  if (st) return st;
  cJSON_AddStringToObject(sh, "material", name);
  for (int side = 0; side < 2; side++) {
    const char *key = side ? "exterior" : "interior";
    xml_node *med = mi_prop(c, n, key); /* inline, or a ref (check_refs: it names an element) */
    if (!med) continue;
    if (strcmp(med->name, "medium")) return mi_bad(c, med, "is the shape's %s: it must be a <medium>", key);
    TRY(mi_medium(c, med, name, sizeof name));
    cJSON_AddStringToObject(sh, key, name);
  }
  mi_warn_unused(c, n);
  return VALO_OK;
}

/* Mitsuba's instancing: a <shape type="shapegroup" id=".."> holds shapes that are not
 * rendered where they stand; each <shape type="instance"> with a <ref> to it and a
 * to_world places them all once more. valo has no instances in its scene: each is read
 * as copies of the group's shapes, placed by the instance's to_world after their own
 * (memory and load time grow with the count). As in Mitsuba, a group holds neither
 * emitters nor groups or instances. The group's unread properties are warned about once. */
static valo_status check_group(mctx *c, xml_node *g) {
  if (!g->used) g->used = 1; /* 2 once an instance has read its shapes */
  for (xml_node *k = g->child; k; k = k->next) {
    if (!strcmp(k->name, "shape")) {
      const char *t = xml_attr_get(k, "type");
      if (t && (!strcmp(t, "shapegroup") || !strcmp(t, "instance"))) return mi_bad(c, k, "a shapegroup cannot hold groups or instances (nor can Mitsuba's)");
      if (mi_child(c, k, "emitter", 0)) return mi_bad(c, k, "an emitting shape cannot be instanced (nor can it in Mitsuba)");
    } else if (strcmp(k->name, "ref")) {
      return mi_bad(c, k, "a shapegroup holds shapes");
    }
  }
  return VALO_OK;
}

static valo_status read_instance(mctx *c, xml_node *n) {
  xml_node *g = NULL;
  for (xml_node *k = n->child; k; k = k->next)
    if (!strcmp(k->name, "ref")) {
      if (g) return mi_bad(c, k, "an instance refers to one shapegroup");
      xml_node *t = mi_find_id(c, xml_attr_get(k, "id"));
      const char *tt = t ? xml_attr_get(t, "type") : NULL;
      if (!t || strcmp(t->name, "shape") || !tt || strcmp(tt, "shapegroup")) return mi_bad(c, k, "an instance refers to a <shape type=\"shapegroup\">");
      k->used = 1;
      g = t;
    }
  if (!g) return mi_bad(c, n, "needs a <ref id=\"...\"/> to its shapegroup");
  double m[16];
  TRY(mi_transform(c, n, "to_world", m, NULL));
  mi_warn_unused(c, n);
  int again = g->used == 2;
  TRY(check_group(c, g));
  g->used = 2;
  c->outer = m;
  c->quiet = again;
  valo_status st = VALO_OK;
  for (xml_node *k = g->child; k && !st; k = k->next) {
    xml_node *sh = !strcmp(k->name, "ref") ? mi_find_id(c, xml_attr_get(k, "id")) : k;
    if (!sh || strcmp(sh->name, "shape")) { st = mi_bad(c, k, "a shapegroup holds shapes"); break; }
    k->used = 1;
    st = read_shape(c, sh);
  }
  c->outer = NULL;
  c->quiet = 0;
  return st;
}

/* ---- the document ---- */

static valo_status read_document(mctx *c) {
  TRY(mi_document_prepare(c));
  xml_node *r = c->root;
  int sensors = 0;
  for (xml_node *k = r->child; k; k = k->next) {
    if (!strcmp(k->name, "default")) continue;
    if (!strcmp(k->name, "sensor")) {
      if (sensors++) { mi_warn(c, k, "valo renders the first sensor; this one is not read"); continue; }
      k->used = 1;
      TRY(read_sensor(c, k));
    } else if (!strcmp(k->name, "integrator")) {
      k->used = 1;
      TRY(read_integrator(c, k));
    } else if (!strcmp(k->name, "shape")) {
      const char *type = xml_attr_get(k, "type");
      k->used = 1;
      if (type && !strcmp(type, "shapegroup")) TRY(check_group(c, k)); /* placed by its instances */
      else if (type && !strcmp(type, "instance")) TRY(read_instance(c, k));
      else TRY(read_shape(c, k));
    } else if (!strcmp(k->name, "emitter")) {
      k->used = 1;
      TRY(mi_emitter(c, k));
    } else if (!strcmp(k->name, "bsdf") || !strcmp(k->name, "texture") || !strcmp(k->name, "medium") || !strcmp(k->name, "phase") ||
               !strcmp(k->name, "volume")) {
      continue; /* read where a shape or sensor refers to it */
    } else {
      return mi_bad(c, k, "valo does not read this element here (sensor, integrator, shape, emitter, bsdf, texture, medium, default)");
    }
  }
  if (!sensors) {
    /* Mitsuba's default sensor is a perspective camera at the origin looking down +z. */
    return mi_bad(c, r, "has no <sensor>: valo needs the camera given");
  }
  return VALO_OK;
}

/* Adds the XML line of the shape or light the JSON stage was reading to its message. */
static void add_lines(mctx *c, const int at[2]) {
  const xml_node **nodes[2] = {c->shape_at, c->light_at};
  int nl[2] = {c->nshape_at, c->nlight_at};
  for (int j = 0; j < 2; j++) {
    int i = at[j];
    if (i < 0 || i >= nl[j]) continue;
    size_t len = strlen(c->err->message);
    const xml_node *n = nodes[j][i];
    snprintf(c->err->message + len, sizeof c->err->message - len, " (the %s at line %d%s%s)", j ? "<emitter>" : "<shape>", n->line,
             n->file ? " of " : "", n->file ? n->file : "");
    return;
  }
}

/* Reads and translates path: *c holds the JSON tree (c->out) and the XML (free both with
 * translation_free). */
static valo_status translate_file(mctx *c, const char *path, const char *defines, valo_error *err) {
  memset(c, 0, sizeof *c);
  c->path = path; c->err = err; c->defines = defines;
  char *text;
  size_t len;
  TRY(scene_text_read(path, &text, &len, err));
  valo_status st = xml_parse(path, text, len, &c->root, err);
  free(text);
  if (st) return st;
  c->out = cJSON_CreateObject();
  if (c->out) {
    c->materials = cJSON_AddObjectToObject(c->out, "materials");
    c->media = cJSON_AddObjectToObject(c->out, "media");
    c->shapes = cJSON_AddArrayToObject(c->out, "shapes");
    c->lights = cJSON_AddArrayToObject(c->out, "lights");
  }
  if (!c->out || !c->materials || !c->media || !c->shapes || !c->lights) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  return read_document(c);
}

static void translation_free(mctx *c) {
  cJSON_Delete(c->out);
  xml_free(c->root);
  free(c->shape_at);
  free(c->light_at);
  for (int i = 0; i < c->nincluded; i++) free(c->included[i]);
  free(c->included);
  for (int i = 0; i < c->nsearch; i++) free(c->search[i]);
  free(c->search);
  for (int i = 0; i < c->nfound; i++) free(c->found[i]);
  free(c->found);
  free(c->bsdf_names);
  free(c->ids);
  free(c->bsdf_stack);
  strmap_free(&c->bsdf_ids);
  strmap_free(&c->material_names);
}

valo_status load_mitsuba(scene *s, const char *path, const char *defines, valo_options *settings, valo_error *err) {
  mctx c;
  valo_status st = translate_file(&c, path, defines, err);
  if (!st) {
    int at[2] = {-1, -1};
    st = load_json_tree(s, path, c.out, settings, at, err);
    if (st) add_lines(&c, at);
  }
  translation_free(&c);
  return st;
}

/* A file name of the translated tree made absolute (the JSON file may live elsewhere). */
static valo_status absolute(cJSON *item, const char *dir, valo_error *err) {
  const char *v = cJSON_GetStringValue(item);
  if (!v || v[0] == '/' || !dir[0]) return VALO_OK;
  char full[4096];
  snprintf(full, sizeof full, "%s/%s", dir, v);
  if (!cJSON_SetValuestring(item, full)) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  return VALO_OK;
}

valo_status mitsuba_to_json(const char *path, const char *defines, const char *out, valo_error *err) {
  mctx c;
  valo_status st = translate_file(&c, path, defines, err);
  char dir[4096] = "";
  char *real = st ? NULL : realpath(path, NULL);
  if (real) {
    char *slash = strrchr(real, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - real), real);
    free(real);
  }
  /* Every value that names a file: shapes' "file", media's and the environment's "file",
   * and a material's texture objects' "file". */
  for (cJSON *sh = c.shapes ? c.shapes->child : NULL; !st && sh; sh = sh->next) st = absolute(cJSON_GetObjectItemCaseSensitive(sh, "file"), dir, err);
  for (cJSON *m = c.media ? c.media->child : NULL; !st && m; m = m->next) st = absolute(cJSON_GetObjectItemCaseSensitive(m, "file"), dir, err);
  if (!st) st = absolute(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(c.out, "environment"), "file"), dir, err);
  for (cJSON *m = c.materials ? c.materials->child : NULL; !st && m; m = m->next)
    for (cJSON *k = m->child; !st && k; k = k->next)
      if (cJSON_IsObject(k)) st = absolute(cJSON_GetObjectItemCaseSensitive(k, "file"), dir, err);
  char *text = st ? NULL : cJSON_Print(c.out);
  if (!st && !text) st = err_set(err, VALO_ERR_NOMEM, "out of memory");
  if (!st) {
    size_t n = strlen(text);
    text[n] = '\n'; /* cJSON_Print's NUL becomes the last line's end */
    if (atomic_write(out, text, n + 1)) st = err_set(err, VALO_ERR_IO, "%s: cannot write: %s", out, strerror(errno));
  }
  free(text);
  translation_free(&c);
  return st;
}
