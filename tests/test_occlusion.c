/* test_occlusion.c — seed 003's occlusion methods:
 *  - `ao` against closed forms: an open plane gives 1; on a floor at distance x from an
 *    infinite wall with ray length D, a cosine-weighted direction projects to a uniform
 *    point of the unit disc (Malley), so the unoccluded fraction is
 *    1 - (acos a - a sqrt(1 - a^2)) / pi with a = x / D (1/2 at the foot of the wall), and
 *    the bent normal leans away from the wall by atan((4 / 3 pi) / (2 / 3)) = 32.5 deg;
 *    under an infinite plane at height h it is 0 for D = inf and 1 for D < h;
 *  - `proximity-ao`'s splatting: every final edge <= 2d, no two points closer than d/2,
 *    point counts in the range the spacing implies, the same points on every run, per-
 *    shape spacing; images bit-identical for 1 and 3 threads; per-shape strength;
 *  - on CornellBox-Original, proximity-ao correlates with converged ao. */
#include "harness.h"
#include "load/load.h"
#include "scene/splat.h"
#include "geometry/pointtree.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define BIG "10000"
static const char *floor_obj = "v 0 0 -" BIG "\nv " BIG " 0 -" BIG "\nv " BIG " 0 " BIG "\nv 0 0 " BIG "\nf 1 2 3 4\n";
static const char *wide_floor_obj = "v -" BIG " 0 -" BIG "\nv " BIG " 0 -" BIG "\nv " BIG " 0 " BIG "\nv -" BIG " 0 " BIG "\nf 1 2 3 4\n";
/* the wall reaches below the floor, so that no hit lands on an edge (at coordinates of
 * 10^4 a float's error is 10^-3) */
static const char *wall_obj = "v 0 -" BIG " -" BIG "\nv 0 -" BIG " " BIG "\nv 0 " BIG " " BIG "\nv 0 " BIG " -" BIG "\nf 1 2 3 4\n";
static const char *ceiling_obj = "v -" BIG " 1 -" BIG "\nv " BIG " 1 -" BIG "\nv " BIG " 1 " BIG "\nv -" BIG " 1 " BIG "\nf 1 2 3 4\n";

/* The ao value (and bent normal) at floor point (x, 0, 0), seen from straight above. */
static int ao_at(const char *shapes, double x, double cam_y, const char *params, int spp, double *ao, vec3 *bent) {
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [%.9g, %.9g, 0], \"look_at\": [%.9g, 0, 0], \"up\": [0, 0, -1], \"fov\": 0.01},\n"
           "  \"film\": {\"width\": 1, \"height\": 1},\n"
           "  \"render\": {\"integrator\": \"ao\", \"spp\": %d, \"seed\": 3, \"ao\": {%s}},\n"
           "  \"shapes\": [%s] }\n", x, cam_y, x, spp, params, shapes);
  const char *path = scratch_file("ao.json", json);
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1 | VALO_AOVS_AO;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  if (!r) return -1;
  float px[3];
  valo_render_pixels(r, px);
  *ao = px[1];
  image b;
  if (read_aov(r, "bent", &b)) return -1;
  *bent = v3(b.rgb[0], b.rgb[1], b.rgb[2]);
  image_free(&b);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}

static int write_planes(void) {
  return scratch_file("floor.obj", floor_obj) && scratch_file("wide_floor.obj", wide_floor_obj) && scratch_file("wall.obj", wall_obj) &&
                 scratch_file("ceiling.obj", ceiling_obj)
             ? 0
             : -1;
}

static int ao_open_plane(void) {
  CHECK(write_planes() == 0, "write");
  double v;
  vec3 b;
  CHECK(ao_at("{\"file\": \"wide_floor.obj\"}", 0.3, 1, "\"distance\": 1e30", 256, &v, &b) == 0, "render");
  fprintf(stderr, "open plane: ao %.6f, bent normal (%.4f %.4f %.4f)\n", v, b.x, b.y, b.z);
  CHECK(v == 1, "ao %g", v);
  /* every direction is open: the bent normal is the mean cosine-weighted direction, the normal */
  CHECK(fabs(b.y - 1) < 1e-3 && fabs(b.x) < 0.03 && fabs(b.z) < 0.03, "bent (%g %g %g)", b.x, b.y, b.z);
  return 0;
}

static int ao_wall_closed_form(void) {
  CHECK(write_planes() == 0, "write");
  const char *shapes = "{\"file\": \"floor.obj\"}, {\"file\": \"wall.obj\"}";
  struct { double x, D; } cs[] = {{0.02, 1e30}, {0.5, 1.0}, {0.2, 1.0}, {0.9, 1.0}};
  for (int i = 0; i < 4; i++) {
    char p[64];
    snprintf(p, sizeof p, "\"distance\": %.9g", cs[i].D);
    double v;
    vec3 b;
    CHECK(ao_at(shapes, cs[i].x, 0.3, p, 4096, &v, &b) == 0, "render");
    double a = cs[i].x / cs[i].D;
    double want = 1 - (acos(a) - a * sqrt(1 - a * a)) / M_PI;
    /* binomial sigma at 4096 rays <= 0.0078; the Sobol rays are stratified (far less) */
    fprintf(stderr, "x %.3g, D %.3g: ao %.5f, closed form %.5f; bent (%.4f %.4f %.4f)\n", cs[i].x, cs[i].D, v, want, b.x, b.y, b.z);
    CHECK(fabs(v - want) < 0.02, "ao %g, expected %g", v, want);
    if (i == 0) {
      /* at the foot: mean open direction (4/(3 pi), 2/3, 0) normalised, leaning away (+x) */
      double ang = atan2(b.x, b.y) * 180 / M_PI, want_ang = atan2(4 / (3 * M_PI), 2.0 / 3) * 180 / M_PI;
      fprintf(stderr, "bent normal leans %.2f deg from the floor normal (closed form %.2f)\n", ang, want_ang);
      CHECK(fabs(ang - want_ang) < 1.5, "bent normal angle %g", ang);
    }
  }
  return 0;
}

static int ao_under_plane(void) {
  CHECK(write_planes() == 0, "write");
  const char *shapes = "{\"file\": \"wide_floor.obj\"}, {\"file\": \"ceiling.obj\"}";
  double v;
  vec3 b;
  CHECK(ao_at(shapes, 0, 0.5, "\"distance\": 1e30", 1024, &v, &b) == 0, "render");
  fprintf(stderr, "under a plane at h = 1, D = inf: ao %g\n", v);
  CHECK(v == 0, "ao %g", v);
  CHECK(ao_at(shapes, 0, 0.5, "\"distance\": 0.99", 1024, &v, &b) == 0, "render");
  fprintf(stderr, "under a plane at h = 1, D = 0.99: ao %g\n", v);
  CHECK(v == 1, "ao %g", v);
  return 0;
}

/* ---- proximity-ao ---- */
static int load_internal(const char *path, scene **out) {
  valo_error err;
  scene *s = scene_new(path);
  if (!s) return -1;
  if (load_json(s, path, NULL, &err) || scene_commit(s, &err)) { fprintf(stderr, "%s\n", err.message); scene_free(s); return -1; }
  *out = s;
  return 0;
}

typedef struct near_acc { uint32_t self; int close; } near_acc;
static void near_visit(void *u, uint32_t i, float d2) {
  near_acc *a = u;
  (void)d2;
  if (i != a->self) a->close++;
}

static double total_area(const scene *s, uint32_t t0, uint32_t t1) {
  double a = 0;
  for (uint32_t t = t0; t < t1; t++) a += 0.5 * v3_len(scene_tri_ng(s, t));
  return a;
}

static int proximity_splatting(void) {
  CHECK(scratch_file("quad.obj", "v 0 0 0\nv 3 0 0\nv 3 0 2\nv 0 0 2\nf 1 2 3 4\n"), "write");
  /* a long thin triangle too, and a sphere sharing nothing with the quad */
  CHECK(scratch_file("sliver.obj", "v 0 1 0\nv 4 1 0.05\nv 4 1 0\nf 1 2 3\n"), "write");
  const char *json = "{ \"shapes\": [ {\"file\": \"quad.obj\"}, {\"file\": \"sliver.obj\"},\n"
                     "  {\"type\": \"sphere\", \"center\": [1, 2, 1], \"radius\": 0.5, \"proximity\": {\"spacing\": 0.02}} ] }";
  const char *path = scratch_file("splat.json", json);
  scene *s;
  CHECK(load_internal(path, &s) == 0, "load");
  const float d = 0.05f;
  splat_points a, b;
  CHECK(splat_scene(s, d, 10000000, 1, &a) == 0, "splat");
  CHECK(splat_scene(s, d, 10000000, 3, &b) == 0, "splat again, 3 threads");
  CHECK(a.n_pts == b.n_pts && !memcmp(a.p, b.p, a.n_pts * sizeof *a.p) && !memcmp(a.n, b.n, a.n_pts * sizeof *a.n) &&
            !memcmp(a.area, b.area, a.n_pts * sizeof *a.area),
        "not deterministic");
  fprintf(stderr, "%u points; longest final edge / 2d = %.4f\n", a.n_pts, a.max_edge_ratio);
  CHECK(a.max_edge_ratio <= 1.0f, "a final edge is %.4f x 2d", a.max_edge_ratio);
  /* no two points closer than half their spacing */
  point_tree t;
  CHECK(point_tree_build(&t, a.p, a.n_pts) == 0, "tree");
  int close = 0;
  for (uint32_t i = 0; i < t.n; i++) {
    float sp = a.spacing[t.id[i]];
    near_acc acc = {i, 0};
    point_tree_radius(&t, t.p[i], 0.25f * sp * sp * 0.999f, near_visit, &acc);
    close += acc.close;
  }
  CHECK(close == 0, "%d pairs closer than d/2", close);
  /* counts: the quad (area 6) at spacing d and the sphere at its own 0.02 */
  uint32_t on_quad = 0, on_sphere = 0;
  for (uint32_t i = 0; i < a.n_pts; i++) {
    if (a.p[i].y == 0) on_quad++;
    if (v3_len(v3_sub(a.p[i], v3(1, 2, 1))) < 0.6f) on_sphere++;
  }
  double qa = total_area(s, 0, 2), sa = total_area(s, s->shape_ao[0].first, s->shape_ao[0].end);
  double dq = on_quad * (double)d * d / qa, ds = on_sphere * 0.02 * 0.02 / sa;
  fprintf(stderr, "points per d^2 of area: quad %.3f, sphere (own spacing) %.3f\n", dq, ds);
  CHECK(dq > 0.5 && dq < 4.7 && ds > 0.5 && ds < 4.7, "densities %g %g", dq, ds);
  point_tree_free(&t);
  splat_free(&a);
  splat_free(&b);
  scene_free(s);
  return 0;
}

static float *render_prox(const char *json, int threads, int *w, int *h) {
  valo_options o;
  valo_options_init(&o);
  o.threads = threads;
  return render_json_text(json, &o, w, h);
}

static int proximity_threads_and_shapes(void) {
  CHECK(scratch_file("box_floor.obj", "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nf 1 2 3 4\n"), "write");
  const char *base = "{ \"camera\": {\"position\": [0, 3, 3], \"look_at\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 50},\n"
                     "  \"film\": {\"width\": 48, \"height\": 48},\n"
                     "  \"render\": {\"integrator\": \"proximity-ao\", \"spp\": 2, \"proximity-ao\": {\"radius\": 0.6}},\n"
                     "  \"shapes\": [ {\"file\": \"box_floor.obj\"%s},\n"
                     "    {\"type\": \"sphere\", \"center\": [0, 0.45, 0], \"radius\": 0.5} ] }";
  char json[2048];
  snprintf(json, sizeof json, base, "");
  int w, h, w2, h2;
  float *a = render_prox(json, 1, &w, &h), *b = render_prox(json, 3, &w2, &h2);
  CHECK(a && b, "render");
  CHECK(!memcmp(a, b, (size_t)w * h * 3 * sizeof *a), "1 and 3 threads differ");
  /* with strength 0 on the floor, no pixel gets darker and the floor's pixels (which
   * darken near the sphere by default) are white; the sphere's are unchanged */
  snprintf(json, sizeof json, base, ", \"proximity\": {\"strength\": 0}");
  float *c = render_prox(json, 2, &w, &h);
  CHECK(c, "render");
  double lighter = 0;
  int darker = 0, white = 0, same = 0;
  for (int i = 0; i < w * h; i++) {
    if (c[3 * i] < a[3 * i]) darker++;
    lighter += c[3 * i] - a[3 * i];
    white += c[3 * i] == 1;
    same += c[3 * i] == a[3 * i] && a[3 * i] < 1;
  }
  fprintf(stderr, "floor strength 0: %d pixels white, floor darkness removed %.2f, %d pixels darker, %d dark pixels unchanged\n", white,
          lighter, darker, same);
  CHECK(darker == 0 && lighter > 5 && white > w * h / 3 && same > 100, "per-shape strength");
  free(a); free(b); free(c);
  return 0;
}

static int proximity_matches_ao(void) {
  const char *obj = shared_file("scenes/cornell/CornellBox-Original.obj");
  if (!obj) return TEST_SKIP;
  char json[2048];
  const char *fmt = "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
                    "  \"film\": {\"width\": 96, \"height\": 96}, \"render\": {\"integrator\": \"%s\", \"spp\": %d},\n"
                    "  \"shapes\": [ {\"file\": \"%s\"} ] }";
  snprintf(json, sizeof json, fmt, "ao", 256, obj);
  int w, h;
  float *ao = render_json_text(json, NULL, &w, &h);
  snprintf(json, sizeof json, fmt, "proximity-ao", 4, obj);
  float *px = render_json_text(json, NULL, &w, &h);
  CHECK(ao && px, "render");
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n = w * h;
  for (int i = 0; i < w * h; i++) {
    double x = px[3 * i], y = ao[3 * i];
    sa += x; sb += y; saa += x * x; sbb += y * y; sab += x * y;
  }
  double corr = (sab / n - sa / n * sb / n) / sqrt((saa / n - sa * sa / n / n) * (sbb / n - sb * sb / n / n));
  fprintf(stderr, "CornellBox-Original: proximity-ao mean %.4f, ao (256 rays) mean %.4f, correlation %.4f\n", sa / n, sb / n, corr);
  CHECK(corr > 0.9, "correlation %g", corr);
  CHECK(fabs(sa / sb - 1) < 0.03, "means %g %g", sa / n, sb / n);
  free(ao); free(px);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"ao_open_plane", ao_open_plane},
                                    {"ao_wall_closed_form", ao_wall_closed_form},
                                    {"ao_under_plane", ao_under_plane},
                                    {"proximity_splatting", proximity_splatting},
                                    {"proximity_threads_and_shapes", proximity_threads_and_shapes},
                                    {"proximity_matches_ao", proximity_matches_ao},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
