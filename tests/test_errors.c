/* test_errors.c — bad input gives a clear message naming the file and the problem and a
 * non-zero exit, never a crash or a hang (run under ASan+UBSan in CI). Each case runs the
 * real `valo` binary with a 60 s watchdog and checks the exit code and stderr. Also the
 * command line's own behaviour: --help, --version, usage errors. */
#include "harness.h"
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef VALO_EXE
#define VALO_EXE "valo"
#endif

static char g_out[65536];

/* Runs valo with args (NULL-terminated); returns the exit code (128+sig if killed), and
 * the combined stdout+stderr in g_out. */
static int run_valo_int(const char *const *args, int sigint_ms);
static int run_valo(const char *const *args) { return run_valo_int(args, 0); }
/* The same, sending SIGINT (as Ctrl-C does) after sigint_ms milliseconds when > 0. */
static int run_valo_int(const char *const *args, int sigint_ms) {
  char log[1200];
  snprintf(log, sizeof log, "%s/out.txt", scratch_dir());
  pid_t pid = fork();
  if (pid == 0) {
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1); dup2(fd, 2);
    close(fd);
    const char *argv[32];
    int n = 0;
    argv[n++] = VALO_EXE;
    for (int i = 0; args[i] && n < 31; i++) argv[n++] = args[i];
    argv[n] = NULL;
    execv(VALO_EXE, (char *const *)argv);
    _exit(127);
  }
  int status = 0;
  time_t t0 = time(NULL);
  if (sigint_ms > 0) {
    struct timespec d = {sigint_ms / 1000, (long)(sigint_ms % 1000) * 1000000L};
    nanosleep(&d, NULL);
    kill(pid, SIGINT);
  }
  for (;;) {
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (time(NULL) - t0 > 60) { kill(pid, SIGKILL); waitpid(pid, &status, 0); fprintf(stderr, "valo hung: killed\n"); return 999; }
    struct timespec ts = {0, 20000000};
    nanosleep(&ts, NULL);
  }
  FILE *f = fopen(log, "rb");
  size_t len = f ? fread(g_out, 1, sizeof g_out - 1, f) : 0;
  if (f) fclose(f);
  g_out[len] = 0;
  fprintf(stderr, "valo said: %s", g_out);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WEXITSTATUS(status);
}

#define EXPECT_FAIL(code, ...)                                                                          \
  do {                                                                                                  \
    const char *const a_[] = {__VA_ARGS__, NULL};                                                       \
    int rc_ = run_valo(a_);                                                                             \
    CHECK(rc_ == (code), "exit code %d, expected %d", rc_, code);                                       \
  } while (0)
#define SAID(text) CHECK(strstr(g_out, text) != NULL, "message lacks \"%s\"", text)
#define NOT_SAID(text) CHECK(strstr(g_out, text) == NULL, "message has \"%s\"", text)
#define NO_SANITIZER() NOT_SAID("Sanitizer")

static const char *write_file(const char *name, const char *text) { return scratch_file(name, text); }

static const char *CUBE_OBJ =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";

static int missing_file(void) {
  EXPECT_FAIL(1, "render", "no/such/scene.json");
  SAID("no/such/scene.json"); SAID("cannot open"); NO_SANITIZER();
  EXPECT_FAIL(1, "render", "no/such/mesh.obj");
  SAID("no/such/mesh.obj"); NO_SANITIZER();
  /* A JSON scene naming a missing mesh names the mesh. */
  const char *p = write_file("missing_mesh.json", "{ \"shapes\": [ {\"file\": \"nothere.obj\"} ] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("nothere.obj"); NO_SANITIZER();
  return 0;
}

static int malformed_json(void) {
  const char *p = write_file("bad.json", "{\n  \"camera\": {\n    \"fov\": 40,,\n  }\n}\n");
  EXPECT_FAIL(1, "render", p);
  SAID("bad.json:3:"); SAID("syntax"); NO_SANITIZER();
  p = write_file("empty.json", "");
  EXPECT_FAIL(1, "render", p);
  SAID("empty.json"); NO_SANITIZER();
  p = write_file("trailing.json", "{ \"film\": {\"width\": 8} } extra");
  EXPECT_FAIL(1, "render", p);
  SAID("trailing.json:1:"); NO_SANITIZER();
  return 0;
}

static int unknown_key(void) {
  const char *p = write_file("unknown.json", "{ \"camera\": {\"fovy\": 40} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("unknown.json"); SAID("unknown key \"fovy\""); SAID("camera"); NO_SANITIZER();
  p = write_file("unknown_top.json", "{ \"lightz\": [] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("unknown key \"lightz\""); NO_SANITIZER();
  return 0;
}

static int wrong_type(void) {
  const char *p = write_file("type.json", "{ \"film\": {\"width\": \"big\"} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("type.json"); SAID("film.width"); SAID("must be a number"); NO_SANITIZER();
  p = write_file("type2.json", "{ \"camera\": {\"position\": [0, 1]} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("camera.position"); SAID("3 numbers"); NO_SANITIZER();
  p = write_file("type3.json", "{ \"materials\": {\"m\": {\"type\": \"velvet\"}} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("materials.m"); SAID("unknown material type"); NO_SANITIZER();
  p = write_file("type5.json", "{ \"camera\": {\"from_file\": true, \"position\": [0,0,1]} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("type5.json"); SAID("from_file"); NO_SANITIZER();
  p = write_file("type6.json", "{ \"camera\": {\"from_file\": true}, \"shapes\": [{\"type\": \"sphere\"}] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("type6.json"); SAID("no shape file has a camera"); NO_SANITIZER();
  p = write_file("type7.json", "{ \"environment\": {\"type\": \"cube\", \"faces\": [\"a.png\", \"b.png\"]} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("type7.json"); SAID("environment.faces"); SAID("six"); NO_SANITIZER();
  p = write_file("type8.json", "{ \"environment\": {\"type\": \"cube\", \"faces\": [\"n1.png\", \"n2.png\", \"n3.png\", \"n4.png\", \"n5.png\", \"n6.png\"]} }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("n1.png"); NO_SANITIZER();
  p = write_file("type4.json", "{ \"shapes\": [{\"type\": \"sphere\", \"material\": \"nope\"}] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("shapes[0]"); SAID("\"nope\""); NO_SANITIZER();
  return 0;
}

static int unsupported_format(void) {
  const char *p = write_file("garbage.xyz1", "this is not a mesh\n\x01\x02\x03");
  EXPECT_FAIL(1, "render", p);
  SAID("garbage.xyz1"); NO_SANITIZER();
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  EXPECT_FAIL(2, "render", obj, "-o", "out.bmp");
  SAID("out.bmp"); SAID("format"); NO_SANITIZER();
  return 0;
}

static int index_out_of_range(void) {
  const char *p = write_file("badindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("badindex.obj"); NO_SANITIZER();
  return 0;
}

/* PLY: an out-of-range face index, and triangle strips (which Assimp would misread as one
 * polygon without complaint). */
static int bad_ply(void) {
  const char *p = write_file("badidx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("badidx.ply"); SAID("out of range"); NO_SANITIZER();
  p = write_file("strip.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                              "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 2 3\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("strip.ply"); SAID("strips"); NO_SANITIZER();
  return 0;
}

static int nan_vertices(void) {
  const char *p = write_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("nan.obj"); SAID("not finite"); NO_SANITIZER();
  p = write_file("inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("inf.obj"); SAID("not finite"); NO_SANITIZER();
  return 0;
}

static int degenerate_triangles(void) {
  /* Only degenerate triangles: an error. */
  const char *p = write_file("degen.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\n");
  EXPECT_FAIL(1, "render", p, "-o", "x.png");
  SAID("degen.obj"); SAID("degenerate"); NO_SANITIZER();
  /* Some degenerate triangles among good ones: skipped with a warning naming the file. */
  char out[1200];
  snprintf(out, sizeof out, "%s/partial.png", scratch_dir());
  p = write_file("partial.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 2 0\nf 1 2 3\nf 1 3 4\n");
  EXPECT_FAIL(0, "render", p, "-o", out, "--res", "8x8", "--spp", "1");
  SAID("partial.obj"); SAID("skipped 1 degenerate"); NO_SANITIZER();
  return 0;
}

static int absurd_resolution(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  EXPECT_FAIL(2, "render", obj, "--res", "100000x100000");
  SAID("--res"); NO_SANITIZER();
  EXPECT_FAIL(2, "render", obj, "--res", "0x5");
  EXPECT_FAIL(2, "render", obj, "--res", "abc");
  const char *p = write_file("bigfilm.json", "{ \"film\": {\"width\": 1000000000, \"height\": 10}, \"shapes\": [{\"type\": \"sphere\"}] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("bigfilm.json"); SAID("film.width"); SAID("out of range"); NO_SANITIZER();
  return 0;
}

static int absurd_sample_count(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  EXPECT_FAIL(2, "render", obj, "--spp", "0");
  SAID("--spp"); NO_SANITIZER();
  EXPECT_FAIL(2, "render", obj, "--spp", "99999999999");
  EXPECT_FAIL(2, "render", obj, "--spp", "-3");
  const char *p = write_file("spp.json", "{ \"render\": {\"spp\": -5}, \"shapes\": [{\"type\": \"sphere\"}] }\n");
  EXPECT_FAIL(1, "render", p);
  SAID("render.spp"); NO_SANITIZER();
  /* In range per option but absurd together. */
  EXPECT_FAIL(1, "render", obj, "--res", "16384x16384", "--spp", "1048576");
  SAID("samples"); NO_SANITIZER();
  return 0;
}

static int bad_options(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  EXPECT_FAIL(1, "render", obj, "--integrator", "magic", "--res", "4x4");
  SAID("unknown integrator \"magic\""); SAID("path");
  EXPECT_FAIL(2, "render", obj, "--accel", "bvh9");
  EXPECT_FAIL(2, "render", obj, "--frobnicate");
  SAID("unknown option");
  EXPECT_FAIL(2, "render");
  SAID("no scene");
  EXPECT_FAIL(2, "render", obj, "--spp");
  SAID("needs a value");
  EXPECT_FAIL(2, "render", obj, "--aperture", "-1");
  SAID("--aperture");
  EXPECT_FAIL(2, "render", obj, "--focus", "0");
  SAID("--focus");
  EXPECT_FAIL(2, "dance");
  { const char *const none[] = {NULL}; CHECK(run_valo(none) == 2, "no arguments should be a usage error"); }
  return 0;
}

static int help_and_version(void) {
  EXPECT_FAIL(0, "--help");
  SAID("valo render SCENE");
  EXPECT_FAIL(0, "render", "--help");
  SAID("--spp"); SAID("--time"); SAID("--threads"); SAID("--seed"); SAID("--res"); SAID("--integrator"); SAID("--accel");
  EXPECT_FAIL(0, "--version");
  SAID("valo 0.");
  return 0;
}

static int unwritable_output(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  EXPECT_FAIL(1, "render", obj, "--res", "4x4", "--spp", "1", "-o", "/no/such/dir/out.png");
  SAID("/no/such/dir/out.png"); NO_SANITIZER();
  return 0;
}

/* A successful render exits 0, writes every -o, prints the summary. */
static int render_ok(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  char a[1200], b[1200], c[1200];
  snprintf(a, sizeof a, "%s/a.png", scratch_dir());
  snprintf(b, sizeof b, "%s/a.exr", scratch_dir());
  snprintf(c, sizeof c, "%s/a.pfm", scratch_dir());
  EXPECT_FAIL(0, "render", obj, "--res", "16x12", "--spp", "2", "--threads", "2", "-o", a, "-o", b, "-o", c);
  SAID("summary"); SAID("Mrays/s"); SAID("triangles"); NO_SANITIZER();
  CHECK(access(a, R_OK) == 0 && access(b, R_OK) == 0 && access(c, R_OK) == 0, "outputs missing");
  /* --time: a time budget ends the render. */
  EXPECT_FAIL(0, "render", obj, "--res", "16x12", "--time", "0.5", "-o", a);
  SAID("summary");
  return 0;
}

/* Ctrl-C (a real SIGINT) stops the render, writes every -o with the finished passes, says
 * how many spp they hold and exits 130 (issue 8.2). */
static int sigint_writes_image(void) {
  const char *obj = write_file("ok.obj", CUBE_OBJ);
  char a[1200], b[1200];
  snprintf(a, sizeof a, "%s/int.png", scratch_dir());
  snprintf(b, sizeof b, "%s/int.exr", scratch_dir());
  const char *const args[] = {"render", obj, "--res", "64x64", "--spp", "1000000", "-o", a, "-o", b, NULL};
  int rc = run_valo_int(args, 1500);
  CHECK(rc == 130, "exit code %d, expected 130", rc);
  SAID("interrupted after"); SAID("spp"); SAID("wrote"); NOT_SAID("no image written"); NO_SANITIZER();
  CHECK(access(a, R_OK) == 0 && access(b, R_OK) == 0, "outputs missing after Ctrl-C");
  const char *p = strstr(g_out, "interrupted after ");
  int spp = p ? atoi(p + strlen("interrupted after ")) : 0;
  CHECK(spp > 0, "reported %d spp", spp);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"missing_file", missing_file},
                                    {"malformed_json", malformed_json},
                                    {"unknown_key", unknown_key},
                                    {"wrong_type", wrong_type},
                                    {"unsupported_format", unsupported_format},
                                    {"index_out_of_range", index_out_of_range},
                                    {"nan_vertices", nan_vertices},
                                    {"bad_ply", bad_ply},
                                    {"degenerate_triangles", degenerate_triangles},
                                    {"absurd_resolution", absurd_resolution},
                                    {"absurd_sample_count", absurd_sample_count},
                                    {"bad_options", bad_options},
                                    {"help_and_version", help_and_version},
                                    {"unwritable_output", unwritable_output},
                                    {"render_ok", render_ok},
                                    {"sigint_writes_image", sigint_writes_image},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
