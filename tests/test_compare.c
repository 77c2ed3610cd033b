/* test_compare.c — `valo compare` as a user runs it: the report's figures (summary.json and
 * the page's table) equal the relMSE and bias recomputed here from the EXRs it wrote,
 * against the reference it names (the longest render, or a given file); every file the
 * page shows is there; the page loads nothing from elsewhere; wrong input is refused;
 * Ctrl-C stops it with exit 130 and no report; and
 * headless Chromium renders the page (a screenshot, and its DOM's figures equal the
 * EXRs'). Chromium missing: that case skips, and fails under CI=true. */
#include "harness.h"
#include "image/image_io.h"
#include <cjson/cJSON.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_out[65536];


static const char *in_dir(const char *dir, const char *name) {
  static char b[4][1400];
  static int k;
  char *p = b[k++ & 3];
  snprintf(p, sizeof b[0], "%s/%s", dir, name);
  return p;
}

static double relmse(const image *a, const image *r, double *bias) {
  double e = 0, sa = 0, sr = 0;
  size_t n = (size_t)a->w * a->h * 3;
  for (size_t i = 0; i < n; i++) {
    double d = (double)a->rgb[i] - r->rgb[i];
    e += d * d / ((double)r->rgb[i] * r->rgb[i] + 0.01);
    sa += a->rgb[i];
    sr += r->rgb[i];
  }
  *bias = (sa - sr) / sr;
  return e / (double)n;
}

static int close_to(double a, double b) { return fabs(a - b) <= 1e-6 * fabs(b) + 1e-12; }

/* Checks dir's report: each integrator's relMSE and bias in summary.json equal those of its
 * EXR against ref (an EXR path), the page shows them and every image it names exists. */
static int check_report(const char *dir, const char *ref_path, int expect_runs) {
  char *js = read_text_file(in_dir(dir, "summary.json")), *html = read_text_file(in_dir(dir, "index.html"));
  CHECK(js && html, "summary.json or index.html missing in %s", dir);
  cJSON *root = cJSON_Parse(js);
  CHECK(root != NULL, "summary.json is not JSON");
  const cJSON *runs = cJSON_GetObjectItem(root, "integrators");
  CHECK(cJSON_GetArraySize(runs) == expect_runs, "%d integrators in the summary, expected %d", cJSON_GetArraySize(runs), expect_runs);
  image ref;
  CHECK(image_read(ref_path, &ref, NULL) == 0, "cannot read the reference %s", ref_path);
  const cJSON *u;
  cJSON_ArrayForEach(u, runs) {
    const char *name = cJSON_GetObjectItem(u, "name")->valuestring, *img = cJSON_GetObjectItem(u, "image")->valuestring;
    image im;
    CHECK(image_read(in_dir(dir, img), &im, NULL) == 0, "%s: its image %s cannot be read", name, img);
    CHECK(im.w == ref.w && im.h == ref.h, "%s: %dx%d against a %dx%d reference", name, im.w, im.h, ref.w, ref.h);
    double bias, e = relmse(&im, &ref, &bias);
    double je = cJSON_GetObjectItem(u, "relmse")->valuedouble, jb = cJSON_GetObjectItem(u, "mean_bias")->valuedouble;
    CHECK(close_to(je, e), "%s: summary relMSE %.9g, from the EXRs %.9g", name, je, e);
    CHECK(close_to(jb, bias) || fabs(jb - bias) < 1e-7, "%s: summary bias %.9g, from the EXRs %.9g", name, jb, bias);
    char cell[128];
    snprintf(cell, sizeof cell, "<td class=\"relmse\">%.6g</td>", e);
    CHECK(strstr(html, cell) != NULL, "%s: the page lacks %s", name, cell);
    const cJSON *curve = cJSON_GetObjectItem(u, "curve");
    CHECK(cJSON_GetArraySize(curve) >= 1, "%s: no moments for the plot", name);
    const cJSON *last = cJSON_GetArrayItem(curve, cJSON_GetArraySize(curve) - 1);
    CHECK(close_to(cJSON_GetObjectItem(last, "relmse")->valuedouble, e), "%s: the plot's last point is not the final relMSE", name);
    const char *files[] = {".png", "_error.png", "_crop.png"};
    for (int k = 0; k < 3; k++) {
      char f[128];
      snprintf(f, sizeof f, "%s%s", name, files[k]);
      CHECK(access(in_dir(dir, f), R_OK) == 0, "%s is missing", f);
      char src[160];
      snprintf(src, sizeof src, "src=\"%s\"", f);
      CHECK(strstr(html, src) != NULL, "the page does not show %s", f);
    }
    image_free(&im);
  }
  image_free(&ref);
  CHECK(strstr(html, "<svg") && strstr(html, "class=\"curve\""), "no SVG plot with curves");
  CHECK(!strstr(html, "<script") && !strstr(html, "https://") && !strstr(html, "src=\"http"), "the page loads something");
  cJSON_Delete(root);
  free(js);
  free(html);
  return 0;
}

static const char *scene(void) { return VALO_SOURCE_DIR "/scenes/default.json"; }

#define RUN(code, ...)                                                      \
  do {                                                                      \
    const char *const a_[] = {__VA_ARGS__, NULL};                           \
    int rc_ = run_cli(a_, 0, 600, g_out, sizeof g_out);                     \
    CHECK(rc_ == (code), "exit code %d, expected %d", rc_, (code));         \
  } while (0)

/* Without a reference: the longest render is it (named in the summary and the page). */
static int longest_is_reference(void) {
  char dir[1200];
  snprintf(dir, sizeof dir, "%s/report", scratch_dir());
  RUN(0, "compare", scene(), "--integrators", "path,vpl", "--spp", "6", "--res", "64x48", "-o", dir);
  char *js = read_text_file(in_dir(dir, "summary.json"));
  CHECK(js != NULL, "no summary");
  cJSON *root = cJSON_Parse(js);
  const char *ref = cJSON_GetObjectItem(root, "reference")->valuestring;
  CHECK(cJSON_IsTrue(cJSON_GetObjectItem(root, "reference_is_a_render")), "the summary does not say the reference is a render");
  /* the longest */
  double best = -1;
  const char *longest = NULL;
  const cJSON *u;
  cJSON_ArrayForEach(u, cJSON_GetObjectItem(root, "integrators")) {
    double s = cJSON_GetObjectItem(u, "seconds")->valuedouble;
    if (s > best) { best = s; longest = cJSON_GetObjectItem(u, "name")->valuestring; }
  }
  CHECK(longest && !strcmp(ref, longest), "reference %s, the longest render is %s", ref, longest);
  char exr[64];
  snprintf(exr, sizeof exr, "%s.exr", ref);
  int r = check_report(dir, in_dir(dir, exr), 2);
  char *html = read_text_file(in_dir(dir, "index.html"));
  CHECK(html && strstr(html, "no reference was given"), "the page does not say there was no reference");
  free(html);
  cJSON_Delete(root);
  free(js);
  return r;
}

/* With a reference file, at equal time; wrong input refused. */
static int reference_and_refusals(void) {
  char dir[1200], ref[1200];
  snprintf(dir, sizeof dir, "%s/report2", scratch_dir());
  snprintf(ref, sizeof ref, "%s/ref.exr", scratch_dir());
  RUN(0, "render", scene(), "--spp", "64", "--res", "64x48", "-q", "-o", ref);
  RUN(0, "compare", scene(), "--integrators", "path,photon", "--time", "0.6", "--res", "64x48", "--reference", ref, "-o", dir);
  if (check_report(dir, ref, 2)) return 1;
  char *js = read_text_file(in_dir(dir, "summary.json"));
  CHECK(js && strstr(js, "\"reference_is_a_render\": false"), "the summary does not name the file as the reference");
  free(js);
  RUN(1, "compare", scene(), "--integrators", "path", "--spp", "2", "--res", "32x32", "--reference", ref, "-o", dir);
  CHECK(strstr(g_out, "64x48") && strstr(g_out, "32x32"), "the size refusal does not give both sizes");
  RUN(2, "compare", scene(), "--integrators", "path,nope", "--spp", "2", "-o", dir);
  CHECK(strstr(g_out, "\"nope\""), "the unknown integrator is not named");
  RUN(2, "compare", scene(), "--integrators", "path", "-o", dir);
  CHECK(strstr(g_out, "--time") && strstr(g_out, "--spp"), "the missing budget is not said");
  RUN(2, "compare", scene(), "--spp", "2", "-o", dir);
  RUN(2, "compare", scene(), "--integrators", "path", "--spp", "2", "--crop", "1,2,3", "-o", dir);
  /* Ctrl-C: exit 130, no report */
  char dir4[1200];
  snprintf(dir4, sizeof dir4, "%s/report4", scratch_dir());
  const char *const ia[] = {"compare", scene(), "--integrators", "path,vpl", "--time", "30", "--res", "64x48", "-o", dir4, NULL};
  int irc = run_cli(ia, 1500, 120, g_out, sizeof g_out);
  CHECK(irc == 130, "Ctrl-C: exit %d, expected 130", irc);
  CHECK(access(in_dir(dir4, "index.html"), F_OK) != 0, "an interrupted comparison wrote a report");
  RUN(0, "compare", "--help");
  CHECK(strstr(g_out, "--integrators") && strstr(g_out, "--reference"), "compare --help lacks its options");
  return 0;
}

/* Headless Chromium renders the page: a screenshot of it, and the figures in its DOM
 * (after the browser parsed it) are those of the EXRs. */
static int chromium_page(void) {
  int ci = getenv("CI") && !strcmp(getenv("CI"), "true");
  if (system("command -v chromium > /dev/null 2>&1") != 0) {
    fprintf(stderr, "chromium is not installed: %s\n", ci ? "failing under CI=true" : "skipped");
    return ci ? 1 : TEST_SKIP;
  }
  char dir[1200], abs[1200];
  CHECK(realpath(scratch_dir(), abs) != NULL, "no scratch folder");
  snprintf(dir, sizeof dir, "%s/report3", abs); /* file:// wants an absolute path */
  RUN(0, "compare", scene(), "--integrators", "path,vpl", "--spp", "4", "--res", "64x48", "-o", dir);
  char cmd[4400];
  snprintf(cmd, sizeof cmd,
           "cd %s && timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir=%s/chr --window-size=1200,1600 "
           "--screenshot=%s/shot.png file://%s/index.html > /dev/null 2>&1 && "
           "timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir=%s/chr --dump-dom file://%s/index.html > %s/dom.html 2>/dev/null",
           dir, dir, dir, dir, dir, dir, dir);
  CHECK(system(cmd) == 0, "chromium failed: %s", cmd);
  struct stat st;
  CHECK(stat(in_dir(dir, "shot.png"), &st) == 0 && st.st_size > 5000, "no screenshot (or an empty one)");
  int w = 0, h = 0;
  FILE *f = fopen(in_dir(dir, "shot.png"), "rb");
  unsigned char hd[24];
  CHECK(f && fread(hd, 1, 24, f) == 24, "cannot read the screenshot");
  fclose(f);
  w = (hd[16] << 24) | (hd[17] << 16) | (hd[18] << 8) | hd[19];
  h = (hd[20] << 24) | (hd[21] << 16) | (hd[22] << 8) | hd[23];
  CHECK(!memcmp(hd + 1, "PNG", 3) && w == 1200 && h == 1600, "the screenshot is %dx%d, expected 1200x1600", w, h);
  /* the browser's DOM holds the summary's figures, which check_report ties to the EXRs */
  char *dom = read_text_file(in_dir(dir, "dom.html"));
  char *js = read_text_file(in_dir(dir, "summary.json"));
  CHECK(dom && js && strstr(dom, "<svg"), "the DOM has no SVG");
  cJSON *root = cJSON_Parse(js);
  const char *ref = cJSON_GetObjectItem(root, "reference")->valuestring;
  char exr[64];
  snprintf(exr, sizeof exr, "%s.exr", ref);
  if (check_report(dir, in_dir(dir, exr), 2)) return 1;
  const cJSON *u;
  cJSON_ArrayForEach(u, cJSON_GetObjectItem(root, "integrators")) {
    char cell[128];
    snprintf(cell, sizeof cell, "<td class=\"relmse\">%.6g</td>", cJSON_GetObjectItem(u, "relmse")->valuedouble);
    CHECK(strstr(dom, cell) != NULL, "the rendered page lacks %s", cell);
  }
  cJSON_Delete(root);
  free(dom);
  free(js);
  fprintf(stderr, "chromium rendered the report (%s/shot.png, %dx%d) with the EXRs' figures\n", dir, w, h);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"longest_is_reference", longest_is_reference},
                                    {"reference_and_refusals", reference_and_refusals},
                                    {"chromium_page", chromium_page},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
