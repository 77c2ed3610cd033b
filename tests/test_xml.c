/* test_xml.c — Mitsuba scene files (.xml): the XML reader (entities, comments, errors with
 * line and column), the translation into valo's scene (an XML scene renders as the JSON
 * scene it means), Mitsuba 0.6's camelCase names, <default> values and --define, the
 * warning for properties valo does not read, Mitsuba's unit shapes, <include>, <path>, and instancing. Against
 * Mitsuba itself: test_mitsuba from_xml and veach_mis_xml. */
#include "harness.h"
#include "load/load.h"
#include "load/xml.h"
#include "scene/scene.h"
#include "image/texture.h"
#include "valo/valo.h"
#include <stb_image_write.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int parser(void) {
  const char *ok = "<?xml version='1.0'?>\n<!-- a comment -->\n<scene version=\"3.0.0\">\n"
                   "  <string name=\"a\" value=\"x &amp; &lt;y&gt; &quot;q&quot; &apos;s&apos; &#65;&#x42; &#xe9;\"/>\n"
                   "  <!-- <shape> inside a comment is not an element -->\n"
                   "  <shape type='obj'><ref id=\"m\"/>text is ignored</shape>\n</scene>\n";
  xml_node *root;
  valo_error err;
  CHECK(xml_parse("ok.xml", ok, strlen(ok), &root, &err) == VALO_OK, "%s", err.message);
  CHECK(!strcmp(root->name, "scene") && root->line == 3, "root <%s> at line %d", root->name, root->line);
  const xml_node *s = root->child;
  CHECK(s && !strcmp(s->name, "string") && s->line == 4, "first child");
  CHECK(!strcmp(xml_attr_get(s, "value"), "x & <y> \"q\" 's' AB \xc3\xa9"), "entities decoded: [%s]", xml_attr_get(s, "value"));
  const xml_node *sh = s->next;
  CHECK(sh && !strcmp(sh->name, "shape") && sh->line == 6 && !strcmp(xml_attr_get(sh, "type"), "obj"), "second child");
  CHECK(sh->child && !strcmp(sh->child->name, "ref") && !sh->child->next && sh->next == NULL, "the ref and nothing else");
  xml_free(root);
  static const struct { const char *text, *said; } bad[] = {
      {"<scene>\n  <shape type=\"obj\">\n</scene>", "bad.xml:3:3: XML: end tag does not match <shape> of line 2"},
      {"<scene>\n  <a b=\"1\" b=\"2\"/>\n</scene>", "bad.xml:2:12: XML: attribute given twice"},
      {"<scene a=1/>", "bad.xml:1:10: XML: attribute value must be quoted"},
      {"<scene/>\n<more/>", "bad.xml:2:1: XML: text after the root element"},
      {"<scene>\n<!-- open", "bad.xml:2:1: XML: comment not closed"},
      {"<scene a=\"&nbsp;\"/>", "unknown entity"},
      {"<scene a=\"&#0;\"/>", "unknown entity"},
      {"<scene a=\"x\">", "element not closed"},
      {"", "no element in the file"},
      {"<scene><![CDATA[x]]></scene>", "CDATA"},
      {"<scene a=\"<\"/>", "'<' inside an attribute value"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    valo_status st = xml_parse("bad.xml", bad[k].text, strlen(bad[k].text), &root, &err);
    CHECK(st != VALO_OK && root == NULL, "case %zu parsed", k);
    CHECK(strstr(err.message, bad[k].said), "case %zu: \"%s\" does not say \"%s\"", k, err.message, bad[k].said);
  }
  /* nesting is bounded (no input can exhaust the stack) */
  char deep[70 * 4 + 16] = "";
  for (int i = 0; i < 70; i++) strcat(deep, "<a>");
  CHECK(xml_parse("deep.xml", deep, strlen(deep), &root, &err) != VALO_OK && strstr(err.message, "64 deep"), "%s", err.message);
  return 0;
}

/* A Mitsuba 3 scene with one of most things valo reads, and the JSON scene it means. */
static const char *XML_SCENE =
    "<scene version=\"3.0.0\">\n"
    "  <default name=\"spp\" value=\"4\"/>\n"
    "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"5\"/><integer name=\"rr_depth\" value=\"2\"/></integrator>\n"
    "  <sensor type=\"perspective\">\n"
    "    <float name=\"fov\" value=\"50\"/>\n"
    "    <transform name=\"to_world\"><lookat origin=\"0, 2, 6\" target=\"0, 0.5, 0\" up=\"0, 1, 0\"/></transform>\n"
    "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spp\"/></sampler>\n"
    "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"48\"/><integer name=\"height\" value=\"32\"/><rfilter type=\"tent\"/></film>\n"
    "  </sensor>\n"
    "  <bsdf type=\"twosided\" id=\"white\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.7, 0.6, 0.5\"/></bsdf></bsdf>\n"
    "  <bsdf type=\"roughconductor\" id=\"metal\"><float name=\"alpha\" value=\"0.09\"/><rgb name=\"eta\" value=\"0.2 0.9 1.1\"/>\n"
    "    <rgb name=\"k\" value=\"3.9, 2.4, 2.1\"/><rgb name=\"specular_reflectance\" value=\"0.8, 0.8, 0.8\"/></bsdf>\n"
    "  <shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"4\"/><rotate x=\"1\" angle=\"-90\"/></transform>\n"
    "    <ref id=\"white\"/></shape>\n"
    "  <shape type=\"cube\"><transform name=\"to_world\"><scale x=\"0.5\" y=\"0.5\" z=\"0.5\"/><rotate y=\"1\" angle=\"30\"/>\n"
    "    <translate x=\"-1\" y=\"0.5\"/></transform><ref id=\"metal\"/></shape>\n"
    "  <shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"0.6\" z=\"0\"/><float name=\"radius\" value=\"0.6\"/>\n"
    "    <bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"bk7\"/><string name=\"ext_ior\" value=\"air\"/></bsdf></shape>\n"
    "  <shape type=\"disk\"><transform name=\"to_world\"><scale value=\"0.5\"/><rotate x=\"1\" angle=\"90\"/><translate y=\"3\"/></transform>\n"
    "    <emitter type=\"area\"><rgb name=\"radiance\" value=\"8, 8, 8\"/></emitter></shape>\n"
    "  <emitter type=\"point\"><point name=\"position\" x=\"2\" y=\"3\" z=\"2\"/><rgb name=\"intensity\" value=\"5, 5, 5\"/></emitter>\n"
    "  <emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"-2, 3, 2\" target=\"-2, 0, 2\" up=\"0, 0, 1\"/></transform>\n"
    "    <rgb name=\"intensity\" value=\"10, 10, 10\"/><float name=\"cutoff_angle\" value=\"30\"/></emitter>\n"
    "  <emitter type=\"directional\"><vector name=\"direction\" x=\"0.3\" y=\"-1\" z=\"-0.2\"/><rgb name=\"irradiance\" value=\"0.5\"/></emitter>\n"
    "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.1, 0.15, 0.2\"/></emitter>\n"
    "</scene>\n";

/* Renders path with its own settings, or at spp samples per pixel when spp > 0. */
static float *render_path_spp(const char *path, int spp, int *w, int *h) {
  valo_options o;
  valo_options_init(&o);
  o.threads = 2;
  if (spp > 0) o.spp = spp;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  if (!r) return NULL;
  valo_stats st;
  valo_render_stats(r, &st);
  *w = st.width; *h = st.height;
  float *px = malloc((size_t)st.width * st.height * 3 * sizeof(float));
  if (px) valo_render_pixels(r, px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return px;
}
static float *render_path(const char *path, int *w, int *h) { return render_path_spp(path, 0, w, h); }

/* Pixels of a and b: *far the share differing by more than 1e-4 relative (an edge a ray
 * meets on one side in one and on the other in the other), *mean the relative difference
 * of the means. */
static void differ(const float *a, const float *b, int n, double *far, double *mean) {
  double sa = 0, sb = 0;
  int nf = 0;
  for (int i = 0; i < 3 * n; i++) {
    sa += a[i]; sb += b[i];
    if (fabsf(a[i] - b[i]) > 1e-4f * fmaxf(1e-3f, fabsf(b[i]))) nf++;
  }
  *far = (double)nf / (3 * n);
  *mean = fabs(sa / sb - 1);
}

static int xml_equals_json(void) {
  /* The JSON the XML means: Mitsuba's horizontal 50-degree field on a 48 x 32 film is a
   * vertical one of 2 atan(tan 25 / 1.5); max_depth 5 and rr_depth 2 count the camera ray,
   * valo's 4 and 1 do not; alpha 0.09 is roughness 0.3; bk7 in air is 1.5046 / 1.00028; the spot's beam is
   * 3/4 of its cut-off (delta 7.5 degrees), falling off linearly in angle as Mitsuba's
   * does; the disk, with no BSDF, is Mitsuba's default diffuse 0.5. */
  double vfov = 360 / M_PI * atan(tan(25 * M_PI / 180) / 1.5);
  char json[4096];
  snprintf(json, sizeof json,
           "{\"camera\": {\"position\": [0, 2, 6], \"look_at\": [0, 0.5, 0], \"up\": [0, 1, 0], \"fov\": %.17g},\n"
           " \"film\": {\"width\": 48, \"height\": 32, \"filter\": \"tent\", \"filter_radius\": 1, \"splat\": true},\n"
           " \"render\": {\"integrator\": \"path\", \"max_depth\": 4, \"rr_depth\": 1, \"spp\": 4, \"sampler\": \"independent\"},\n"
           " \"materials\": {\"white\": {\"type\": \"diffuse\", \"reflectance\": [0.7, 0.6, 0.5]},\n"
           "   \"metal\": {\"type\": \"conductor\", \"eta\": [0.2, 0.9, 1.1], \"k\": [3.9, 2.4, 2.1], \"reflectance\": [0.8, 0.8, 0.8],\n"
           "             \"roughness\": 0.3, \"distribution\": \"beckmann\"},\n"
           "   \"glass\": {\"type\": \"dielectric\", \"ior\": %.17g},\n"
           "   \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 8}},\n"
           " \"shapes\": [{\"type\": \"rectangle\", \"transform\": {\"scale\": 4, \"rotate_x\": -90}, \"material\": \"white\"},\n"
           "   {\"type\": \"cube\", \"transform\": {\"scale\": 0.5, \"rotate_y\": 30, \"translate\": [-1, 0.5, 0]}, \"material\": \"metal\"},\n"
           "   {\"type\": \"sphere\", \"center\": [1, 0.6, 0], \"radius\": 0.6, \"material\": \"glass\"},\n"
           "   {\"type\": \"disk\", \"transform\": {\"scale\": 0.5, \"rotate_x\": 90, \"translate\": [0, 3, 0]}, \"material\": \"lamp\"}],\n"
           " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, 2], \"intensity\": 5},\n"
           "   {\"type\": \"spot\", \"position\": [-2, 3, 2], \"look_at\": [-2, 2, 2], \"intensity\": 10, \"cone_angle\": 30, \"cone_delta_angle\": 7.5, \"falloff\": \"linear\"},\n"
           "   {\"type\": \"directional\", \"direction\": [0.3, -1, -0.2], \"irradiance\": 0.5}],\n"
           " \"environment\": {\"type\": \"constant\", \"radiance\": [0.1, 0.15, 0.2]}}\n",
           vfov, 1.5046 / 1.00028);
  int w1, h1, w2, h2;
  warnings_capture(1);
  float *a = render_path(scratch_file("scene.xml", XML_SCENE), &w1, &h1);
  int warned = warnings_text()[0] != 0;
  warnings_capture(0);
  CHECK(a, "the XML scene did not render");
  CHECK(!warned, "the scene gave warnings (printed above): everything in it is read");
  float *b = render_path(scratch_file("scene.json", json), &w2, &h2);
  CHECK(b, "the JSON scene did not render");
  CHECK(w1 == 48 && h1 == 32 && w2 == 48 && h2 == 32, "sizes %dx%d, %dx%d", w1, h1, w2, h2);
  double far, mean;
  differ(a, b, w1 * h1, &far, &mean);
  fprintf(stderr, "XML against JSON: %.2f%% of pixel channels differ by more than 1e-4, means by %.2e\n", 100 * far, mean);
  CHECK(far < 0.02 && mean < 1e-3, "the XML scene renders differently from the JSON it means");
  /* and the test can tell: a metal of GGX in place of Beckmann */
  char *ggx = strdup(json), *at = strstr(ggx, "\"beckmann\"");
  memcpy(at, "\"ggx\"     ", 10);
  float *c = render_path(scratch_file("ggx.json", ggx), &w2, &h2);
  CHECK(c, "render");
  differ(c, b, w1 * h1, &far, &mean);
  CHECK(far > 0.05, "GGX and Beckmann metal rendered alike (%.2f%% of channels differ)", 100 * far);
  free(ggx); free(a); free(b); free(c);
  return 0;
}

/* Mitsuba 0.6's names (camelCase, lookAt) mean what Mitsuba 3's do: the same image. */
static int mitsuba_06_names(void) {
  char *old = strdup(XML_SCENE);
  static const char *const from[] = {"version=\"3.0.0\"", "max_depth", "rr_depth", "to_world", "to_world", "to_world", "to_world", "to_world",
                                     "sample_count", "int_ior", "ext_ior", "specular_reflectance", "cutoff_angle", "<lookat", "<lookat"};
  static const char *const to[] = {"version=\"0.6.0\"", "maxDepth", "rrDepth", "toWorld", "toWorld", "toWorld", "toWorld", "toWorld",
                                   "sampleCount", "intIOR", "extIOR", "specularReflectance", "cutoffAngle", "<lookAt", "<lookAt"};
  for (size_t k = 0; k < sizeof from / sizeof from[0]; k++) {
    char *p = strstr(old, from[k]);
    CHECK(p, "no %s left", from[k]);
    size_t a = strlen(from[k]), b = strlen(to[k]);
    char *n = malloc(strlen(old) + b + 1);
    memcpy(n, old, (size_t)(p - old));
    strcpy(n + (p - old), to[k]);
    strcat(n, p + a);
    free(old);
    old = n;
  }
  CHECK(!strstr(old, "to_world") && strstr(old, "lookAt"), "rewritten");
  int w, h;
  float *a = render_path(scratch_file("new.xml", XML_SCENE), &w, &h);
  float *b = render_path(scratch_file("old.xml", old), &w, &h);
  CHECK(a && b, "render");
  CHECK(!memcmp(a, b, (size_t)w * h * 3 * sizeof(float)), "0.6 names render differently");
  free(old); free(a); free(b);
  return 0;
}

/* <default> values, $substitution and --define (valo_load_options.defines). */
static int defaults_and_defines(void) {
  const char *xml = "<scene version=\"3.0.0\">\n<default name=\"res\" value=\"24\"/>\n"
                    "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>\n"
                    "<film type=\"hdrfilm\"><integer name=\"width\" value=\"$res\"/><integer name=\"height\" value=\"$h\"/></film></sensor>\n"
                    "<emitter type=\"constant\"/>\n</scene>\n";
  const char *p = scratch_file("defs.xml", xml);
  valo_load_options lo;
  valo_load_options_init(&lo);
  valo_scene *sc;
  valo_error err;
  CHECK(valo_scene_load_with(p, &lo, &sc, &err) != VALO_OK, "loaded with $h undefined");
  CHECK(strstr(err.message, "defs.xml:4:") && strstr(err.message, "$h has no <default"), "said: %s", err.message);
  snprintf(lo.defines, sizeof lo.defines, "h=12 res=36");
  CHECK(valo_scene_load_with(p, &lo, &sc, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  valo_scene_file_options(sc, &o);
  CHECK(o.width == 36 && o.height == 12, "film %dx%d, not 36x12 (--define replaces the default)", o.width, o.height);
  valo_scene_destroy(sc);
  return 0;
}

/* Loads path, keeping the warnings it gave in said. */
static valo_status load_saying(const char *path, char *said, size_t n, valo_error *err) {
  warnings_capture(1);
  valo_scene *sc;
  valo_status st = valo_scene_load(path, &sc, err);
  snprintf(said, n, "%s", warnings_text());
  warnings_capture(0);
  if (st == VALO_OK) valo_scene_destroy(sc);
  return st;
}

/* What valo does not read is said, naming the line; what it cannot render is an error. */
static int unread_is_said(void) {
  const char *xml = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>\n"
                    "<float name=\"shutter_open\" value=\"0\"/></sensor>\n"
                    "<shape type=\"sphere\"><bsdf type=\"diffuse\"><float name=\"roughness\" value=\"0.5\"/></bsdf></shape>\n"
                    "<emitter type=\"constant\"/>\n</scene>\n";
  char said[2048];
  valo_error err;
  CHECK(load_saying(scratch_file("unread.xml", xml), said, sizeof said, &err) == VALO_OK, "%s", err.message);
  CHECK(strstr(said, "unread.xml:3: <float name=\"shutter_open\">: not read by valo"), "said: %s", said);
  CHECK(strstr(said, "unread.xml:4: <float name=\"roughness\">: not read by valo"), "said: %s", said);
  return 0;
}

/* Mitsuba's unit shapes, emitting radiance 2 from their front: the rectangle [-1, 1]^2
 * facing +z fills the film with 2 seen from +z and 0 from behind; the cube [-1, 1]^3
 * faces out; the disk of radius 1 seen from distance 2 under a 60-degree field covers
 * pi / (2 x 2 tan 30)^2 = 3 pi / 16 of the film, so the film's mean is 2 x 3 pi / 16. */
/* A perspective sensor without fov: Mitsuba's focal_length, 50mm by default, is a 35 mm
 * film's diagonal (43.27 mm across); both fov and focal_length is an error. */
static int focal_length(void) {
  static const struct { const char *sensor; double diag_mm; } cases[] = {
      {"<sensor type=\"perspective\"/>", 50}, {"<sensor type=\"perspective\"><string name=\"focal_length\" value=\"28mm\"/></sensor>", 28}};
  for (int k = 0; k < 2; k++) {
    char xml[512];
    snprintf(xml, sizeof xml, "<scene version=\"3.0.0\">%s<shape type=\"sphere\"/><emitter type=\"constant\"/></scene>", cases[k].sensor);
    scene *s;
    valo_options f;
    valo_options_init(&f);
    valo_error err;
    CHECK(scene_load(scratch_file("focal.xml", xml), NULL, &s, &f, &err) == VALO_OK, "%s", err.message);
    /* Mitsuba's default film is 768 x 576: the diagonal's half-angle tangent times 3/5. */
    double want = 360 / M_PI * atan(sqrt(36.0 * 36 + 24 * 24) / (2 * cases[k].diag_mm) * 0.6);
    CHECK(fabs(s->cam.fov_deg - want) < 1e-3, "focal length %g mm: vertical fov %g, not %g", cases[k].diag_mm, (double)s->cam.fov_deg, want);
    scene_free(s);
  }
  const char *both = "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/>"
                     "<string name=\"focal_length\" value=\"35mm\"/></sensor><shape type=\"sphere\"/></scene>";
  valo_scene *sc;
  valo_error err;
  CHECK(valo_scene_load(scratch_file("both.xml", both), &sc, &err) != VALO_OK && strstr(err.message, "fov or focal_length"), "fov and focal_length accepted");
  return 0;
}

static int unit_shapes(void) {
  static const char *const fmt =
      "<scene version=\"3.0.0\">\n<sensor type=\"%s\"><float name=\"fov\" value=\"60\"/>\n"
      "<transform name=\"to_world\"><lookat origin=\"0, 0, %s\" target=\"0, 0, 0\"/></transform>\n"
      "<sampler type=\"independent\"><integer name=\"sample_count\" value=\"16\"/></sampler>\n"
      "<film type=\"hdrfilm\"><integer name=\"width\" value=\"64\"/><integer name=\"height\" value=\"64\"/><rfilter type=\"box\"/></film></sensor>\n"
      "<shape type=\"%s\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"2\"/></emitter>%s</shape>\n</scene>\n";
  struct { const char *shape, *z, *extra; double expect; } t[] = {
      {"rectangle", "0.5", "", 2},   /* the film sees [-0.29, 0.29]^2 of the rectangle */
      {"rectangle", "-0.5", "", 0},  /* behind it */
      {"cube", "0.2", "<transform name=\"to_world\"><scale value=\"0.1\"/></transform>", 2}, /* outside, facing out */
      {"disk", "2", "", 2 * 3 * M_PI / 16},
  };
  for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
    char xml[2048];
    snprintf(xml, sizeof xml, fmt, "perspective", t[k].z, t[k].shape, t[k].extra);
    int w, h;
    float *px = render_path(scratch_file("unit.xml", xml), &w, &h);
    CHECK(px, "render");
    double s = 0;
    for (int i = 0; i < 3 * w * h; i++) s += px[i];
    s /= 3.0 * w * h;
    free(px);
    fprintf(stderr, "%s seen from z = %s: mean %.4f, expected %.4f\n", t[k].shape, t[k].z, s, t[k].expect);
    CHECK(fabs(s - t[k].expect) < 0.01 * fmax(t[k].expect, 1) , "%s: mean %.4f, expected %.4f", t[k].shape, s, t[k].expect);
  }
  return 0;
}

/* The Mitsuba scene file at path, loaded (not committed); NULL, the reason printed, when
 * it does not load. */
static scene *mitsuba_scene(const char *path) {
  scene *s = scene_new(path);
  valo_error err;
  valo_options set;
  valo_options_init(&set);
  if (load_mitsuba(s, path, NULL, &set, &err) == VALO_OK) return s;
  fprintf(stderr, "%s\n", err.message);
  scene_free(s);
  return NULL;
}

/* A mesh's v as Mitsuba reads it: an OBJ's turned over (flip_tex_coords, default true),
 * which is valo's own reading; a PLY's as it stands, running down the image, so valo turns
 * it up; an OBJ with flip_tex_coords false likewise. Checked at the quads' corner (-1, -1),
 * whose file v is 0 (Mitsuba 3.9.1's vertex_texcoords_buffer: 1 for the OBJ, 0 for the PLY). */
static int mesh_v_as_mitsuba(void) {
  const char *quad_v = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  const char *quad_p = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\n"
                       "property float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                       "-1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n3 0 1 2\n3 0 2 3\n";
  scratch_file("quad-uv.obj", quad_v);
  scratch_file("quad-uv.ply", quad_p);
  const char *obj = "quad-uv.obj", *ply = "quad-uv.ply"; /* beside the scene file */
  char xml[2048];
  snprintf(xml, sizeof xml,
           "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n"
           "<shape type=\"ply\"><string name=\"filename\" value=\"%s\"/></shape>\n"
           "<shape type=\"obj\"><string name=\"filename\" value=\"%s\"/><transform name=\"to_world\"><translate x=\"10\"/></transform></shape>\n"
           "<shape type=\"obj\"><string name=\"filename\" value=\"%s\"/><boolean name=\"flip_tex_coords\" value=\"false\"/>"
           "<transform name=\"to_world\"><translate x=\"20\"/></transform></shape>\n</scene>\n",
           ply, obj, obj);
  const char *path = scratch_file("mesh-uv.xml", xml);
  scene *s = mitsuba_scene(path);
  CHECK(s, "the scene does not load");
  const float want[3] = {1, 0, 1}; /* valo's v at the corner: the PLY, the OBJ, the OBJ not flipped */
  int found[3] = {0, 0, 0};
  for (uint32_t v = 0; v < s->nverts; v++) {
    vec3 p = s->pos[v];
    if (p.y != -1) continue;
    for (int k = 0; k < 3; k++)
      if (p.x == -1 + 10 * k) {
        CHECK(s->uv[2 * v + 1] == want[k], "shape %d: v %g at its corner, Mitsuba's is %g", k, s->uv[2 * v + 1], want[k]);
        found[k]++;
      }
  }
  scene_free(s);
  CHECK(found[0] && found[1] && found[2], "corners found: %d %d %d", found[0], found[1], found[2]);
  return 0;
}

/* A file written on one line (as programs write them): each anonymous BSDF and each
 * emitter stays its own material (they were named by line alone, and the second of a line
 * took the first's: a green sphere rendered red, a lamp at the first's radiance). */
static int one_line_materials(void) {
  const char *xml = "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>"
                    "<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.9 0 0\"/></bsdf></shape>"
                    "<shape type=\"sphere\"><point name=\"center\" value=\"3 0 0\"/><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0 0.9 0\"/></bsdf></shape>"
                    "<shape type=\"sphere\"><point name=\"center\" value=\"6 0 0\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>"
                    "<shape type=\"sphere\"><point name=\"center\" value=\"9 0 0\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"5\"/></emitter></shape>"
                    "</scene>\n";
  const char *path = scratch_file("one-line.xml", xml);
  scene *s = mitsuba_scene(path);
  CHECK(s, "the scene does not load");
  const uint32_t first[4] = {0, 5120, 10240, 15360};
  CHECK(s->ntris == 4 * 5120, "%u triangles", s->ntris);
  const material *m[4];
  for (int k = 0; k < 4; k++) m[k] = &s->mats[s->tri_mat[first[k]]];
  CHECK(m[0]->kd.r > 0.8f && m[0]->kd.g == 0, "the first sphere is (%g %g %g), not red", m[0]->kd.r, m[0]->kd.g, m[0]->kd.b);
  CHECK(m[1]->kd.g > 0.8f && m[1]->kd.r == 0, "the second sphere is (%g %g %g), not green", m[1]->kd.r, m[1]->kd.g, m[1]->kd.b);
  CHECK(m[2]->emission.g == 1 && m[3]->emission.g == 5, "the lamps glow %g and %g, not 1 and 5", m[2]->emission.g, m[3]->emission.g);
  scene_free(s);
  return 0;
}

/* Spectra listed per wavelength (value="400:0.2, 500:0.8, ..." and a filename of "nm value"
 * lines) read as Mitsuba 3.9.1's RGB modes read them (its own values, printed by
 * mi.traverse of the same BSDFs and emitters in scalar_rgb): a reflectance under D65 and
 * white near 1, an emitter's over the equal-energy spectrum, 0 outside the listed range;
 * within 1.5 % (valo's CIE curves are a fitted approximation). Valo's conductor-table
 * projection (white-balanced per channel, ends held) was 15 % off in red. */
static int spectrum_lists(void) {
  CHECK(scratch_file("refl.spd", "# a measured reflectance\n400 0.2\n500 0.8  # green\n600 0.4\n700 0.1\n"), "write");
  char xml[2048];
  snprintf(xml, sizeof xml,
           "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n"
           "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0.2, 500:0.8, 600:0.4, 700:0.1\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" filename=\"refl.spd\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:1, 700:1\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><emitter type=\"area\"><spectrum name=\"radiance\" value=\"400:2.0, 500:0.5, 600:1.0, 700:3\"/></emitter></shape>\n"
           "<shape type=\"rectangle\"><emitter type=\"area\"><spectrum name=\"radiance\" value=\"400:1, 700:1\"/></emitter></shape>\n</scene>\n");
  scene *s = mitsuba_scene(scratch_file("spectra.xml", xml));
  CHECK(s, "the scene does not load");
  static const double want[5][3] = {{0.22197, 0.66492, 0.51509}, {0.22197, 0.66492, 0.51509}, {0.995342, 0.999756, 0.994909},
                                    {1.84581, 0.575462, 1.143}, {1.19969, 0.94952, 0.903443}};
  for (int k = 0; k < 5; k++) {
    const material *m = &s->mats[s->tri_mat[2 * k]];
    rgb got = k < 3 ? m->kd : m->emission;
    const float g[3] = {got.r, got.g, got.b};
    for (int i = 0; i < 3; i++)
      CHECK(fabs(g[i] / want[k][i] - 1) < 0.015, "shape %d channel %d: %g, Mitsuba %g", k, i, g[i], want[k][i]);
  }
  scene_free(s);
  return 0;
}

/* Which Mitsuba BSDFs are black from behind (valo's black_back), as Mitsuba 3.9.1 renders a
 * quad seen from behind under a constant sky: diffuse, conductors, plastics, principled
 * without transmission and a shape's default BSDF are; dielectrics, principled with
 * spec_trans, and whatever a twosided holds are not. A BSDF with an id used alone and in a
 * twosided of two is two materials; a blend's components each keep their own. */
static int black_backs(void) {
  const char *xml = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n"
                    "<bsdf type=\"diffuse\" id=\"w\"/>\n"
                    "<shape type=\"rectangle\"><ref id=\"w\"/></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"roughconductor\"/></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"conductor\"/></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"roughplastic\"/></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"principled\"/></shape>\n"
                    "<shape type=\"rectangle\"/>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"dielectric\"/></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"principled\"><float name=\"spec_trans\" value=\"0.5\"/></bsdf></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"twosided\"><bsdf type=\"roughplastic\"/></bsdf></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"twosided\"><ref id=\"w\"/><bsdf type=\"conductor\"/></bsdf></shape>\n"
                    "<shape type=\"rectangle\"><bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.5\"/><ref id=\"w\"/><bsdf type=\"dielectric\"/>"
                    "</bsdf></shape>\n</scene>\n";
  scene *s = mitsuba_scene(scratch_file("backs.xml", xml));
  CHECK(s, "the scene does not load");
  CHECK(s->ntris == 22, "%u triangles", s->ntris);
  static const int want[9] = {1, 1, 1, 1, 1, 1, 0, 0, 0};
  for (int k = 0; k < 9; k++) {
    const material *m = &s->mats[s->tri_mat[2 * k]];
    CHECK(m->black_back == want[k], "shape %d (%s): black_back %d", k, m->name, m->black_back);
  }
  const material *sided = &s->mats[s->tri_mat[18]], *blend = &s->mats[s->tri_mat[20]];
  CHECK(sided->type == MAT_BLEND && sided->blend_by_side, "the twosided of two is not a sided material");
  for (int k = 0; k < 2; k++)
    CHECK(!s->mats[sided->blend[k]].black_back, "the twosided's %s (%s) is black from behind", k ? "back" : "front", s->mats[sided->blend[k]].name);
  CHECK(blend->type == MAT_BLEND && !blend->blend_by_side && !blend->black_back, "the blend");
  CHECK(s->mats[blend->blend[0]].black_back && !s->mats[blend->blend[1]].black_back, "the blend's diffuse %d, dielectric %d",
        s->mats[blend->blend[0]].black_back, s->mats[blend->blend[1]].black_back);
  scene_free(s);
  return 0;
}

/* A bitmap given for a number (a mask's opacity, a rough conductor's alpha, a blend's
 * weight) is read as Mitsuba's eval_1 reads it: its luminance, alpha ignored. A red
 * pixel is 0.212671 (Mitsuba 3.9.1 gives 0.2126710 for the same file), a white pixel of
 * alpha 0 is opaque; the same red file as a colour stays red. */
static int scalar_bitmaps(void) {
  unsigned char red[3] = {255, 0, 0}, clear[4] = {255, 255, 255, 0};
  char rp[1200], cp[1200], xml[3000];
  snprintf(rp, sizeof rp, "%s/red1.png", scratch_dir());
  snprintf(cp, sizeof cp, "%s/clear1.png", scratch_dir());
  CHECK(stbi_write_png(rp, 1, 1, 3, red, 3) && stbi_write_png(cp, 1, 1, 4, clear, 4), "write");
  snprintf(xml, sizeof xml,
           "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n"
           "<shape type=\"rectangle\"><bsdf type=\"mask\"><texture type=\"bitmap\" name=\"opacity\"><string name=\"filename\" value=\"%s\"/></texture>"
           "<bsdf type=\"diffuse\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"roughconductor\"><texture type=\"bitmap\" name=\"alpha\"><string name=\"filename\" value=\"%s\"/>"
           "</texture></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"blendbsdf\"><texture type=\"bitmap\" name=\"weight\"><string name=\"filename\" value=\"%s\"/>"
           "</texture><bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"%s\"/>"
           "</texture></bsdf></shape>\n</scene>\n",
           "clear1.png", "red1.png", "red1.png", "red1.png"); /* beside the scene file */
  scene *s = mitsuba_scene(scratch_file("scalar-bitmaps.xml", xml));
  CHECK(s, "the scene does not load");
  const material *mask = &s->mats[s->tri_mat[0]], *rough = &s->mats[s->tri_mat[2]], *blend = &s->mats[s->tri_mat[4]], *colour = &s->mats[s->tri_mat[6]];
  CHECK(mask->tex_alpha >= 0 && !mask->alpha_channel && s->tex[mask->tex_alpha].px[0] == 1, "the mask's white pixel of alpha 0 is not opaque");
  CHECK(rough->tex_rough >= 0 && fabsf(s->tex[rough->tex_rough].px[0] - 0.212671f) < 1e-6f, "the red alpha map reads %g", s->tex[rough->tex_rough].px[0]);
  CHECK(blend->type == MAT_BLEND && blend->tex_weight >= 0 && fabsf(s->tex[blend->tex_weight].px[0] - 0.212671f) < 1e-6f, "the red weight map");
  CHECK(colour->tex_kd >= 0 && s->tex[colour->tex_kd].px[0] == 1 && s->tex[colour->tex_kd].px[1] == 0, "the colour map is not red");
  scene_free(s);
  return 0;
}

/* Mitsuba's mask as valo's stochastic opacity: the default 0.5, a number times the default
 * (a mask inside a mask), and a bitmap
 * decoded from sRGB unless raw (the ramp's texel 32 holds 130: 0.510 raw, 0.223 decoded). */
static int mask_opacity(void) {
  char xml[2048];
  const char *ramp = VALO_SOURCE_DIR "/tests/data/mitsuba-xml/opacity-ramp.png";
  snprintf(xml, sizeof xml,
           "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n"
           "<shape type=\"rectangle\"><bsdf type=\"mask\"><bsdf type=\"diffuse\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"mask\"><float name=\"opacity\" value=\"0.5\"/><bsdf type=\"mask\">"
           "<bsdf type=\"diffuse\"/></bsdf></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"mask\"><texture type=\"bitmap\" name=\"opacity\"><string name=\"filename\" value=\"%s\"/>"
           "<boolean name=\"raw\" value=\"true\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>\n"
           "<shape type=\"rectangle\"><bsdf type=\"mask\"><texture type=\"bitmap\" name=\"opacity\"><string name=\"filename\" value=\"%s\"/>"
           "</texture><bsdf type=\"diffuse\"/></bsdf></shape>\n</scene>\n",
           ramp, ramp);
  const char *path = scratch_file("mask-opacity.xml", xml);
  scene *s = mitsuba_scene(path);
  CHECK(s, "the scene does not load");
  CHECK(s->ntris == 8, "%u triangles", s->ntris);
  const material *m[4];
  for (int k = 0; k < 4; k++) m[k] = &s->mats[s->tri_mat[2 * k]];
  CHECK(m[0]->opacity == 0.5f && m[0]->tex_alpha < 0, "default mask: opacity %g, map %d", m[0]->opacity, m[0]->tex_alpha);
  CHECK(m[1]->opacity == 0.25f && m[1]->tex_alpha < 0, "mask of 0.5 around the default: opacity %g, map %d", m[1]->opacity, m[1]->tex_alpha);
  for (int k = 2; k < 4; k++) {
    CHECK(m[k]->opacity == 1 && m[k]->tex_alpha >= 0 && m[k]->alpha_stochastic, "bitmap mask %d: opacity %g, map %d, stochastic %d", k,
          m[k]->opacity, m[k]->tex_alpha, m[k]->alpha_stochastic);
    float x = s->tex[m[k]->tex_alpha].px[4 * 32], want = k == 2 ? 130 / 255.0f : 0.2232f;
    CHECK(fabsf(x - want) < 1e-3f, "bitmap mask %s: texel 32 reads %g, not %g", k == 2 ? "raw" : "decoded", x, want);
  }
  valo_error err;
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  for (uint32_t t = 0; t < 8; t++) CHECK(s->tri_flags[t] & TRI_ALPHA, "triangle %u is not alpha-tested", t);
  scene_free(s);
  return 0;
}

/* valo convert (valo_scene_convert): the JSON written for an XML scene, in another folder,
 * renders bit for bit as the XML does, its texture and mesh found through absolute names;
 * what is not a Mitsuba scene or not a .json output is refused. */
static int convert_to_json(void) {
  const char *xml_path = VALO_SOURCE_DIR "/tests/data/materials/textured-quad.xml";
  char out[1200];
  snprintf(out, sizeof out, "%s/converted.json", scratch_dir());
  valo_error err;
  CHECK(valo_scene_convert(xml_path, NULL, out, &err) == VALO_OK, "%s", err.message);
  char *text = read_text_file(out);
  CHECK(text && strstr(text, "\"" VALO_SOURCE_DIR), "file names are not absolute: %s", text ? text : "(no file)");
  free(text);
  int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
  /* 64 spp: the file asks for 16 384, and bit-for-bit equality holds at any count */
  float *a = render_path_spp(xml_path, 64, &w1, &h1), *b = render_path_spp(out, 64, &w2, &h2);
  CHECK(a && b && w1 == w2 && h1 == h2, "render");
  CHECK(!memcmp(a, b, (size_t)w1 * h1 * 3 * sizeof(float)), "the converted JSON renders differently from the XML");
  free(a); free(b);
  /* the defines reach the translation; refusals */
  valo_load_options lo;
  valo_load_options_init(&lo);
  snprintf(lo.defines, sizeof lo.defines, "spp=7");
  CHECK(valo_scene_convert(scratch_file("conv.xml", XML_SCENE), &lo, out, &err) == VALO_OK, "%s", err.message);
  text = read_text_file(out);
  CHECK(text && strstr(text, "\"spp\":\t7"), "--define did not reach the JSON");
  free(text);
  /* the path-guiding lab's integrator (and 0.6's guided_path) is valo's guided, its depths read */
  static const char *const guided_types[2] = {"path_guiding_integrator", "guided_path"};
  for (int g = 0; g < 2; g++) {
    char *gx = malloc(strlen(XML_SCENE) + 64), *at = strstr(XML_SCENE, "<integrator type=\"path\">");
    CHECK(gx && at, "the scene's integrator");
    snprintf(gx, strlen(XML_SCENE) + 64, "%.*s<integrator type=\"%s\">%s", (int)(at - XML_SCENE), XML_SCENE, guided_types[g],
             at + strlen("<integrator type=\"path\">"));
    CHECK(valo_scene_convert(scratch_file("guided.xml", gx), NULL, out, &err) == VALO_OK, "%s", err.message);
    free(gx);
    text = read_text_file(out);
    CHECK(text && strstr(text, "\"integrator\":\t\"guided\"") && strstr(text, "\"max_depth\":\t4"), "%s not read as guided: %s",
          guided_types[g], text ? text : "(no file)");
    free(text);
  }
  CHECK(valo_scene_convert(scratch_file("s.json", "{}"), NULL, out, &err) != VALO_OK && strstr(err.message, "Mitsuba scene files"), "%s", err.message);
  CHECK(valo_scene_convert(scratch_file("c2.xml", XML_SCENE), NULL, scratch_path("x.png"), &err) != VALO_OK && strstr(err.message, ".json"), "%s",
        err.message);
  return 0;
}

/* <include>: XML_SCENE cut into five files (a scene root's children spliced in, a
 * single <bsdf> root, one in a subfolder including another, one written in Mitsuba 0.6's
 * names) renders bit for bit as the whole; unnamed BSDFs on the same line of two files
 * are two materials; a missing file, a file that includes itself and
 * an error inside an included file are said with the file and line they are in. */
static int includes(void) {
  char *whole = strdup(XML_SCENE), *main_xml = malloc(strlen(XML_SCENE) + 400);
  CHECK(whole && main_xml, "memory");
  /* the pieces: from the first <bsdf> to the first <shape>, the shapes, the emitters */
  char *b0 = strstr(whole, "  <bsdf type=\"twosided\""), *b1 = strstr(whole, "  <bsdf type=\"roughconductor\""),
       *s0 = strstr(whole, "  <shape type=\"rectangle\""), *s3 = strstr(whole, "  <shape type=\"disk\""),
       *e0 = strstr(whole, "  <emitter type=\"point\"");
  CHECK(b0 && b1 && s0 && s3 && e0, "XML_SCENE's layout");
  char dir[1100];
  snprintf(dir, sizeof dir, "%s/inc", scratch_dir());
  mkdir(dir, 0755);
  char buf[4096];
  snprintf(buf, sizeof buf, "<scene version=\"3.0.0\">\n%.*s</scene>\n", (int)(b1 - b0), b0);
  scratch_file("inc-white.xml", buf);
  /* the metal in 0.6's names, as a lone <bsdf> root */
  snprintf(buf, sizeof buf, "<bsdf version=\"0.6.0\" type=\"roughconductor\" id=\"metal\"><float name=\"alpha\" value=\"0.09\"/>"
                            "<rgb name=\"eta\" value=\"0.2 0.9 1.1\"/>\n<rgb name=\"k\" value=\"3.9, 2.4, 2.1\"/>"
                            "<rgb name=\"specularReflectance\" value=\"0.8, 0.8, 0.8\"/></bsdf>\n");
  scratch_file("inc-metal.xml", buf);
  snprintf(buf, sizeof buf, "<scene version=\"3.0.0\">\n%.*s  <include filename=\"inc-lamp.xml\"/>\n</scene>\n", (int)(s3 - s0), s0);
  scratch_file("inc/shapes.xml", buf);
  snprintf(buf, sizeof buf, "%.*s", (int)(e0 - s3), s3);
  scratch_file("inc-lamp.xml", buf);
  snprintf(main_xml, strlen(XML_SCENE) + 400, "%.*s  <include filename=\"inc-white.xml\"/>\n  <include filename=\"inc-metal.xml\"/>\n"
           "  <include filename=\"inc/shapes.xml\"/>\n%s", (int)(b0 - whole), whole, e0);
  int w1, h1, w2, h2;
  warnings_capture(1);
  float *a = render_path(scratch_file("inc-main.xml", main_xml), &w1, &h1);
  int warned = warnings_text()[0] != 0;
  warnings_capture(0);
  float *b = render_path(scratch_file("inc-whole.xml", XML_SCENE), &w2, &h2);
  CHECK(a && b, "render");
  CHECK(!warned, "warnings (printed above)");
  CHECK(w1 == w2 && h1 == h2 && !memcmp(a, b, (size_t)w1 * h1 * 3 * sizeof(float)), "the included pieces render differently from the whole");
  free(a); free(b);
  /* and the test can tell: the metal without its 0.6 name upgraded is warned about */
  snprintf(buf, sizeof buf, "<bsdf type=\"roughconductor\" id=\"metal\"><rgb name=\"specularReflectance\" value=\"0.8\"/></bsdf>\n");
  scratch_file("inc-metal.xml", buf);
  char said[2048];
  valo_error err;
  valo_scene *sc;
  CHECK(load_saying(scratch_file("inc-main.xml", main_xml), said, sizeof said, &err) == VALO_OK, "%s", err.message);
  CHECK(strstr(said, "inc-metal.xml:1: <rgb name=\"specularReflectance\">: not read"), "said: %s", said);
  static const struct { const char *inc, *text, *want[2]; } bad[] = {
      {"inc-none.xml", NULL, {"inc-none.xml", "(the <include> at "}},
      {"inc-self.xml", "<scene version=\"3.0.0\">\n<include filename=\"inc-self.xml\"/>\n</scene>\n", {"inc-self.xml:2: <include>", "more than 15 deep"}},
      {"inc-bad.xml", "<scene version=\"3.0.0\">\n\n<shape/>\n</scene>\n", {"inc-bad.xml:3: <shape>", "needs a type"}},
      {"inc-broken.xml", "<scene version=\"3.0.0\">\n<shape>\n</scene>\n", {"inc-broken.xml:3:", "(the <include> at "}},
  };
  /* Unnamed BSDFs on the same line of two files are two materials. */
  scratch_file("inc-green.xml", "<scene version=\"3.0.0\">\n<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.1 0.7 0.1\"/></bsdf></shape>\n</scene>\n");
  const char *two = scratch_file("inc-two.xml", "<scene version=\"3.0.0\">\n<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.7 0.1 0.1\"/></bsdf></shape>\n"
                                                "<sensor type=\"perspective\"/><include filename=\"inc-green.xml\"/>\n</scene>\n");
  char out[1200];
  snprintf(out, sizeof out, "%s/inc-two.json", scratch_dir());
  CHECK(mitsuba_to_json(two, NULL, out, &err) == VALO_OK, "%s", err.message);
  FILE *f = fopen(out, "rb");
  CHECK(f, "%s", out);
  size_t got = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[got] = 0;
  CHECK(strstr(buf, "\"bsdf@line2:22\"") && strstr(buf, "\"bsdf@inc-green.xml:line2:22\"") && strstr(buf, "0.7, 0.1, 0.1") && strstr(buf, "0.1, 0.7, 0.1"),
        "both files' line-2 BSDFs should be materials: %s", buf);
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    if (bad[i].text) scratch_file(bad[i].inc, bad[i].text);
    snprintf(buf, sizeof buf, "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<include filename=\"%s\"/>\n</scene>\n", bad[i].inc);
    CHECK(valo_scene_load(scratch_file("inc-top.xml", buf), &sc, &err) != VALO_OK, "%s: loaded", bad[i].inc);
    CHECK(strstr(err.message, bad[i].want[0]) && strstr(err.message, bad[i].want[1]), "%s: said: %s", bad[i].inc, err.message);
  }
  free(whole); free(main_xml);
  return 0;
}

/* <path>: the folders it names are where later relative file names are looked for, the
 * last first, before the main file's folder (as Mitsuba 3.9.1 finds them: of three tri.obj,
 * beside the scene, in the first and in the second <path> folder, it loads the second's).
 * A scene whose mesh, texture and <include> are found on two <path>s renders bit for bit
 * as the scene naming them with their folders; without the <path>s it draws the other
 * triangle beside the scene. A missing folder, a file, and a <path> inside a shape are
 * refused with their line. */
static int search_paths(void) {
  char dir[1100];
  const char *sub[] = {"sp", "sp/meshes", "sp/parts"};
  for (int i = 0; i < 3; i++) {
    snprintf(dir, sizeof dir, "%s/%s", scratch_dir(), sub[i]);
    mkdir(dir, 0755);
  }
  scratch_file("sp/tri.obj", "v -1 0 0\nv 1 0 0\nv 0 1.5 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nf 1/1 2/2 3/3\n");
  scratch_file("sp/meshes/tri.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nf 1/1 2/2 3/3\n");
  scratch_file("sp/parts/tri.obj", "v -1.5 -1 0\nv 1.5 -1 0\nv 0 0.5 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nf 1/1 2/2 3/3\n");
  scratch_file("sp/parts/lamp.xml", "<scene version=\"3.0.0\"><emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.9\"/></emitter></scene>\n");
  unsigned char tex[4 * 3] = {250, 20, 20, 20, 250, 20, 20, 20, 250, 240, 240, 240};
  char tp[1200];
  snprintf(tp, sizeof tp, "%s/sp/meshes/quad.png", scratch_dir());
  CHECK(stbi_write_png(tp, 2, 2, 3, tex, 6), "write %s", tp);
  static const char *fmt =
      "<scene version=\"3.0.0\">\n%s"
      "  <sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/>\n"
      "    <transform name=\"to_world\"><lookat origin=\"0, 0, 3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>\n"
      "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"4\"/></sampler>\n"
      "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"32\"/><integer name=\"height\" value=\"32\"/></film></sensor>\n"
      "  <include filename=\"%s\"/>\n"
      "  <shape type=\"obj\"><string name=\"filename\" value=\"%s\"/>\n"
      "    <bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"%s\"/></texture></bsdf></shape>\n"
      "</scene>\n";
  char xml[2048];
  snprintf(xml, sizeof xml, fmt, "  <path value=\"meshes\"/>\n  <path value=\"parts\"/>\n", "lamp.xml", "tri.obj", "quad.png");
  int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
  warnings_capture(1);
  float *a = render_path(scratch_file("sp/paths.xml", xml), &w1, &h1);
  int warned = warnings_text()[0] != 0;
  warnings_capture(0);
  snprintf(xml, sizeof xml, fmt, "", "parts/lamp.xml", "parts/tri.obj", "meshes/quad.png");
  float *b = render_path(scratch_file("sp/named.xml", xml), &w2, &h2);
  CHECK(a && b && !warned, "render (warnings printed above)");
  CHECK(w1 == w2 && h1 == h2 && !memcmp(a, b, (size_t)w1 * h1 * 3 * sizeof(float)), "the <path> scene renders differently from the named one");
  /* the test can tell: beside the scene is another triangle */
  snprintf(xml, sizeof xml, fmt, "", "parts/lamp.xml", "tri.obj", "meshes/quad.png");
  free(b);
  b = render_path(scratch_file("sp/beside.xml", xml), &w2, &h2);
  CHECK(b && memcmp(a, b, (size_t)w1 * h1 * 3 * sizeof(float)), "the triangle beside the scene renders as the <path> one");
  free(a); free(b);
  static const struct { const char *body, *want[2]; } bad[] = {
      {"<path value=\"nowhere\"/>", {"sp/bad.xml:2: <path>", "nowhere is not a folder"}},
      {"<path value=\"tri.obj\"/>", {"sp/bad.xml:2: <path>", "tri.obj is not a folder"}},
      {"<path/>", {"sp/bad.xml:2: <path>", "needs a value"}},
      {"<shape type=\"sphere\">\n<path value=\"meshes\"/></shape>", {"sp/bad.xml:3: <path>", "must be a child of <scene>"}},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    snprintf(xml, sizeof xml, "<scene version=\"3.0.0\">\n%s\n<sensor type=\"perspective\"/>\n</scene>\n", bad[i].body);
    valo_scene *sc;
    valo_error err;
    CHECK(valo_scene_load(scratch_file("sp/bad.xml", xml), &sc, &err) != VALO_OK, "%s: loaded", bad[i].body);
    CHECK(strstr(err.message, bad[i].want[0]) && strstr(err.message, bad[i].want[1]), "%s: said: %s", bad[i].body, err.message);
  }
  return 0;
}

/* Mitsuba's reconstruction filters read as valo's: box, tent (radius), gaussian (stddev s
 * as radius 4s), mitchell (B = C = 1/3; B = 0, C = 1/2 is Catmull-Rom), catmullrom, lanczos
 * (radius = lobes); other B and C are warned about; a filter valo lacks is warned about
 * and Mitsuba's default Gaussian used. */
static int rfilters(void) {
  static const struct { const char *rf, *name; double radius; int warns; } cases[] = {
      {"<rfilter type=\"box\"/>", "box", 0.5, 0},
      {"<rfilter type=\"tent\"><float name=\"radius\" value=\"1.5\"/></rfilter>", "tent", 1.5, 0},
      {"<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>", "gaussian", 1, 0},
      {"<rfilter type=\"mitchell\"/>", "mitchell", 2, 0},
      {"<rfilter type=\"mitchell\"><float name=\"B\" value=\"0\"/><float name=\"C\" value=\"0.5\"/></rfilter>", "catmull-rom", 2, 0},
      {"<rfilter type=\"mitchell\"><float name=\"B\" value=\"0.5\"/></rfilter>", "mitchell", 2, 1},
      {"<rfilter type=\"catmullrom\"/>", "catmull-rom", 2, 0},
      {"<rfilter type=\"lanczos\"/>", "lanczos", 3, 0},
      {"<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter>", "lanczos", 2, 0},
      {"<rfilter type=\"unknown\"/>", "gaussian", 2, 1},
      {"", "gaussian", 2, 0},
  };
  char xml[1024], out[1200], want[128];
  snprintf(out, sizeof out, "%s/rf.json", scratch_dir());
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    snprintf(xml, sizeof xml, "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/>"
             "<integer name=\"height\" value=\"8\"/>%s</film></sensor>\n</scene>\n", cases[i].rf);
    valo_error err;
    warnings_capture(1);
    valo_status st = valo_scene_convert(scratch_file("rf.xml", xml), NULL, out, &err);
    int warned = warnings_text()[0] != 0;
    warnings_capture(0);
    CHECK(st == VALO_OK, "%s: %s", cases[i].rf, err.message);
    CHECK(warned == cases[i].warns, "%s: %s", cases[i].rf, warned ? "warned" : "no warning");
    char *text = read_text_file(out);
    snprintf(want, sizeof want, "\"filter\":\t\"%s\",\n\t\t\"splat\":\ttrue,\n\t\t\"filter_radius\":\t%g\n", cases[i].name, cases[i].radius);
    CHECK(text && strstr(text, want), "%s: the film is not %s of radius %g: %s", cases[i].rf, cases[i].name, cases[i].radius, text ? text : "");
    free(text);
  }
  return 0;
}

/* Instancing: a shapegroup of a mesh, a cube and a sphere placed by three instances
 * renders as the nine shapes written out with the instances' to_world after their own;
 * a property the group's shapes do not read is warned about once, not per instance;
 * emitters and groups inside a group, an instance without its group or of something
 * else are refused with their line. */
static int instances(void) {
  scratch_file("tri.obj", "v -0.5 0 0\nv 0.5 0 0\nv 0 0.8 0.1\nf 1 2 3\n");
  const char *head = "<scene version=\"3.0.0\">\n"
                     "  <sensor type=\"perspective\"><float name=\"fov\" value=\"50\"/>\n"
                     "    <transform name=\"to_world\"><lookat origin=\"0, 3, 7\" target=\"0, 0.5, 0\" up=\"0, 1, 0\"/></transform>\n"
                     "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"4\"/></sampler>\n"
                     "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"48\"/><integer name=\"height\" value=\"32\"/></film></sensor>\n"
                     "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.8\"/></emitter>\n"
                     "  <shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"5\"/><rotate x=\"1\" angle=\"-90\"/></transform></shape>\n";
  static const char *const own[3] = {"<translate x=\"-0.6\"/>", "<scale value=\"0.3\"/><translate x=\"0.6\" y=\"0.3\"/>", ""};
  static const char *const place[3] = {"<rotate y=\"1\" angle=\"30\"/><translate x=\"-2\"/>", "<scale value=\"1.5\"/>",
                                       "<rotate y=\"1\" angle=\"-70\"/><translate x=\"2\" z=\"-1\"/>"};
  static const char *const body[3] = {"<shape type=\"obj\"><string name=\"filename\" value=\"tri.obj\"/><float name=\"unread\" value=\"1\"/>%s</shape>",
                                      "<shape type=\"cube\">%s<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.8 0.2 0.1\"/></bsdf></shape>",
                                      "<shape type=\"sphere\"><point name=\"center\" x=\"0\" y=\"1.2\" z=\"0\"/><float name=\"radius\" value=\"0.3\"/>%s</shape>"};
  char *a = malloc(16384), *b = malloc(16384), piece[1024], xf[512];
  CHECK(a && b, "memory");
  snprintf(a, 16384, "%s  <shape type=\"shapegroup\" id=\"g\">\n", head);
  snprintf(b, 16384, "%s", head);
  for (int s = 0; s < 3; s++) {
    snprintf(xf, sizeof xf, s == 2 ? "%s" : "<transform name=\"to_world\">%s</transform>", own[s]);
    snprintf(piece, sizeof piece, body[s], xf);
    strcat(a, "    "); strcat(a, piece); strcat(a, "\n");
  }
  strcat(a, "  </shape>\n");
  for (int i = 0; i < 3; i++) {
    snprintf(piece, sizeof piece, "  <shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\">%s</transform></shape>\n", place[i]);
    strcat(a, piece);
    for (int s = 0; s < 3; s++) {
      snprintf(xf, sizeof xf, "<transform name=\"to_world\">%s%s</transform>", own[s], place[i]);
      snprintf(piece, sizeof piece, body[s], xf);
      strcat(b, "  "); strcat(b, piece); strcat(b, "\n");
    }
  }
  strcat(a, "</scene>\n");
  strcat(b, "</scene>\n");
  int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
  warnings_capture(1);
  float *ia = render_path(scratch_file("inst.xml", a), &w1, &h1);
  char said[4096];
  snprintf(said, sizeof said, "%s", warnings_text());
  warnings_capture(0);
  float *ib = render_path(scratch_file("inst-out.xml", b), &w2, &h2);
  CHECK(ia && ib && w1 == w2 && h1 == h2, "render");
  double far, mean;
  differ(ia, ib, w1 * h1, &far, &mean);
  fprintf(stderr, "instances against the shapes written out: %.2f%% of pixel channels differ by more than 1e-4, means by %.2e\n", 100 * far, mean);
  CHECK(far < 0.02 && mean < 1e-4, "the instances render differently from the shapes they place");
  const char *w = strstr(said, "<float name=\"unread\">");
  CHECK(w && !strstr(w + 1, "<float name=\"unread\">"), "the group's unread property should be warned about once: %s", said);
  /* the test can tell: the instances without their to_world */
  char *c = strdup(a), *at;
  while ((at = strstr(c, "<shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\">"))) memcpy(at + 36 + 17, "nothing_", 8);
  warnings_capture(1);
  float *ic = render_path(scratch_file("inst-c.xml", c), &w2, &h2);
  warnings_capture(0);
  CHECK(ic, "render");
  differ(ic, ib, w1 * h1, &far, &mean);
  CHECK(far > 0.05, "instances without their to_world rendered alike (%.2f%% of channels differ)", 100 * far);
  free(ia); free(ib); free(ic); free(c);
  static const struct { const char *group, *use, *want[2]; } bad[] = {
      {"<shape type=\"sphere\"><emitter type=\"area\"/></shape>", "<shape type=\"instance\"><ref id=\"g\"/></shape>", {"bad-inst.xml:4: <shape type=\"sphere\">", "emitting"}},
      {"<shape type=\"shapegroup\" id=\"h\"/>", "", {"bad-inst.xml:4: <shape type=\"shapegroup\" id=\"h\">", "cannot hold groups"}},
      {"<shape type=\"sphere\"/>", "<shape type=\"instance\"/>", {"bad-inst.xml:6: <shape type=\"instance\">", "needs a <ref"}},
      {"<shape type=\"sphere\"/>", "<bsdf type=\"diffuse\" id=\"d\"/><shape type=\"instance\"><ref id=\"d\"/></shape>", {"bad-inst.xml:6: <ref id=\"d\">", "shapegroup"}},
      {"<emitter type=\"point\"/>", "", {"bad-inst.xml:4: <emitter type=\"point\">", "holds shapes"}},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    snprintf(a, 16384, "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<shape type=\"shapegroup\" id=\"g\">\n%s\n</shape>\n%s\n</scene>\n", bad[i].group, bad[i].use);
    valo_scene *sc;
    valo_error err;
    CHECK(valo_scene_load(scratch_file("bad-inst.xml", a), &sc, &err) != VALO_OK, "case %zu loaded", i);
    CHECK(strstr(err.message, bad[i].want[0]) && strstr(err.message, bad[i].want[1]), "case %zu said: %s", i, err.message);
  }
  free(a); free(b);
  return 0;
}

/* An emitting Mitsuba sphere gives off Mitsuba's power: valo's 5 120 triangles scaled
 * about its centre to the exact sphere's area (unscaled, as a sphere that does not emit
 * keeps them, 0.12 % short), and its radius for the cone light sampling draws from is its
 * vertices', so that the cone holds every facet. */
static int emitting_sphere_power(void) {
  for (int glow = 0; glow < 2; glow++) {
    char xml[400];
    snprintf(xml, sizeof xml, "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>\n<shape type=\"sphere\"><float name=\"radius\" value=\"2\"/>%s</shape>\n"
             "<emitter type=\"constant\"/></scene>\n", glow ? "<emitter type=\"area\"/>" : "");
    scene *s = mitsuba_scene(scratch_file("glow.xml", xml));
    CHECK(s, "load");
    double area = 0, far = 0;
    for (uint32_t t = 0; t < s->ntris; t++) {
      const uint32_t *ix = &s->idx[3 * t];
      area += 0.5 * v3_len(v3_cross(v3_sub(s->pos[ix[1]], s->pos[ix[0]]), v3_sub(s->pos[ix[2]], s->pos[ix[0]])));
      for (int k = 0; k < 3; k++) far = fmax(far, v3_len(s->pos[ix[k]]));
    }
    double rel = area / (16 * M_PI) - 1, r = s->nspheres == 1 ? s->spheres[0].r : 0;
    fprintf(stderr, "%s sphere: %u triangles, area %.4f%% off the exact sphere's, vertices at %.6f, radius %.6f\n", glow ? "an emitting" : "a",
            s->ntris, 100 * rel, far, r);
    uint32_t n = s->ntris;
    scene_free(s);
    CHECK(n == 5120 && fabs(r / far - 1) < 1e-6, "%u triangles, radius %g, vertices at %g", n, r, far);
    if (glow) CHECK(fabs(rel) < 1e-5, "area off by %.4f%%", 100 * rel);
    else CHECK(rel < -1e-3, "area off by %.4f%%", 100 * rel);
  }
  return 0;
}

/* Text of n repeats of fmt (one %d: the repeat's number) between head and tail; malloc'd. */
static char *repeated(const char *head, const char *fmt, int n, const char *tail) {
  size_t cap = strlen(head) + strlen(tail) + (size_t)n * (strlen(fmt) + 24) + 1, len = 0;
  char *t = malloc(cap);
  if (!t) return NULL;
  len += (size_t)snprintf(t, cap, "%s", head);
  for (int i = 0; i < n; i++) len += (size_t)snprintf(t + len, cap - len, fmt, i, i + 1, i + 1);
  snprintf(t + len, cap - len, "%s", tail);
  return t;
}

/* Mitsuba files that recurse or expand: each refused at once naming its file, line and
 * bound (a self-referring BSDF once overflowed the stack; a 4 096-fold include of a 1 MB
 * part, or $name substitution to 6 GB, ran for minutes or out of memory), and large flat
 * files read in time linear in their size (200 000 elements, 30 000 shapes naming 30 000
 * BSDFs: once quadratic, 15 minutes and 12 s). The case's ctest time limit (60 s, under
 * ASan too) is what a quadratic reader would cross. */
static int expansion_bounds(void) {
  static const char *SCENE = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n";
  static const struct { const char *file, *body, *want[2]; } bad[] = {
      {"self.xml", "<bsdf type=\"twosided\" id=\"a\"><ref id=\"a\"/></bsdf>\n<shape type=\"sphere\"><ref id=\"a\"/></shape>\n",
       {"self.xml:3: <bsdf type=\"twosided\" id=\"a\">", "a cycle (a -> a)"}},
      {"mask.xml", "<bsdf type=\"mask\" id=\"m\"><float name=\"opacity\" value=\"0.5\"/><ref id=\"m\"/></bsdf>\n<shape type=\"sphere\"><ref id=\"m\"/></shape>\n",
       {"mask.xml:3:", "a cycle (m -> m)"}},
      {"mutual.xml", "<bsdf type=\"twosided\" id=\"a\"><ref id=\"b\"/></bsdf>\n<bsdf type=\"bumpmap\" id=\"b\"><texture type=\"bitmap\" name=\"arbitrary\">"
                     "<string name=\"filename\" value=\"none.png\"/></texture><ref id=\"a\"/></bsdf>\n<shape type=\"sphere\"><ref id=\"a\"/></shape>\n",
       {"mutual.xml:3:", "a cycle (a -> b -> a)"}},
  };
  valo_error err;
  valo_scene *sc;
  char buf[2048];
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    snprintf(buf, sizeof buf, "%s%s</scene>\n", SCENE, bad[i].body);
    CHECK(valo_scene_load(scratch_file(bad[i].file, buf), &sc, &err) != VALO_OK, "%s loaded", bad[i].file);
    CHECK(strstr(err.message, bad[i].want[0]) && strstr(err.message, bad[i].want[1]), "%s said: %s", bad[i].file, err.message);
  }
  /* a chain of 40 000 BSDFs, each wrapping the next; a chain of 30 each holding the next twice (2^30) */
  char *t = repeated(SCENE, "<bsdf type=\"twosided\" id=\"b%d\"><ref id=\"b%d\"/></bsdf>\n", 40000,
                     "<bsdf type=\"diffuse\" id=\"b40000\"/>\n<shape type=\"sphere\"><ref id=\"b0\"/></shape>\n</scene>\n");
  CHECK(t && valo_scene_load(scratch_file("chain.xml", t), &sc, &err) != VALO_OK, "the chain loaded");
  CHECK(strstr(err.message, "chain.xml:35:") && strstr(err.message, "nested more than 32 deep"), "said: %s", err.message);
  free(t);
  t = repeated(SCENE, "<bsdf type=\"twosided\" id=\"b%d\"><ref id=\"b%d\"/><ref id=\"b%d\"/></bsdf>\n", 30,
               "<bsdf type=\"diffuse\" id=\"b30\"/>\n<shape type=\"sphere\"><ref id=\"b0\"/></shape>\n</scene>\n");
  CHECK(t && valo_scene_load(scratch_file("doubling.xml", t), &sc, &err) != VALO_OK, "the doubling chain loaded");
  CHECK(strstr(err.message, "doubling.xml:") && strstr(err.message, "more than 200000 translations"), "said: %s", err.message);
  free(t);
  /* a 1 MB part included 4 096 times */
  size_t part_len = (1u << 20) + 64;
  char *part = malloc(part_len);
  CHECK(part, "memory");
  int k = snprintf(part, part_len, "<scene version=\"3.0.0\">\n<!-- ");
  memset(part + k, 'x', (1u << 20));
  snprintf(part + k + (1u << 20), part_len - (size_t)k - (1u << 20), " -->\n</scene>\n");
  scratch_file("part.xml", part);
  free(part);
  t = repeated(SCENE, "<include filename=\"part.xml\"/>\n", 4096, "<shape type=\"sphere\"/>\n</scene>\n");
  CHECK(t && valo_scene_load(scratch_file("includes.xml", t), &sc, &err) != VALO_OK, "4096 includes of 1 MB loaded");
  CHECK(strstr(err.message, "includes.xml:66: <include>") && strstr(err.message, "more than 64 MiB in all"), "said: %s", err.message);
  free(t);
  /* 12 000 attributes of $a x 8 over a 65 KB default */
  char *dflt = malloc(65200);
  CHECK(dflt, "memory");
  k = snprintf(dflt, 65200, "<scene version=\"3.0.0\">\n<default name=\"a\" value=\"");
  memset(dflt + k, '1', 65000);
  snprintf(dflt + k + 65000, 65200 - (size_t)k - 65000, "\"/>\n<sensor type=\"perspective\"/>\n<shape type=\"sphere\">\n");
  t = repeated(dflt, "<string name=\"s%d\" value=\"$a$a$a$a$a$a$a$a\"/>\n", 12000, "</shape>\n</scene>\n");
  free(dflt);
  CHECK(t && valo_scene_load(scratch_file("subst.xml", t), &sc, &err) != VALO_OK, "6 GB of substitution loaded");
  CHECK(strstr(err.message, "subst.xml:37: <string name=\"s32\">") && strstr(err.message, "more than 16 MiB of attribute text in all"), "said: %s", err.message);
  free(t);
  /* large flat files load: 200 000 elements (7 MB), and 30 000 shapes naming 30 000 BSDFs */
  t = repeated(SCENE, "<bsdf type=\"diffuse\" id=\"unused%d\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf>\n", 100000,
               "<shape type=\"sphere\"/><emitter type=\"constant\"/>\n</scene>\n");
  CHECK(t && strlen(t) > (6u << 20), "the flat file");
  CHECK(valo_scene_load(scratch_file("flat.xml", t), &sc, &err) == VALO_OK, "%s", err.message);
  valo_scene_destroy(sc);
  free(t);
  char *shapes = repeated("", "<shape type=\"rectangle\"><ref id=\"m%d\"/></shape>\n", 30000, "<emitter type=\"constant\"/>\n</scene>\n");
  t = shapes ? repeated(SCENE, "<bsdf type=\"diffuse\" id=\"m%d\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf>\n", 30000, shapes) : NULL;
  CHECK(t, "memory");
  CHECK(valo_scene_load(scratch_file("named.xml", t), &sc, &err) == VALO_OK, "%s", err.message);
  valo_scene_destroy(sc);
  free(t); free(shapes);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"parser", parser}, {"xml_equals_json", xml_equals_json}, {"mitsuba_06_names", mitsuba_06_names},
                                    {"defaults_and_defines", defaults_and_defines}, {"unread_is_said", unread_is_said},
                                    {"unit_shapes", unit_shapes}, {"focal_length", focal_length}, {"convert_to_json", convert_to_json}, {"includes", includes}, {"search_paths", search_paths}, {"rfilters", rfilters}, {"instances", instances}, {"mesh_v_as_mitsuba", mesh_v_as_mitsuba}, {"mask_opacity", mask_opacity}, {"scalar_bitmaps", scalar_bitmaps}, {"black_backs", black_backs}, {"spectrum_lists", spectrum_lists}, {"one_line_materials", one_line_materials}, {"expansion_bounds", expansion_bounds}, {"emitting_sphere_power", emitting_sphere_power}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
