/* gen_manylight.c — writes the many-light scenes of docs/integrators.md (restir-di/gi):
 * OBJ+MTL files of small one-sided emissive triangles, each its own colour and power:
 * in `room` and `sponza` every one tilted and placed at its own height so no two lie in
 * one plane; in `walls`, lamps share their face's plane and none overlaps another. Deterministic
 * (a fixed splitmix64 stream); run by hand, the outputs are committed:
 *   gen_manylight room   DIR   -> DIR/manylight-room.obj/.mtl   (room, boxes, 1024 lamps)
 *   gen_manylight sponza DIR   -> DIR/sponza-lamps.obj/.mtl     (1200 lamps for Sponza's atrium)
 *   gen_manylight walls  DIR   -> DIR/manylight-walls.obj/.mtl  (1536 lamps 1/1000 of the room's
 *                                 width off its walls and ceiling, facing in; three radiance
 *                                 levels over 20x: light dominated by the nearest lamp)
 *   gen_manylight heldout DIR SEED [overlap|apart] [boxes]
 *                              -> DIR/heldout-SEED.obj/.mtl/.json: rooms of the walls room's kind
 *                                 that nothing was tuned on: the same shell, 1536 lamps on the
 *                                 ceiling, back and side walls 1/1000 of the width off them, 8
 *                                 tints drawn per seed x 3 radiance levels over 20x, placed at
 *                                 random (overlapping each other unless `apart`); the JSON puts
 *                                 the Stanford bunny (../shared) on the floor, or three boxes
 *                                 with `boxes`. Not committed (run by hand for bench_restir
 *                                 and bench_view).
 * Colours: hue uniform, saturation 0.1..0.5 (tinted whites, as real lamps; fully saturated
 * random hues put a floor under any one-sample estimator's per-channel error, see
 * docs/integrators.md); radiance log-uniform over a factor 30, so
 * that no one lamp dominates and many matter at every point. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
static uint64_t st = 0x243f6a8885a308d3ULL;
static double rnd(void) {
  uint64_t z = (st += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return (double)(z >> 11) * 0x1p-53;
}

typedef struct { double x, y, z; } v3;
static v3 mk(double x, double y, double z) { v3 v = {x, y, z}; return v; }
static v3 add(v3 a, v3 b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
static v3 scl(v3 a, double s) { return mk(a.x * s, a.y * s, a.z * s); }
static v3 crs(v3 a, v3 b) { return mk(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static v3 nrm(v3 a) { double l = sqrt(a.x * a.x + a.y * a.y + a.z * a.z); return scl(a, 1 / l); }

static int nv = 0;
static void vert(FILE *f, v3 p) { fprintf(f, "v %.6f %.6f %.6f\n", p.x, p.y, p.z); nv++; }
/* An axis-aligned box [lo, hi] (outward faces, counter-clockwise seen from outside). */
static void box(FILE *f, v3 lo, v3 hi, const char *mat) {
  fprintf(f, "usemtl %s\n", mat);
  int b = nv + 1;
  for (int i = 0; i < 8; i++) vert(f, mk(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
  static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int k = 0; k < 6; k++) fprintf(f, "f %d %d %d %d\n", b + q[k][0], b + q[k][1], b + q[k][2], b + q[k][3]);
}
/* A quad seen from the side its normal n points to. */
static void quad(FILE *f, v3 a, v3 b, v3 c, v3 d, const char *mat) {
  fprintf(f, "usemtl %s\n", mat);
  int i = nv + 1;
  vert(f, a); vert(f, b); vert(f, c); vert(f, d);
  fprintf(f, "f %d %d %d %d\n", i, i + 1, i + 2, i + 3);
}

static void hsv(double h, double s, double v, double *r, double *g, double *b) {
  double c = v * s, hp = h * 6, x = c * (1 - fabs(fmod(hp, 2) - 1)), m = v - c;
  double rr = 0, gg = 0, bb = 0;
  if (hp < 1) { rr = c; gg = x; } else if (hp < 2) { rr = x; gg = c; } else if (hp < 3) { gg = c; bb = x; }
  else if (hp < 4) { gg = x; bb = c; } else if (hp < 5) { rr = x; bb = c; } else { rr = c; bb = x; }
  *r = rr + m; *g = gg + m; *b = bb + m;
}

/* Lamp i: an equilateral triangle of edge `edge` centred at c, turned by rot about its
 * normal nn, emitting (R, G, B) on the side nn points to. */
static void lamp_points(v3 c, v3 nn, double edge, double rot, v3 p[3]) {
  v3 t = nrm(crs(nn, fabs(nn.x) < 0.9 ? mk(1, 0, 0) : mk(0, 0, 1))), u = crs(nn, t);
  double r = edge / sqrt(3.0);
  for (int k = 0; k < 3; k++) {
    double a = rot + 2 * PI * k / 3;
    p[k] = add(c, add(scl(t, r * cos(a)), scl(u, r * sin(a))));
  }
}
static void lamp(FILE *obj, FILE *mtl, int i, v3 c, v3 nn, double edge, double rot, double R, double G, double B) {
  v3 p[3];
  lamp_points(c, nn, edge, rot, p);
  fprintf(mtl, "newmtl lamp%04d\nKd 0 0 0\nKe %.4f %.4f %.4f\n\n", i, R, G, B);
  fprintf(obj, "usemtl lamp%04d\n", i);
  /* winding so that the emitting side (counter-clockwise) faces along nn */
  v3 e1 = add(p[1], scl(p[0], -1)), e2 = add(p[2], scl(p[0], -1)), g = crs(e1, e2);
  int flip = g.x * nn.x + g.y * nn.y + g.z * nn.z < 0;
  vert(obj, p[0]); vert(obj, p[flip ? 2 : 1]); vert(obj, p[flip ? 1 : 2]);
  fprintf(obj, "f %d %d %d\n", nv - 2, nv - 1, nv);
}

/* n lamps with centres drawn in [lo, hi] (rejecting those inside any of the nb boxes,
 * grown by a margin), equilateral, of edge `edge`, normal within `tilt` radians of -y. */
static void lamps(FILE *obj, FILE *mtl, int n, v3 lo, v3 hi, double edge, double tilt, double L0, const v3 *blo, const v3 *bhi, int nb) {
  for (int i = 0; i < n; i++) {
    v3 c;
    for (;;) {
      /* one draw per statement: the order of a call's arguments is unspecified, and the
       * committed scenes take z, y, x (gcc's order) */
      double uz = rnd(), uy = rnd(), ux = rnd();
      c = mk(lo.x + (hi.x - lo.x) * ux, lo.y + (hi.y - lo.y) * uy, lo.z + (hi.z - lo.z) * uz);
      int inside = 0;
      for (int k = 0; k < nb; k++)
        if (c.x > blo[k].x - edge && c.x < bhi[k].x + edge && c.y > blo[k].y - edge && c.y < bhi[k].y + edge && c.z > blo[k].z - edge &&
            c.z < bhi[k].z + edge) inside = 1;
      if (!inside) break;
    }
    double th = tilt * sqrt(rnd()), ph = 2 * PI * rnd();
    v3 nn = nrm(mk(sin(th) * cos(ph), -cos(th), sin(th) * sin(ph)));
    double rot = 2 * PI * rnd(), R, G, B;
    double sat = 0.1 + 0.4 * rnd(), hue = rnd(); /* saturation first: the same order */
    hsv(hue, sat, 1, &R, &G, &B);
    double L = L0 * exp(log(30.0) * rnd());
    lamp(obj, mtl, i, c, nn, edge, rot, R * L, G * L, B * L);
  }
}

/* Two triangles in one plane (2D points) overlap: no edge normal of either separates them. */
static int tri2_overlap(const double a[3][2], const double b[3][2]) {
  for (int s = 0; s < 2; s++) {
    const double(*t)[2] = s ? b : a;
    for (int e = 0; e < 3; e++) {
      double nx = t[(e + 1) % 3][1] - t[e][1], ny = t[e][0] - t[(e + 1) % 3][0];
      double amin = 1e30, amax = -1e30, bmin = 1e30, bmax = -1e30;
      for (int k = 0; k < 3; k++) {
        double pa = a[k][0] * nx + a[k][1] * ny, pb = b[k][0] * nx + b[k][1] * ny;
        amin = fmin(amin, pa); amax = fmax(amax, pa); bmin = fmin(bmin, pb); bmax = fmax(bmax, pb);
      }
      if (amax <= bmin || bmax <= amin) return 0;
    }
  }
  return 1;
}

/* Lamps on one face lie in one plane, so none may overlap another: where two did, which
 * one a ray sees is a tie that rounding decides, differently for a shadow ray aimed at one
 * of them and for a ray that finds whichever is nearer (estimators then disagree by the
 * share of light from overlaps). Placed by rejection: a lamp that would overlap one
 * already on its face is drawn again. */
#define WALL_LAMPS_MAX 2048
/* Lamp i's centre, normal and turn: `gap` in front of the room's ceiling (y = 2.5), back
 * (z = -2), left (x = -2) or right (x = 2) face, facing into the room, the faces drawn in
 * proportion to their areas; with `apart`, drawn again while it overlaps a lamp placed
 * before on its face (i lamps so far). */
static void wall_place(int i, double edge, double gap, int apart, v3 *c, v3 *nn, double *rot) {
  static double placed[WALL_LAMPS_MAX][3][2];
  static int face_of[WALL_LAMPS_MAX];
  double tri[3][2];
  int face;
  for (;;) {
    double a = rnd() * (16.0 + 3 * 10.0), u = rnd(), v = rnd();
    double m = edge; /* keep whole triangles on their face */
    if (a < 16) { *c = mk(-2 + m + (4 - 2 * m) * u, 2.5 - gap, -2 + m + (4 - 2 * m) * v); *nn = mk(0, -1, 0); face = 0; }
    else if (a < 26) { *c = mk(-2 + m + (4 - 2 * m) * u, m + (2.5 - 2 * m) * v, -2 + gap); *nn = mk(0, 0, 1); face = 1; }
    else if (a < 36) { *c = mk(-2 + gap, m + (2.5 - 2 * m) * v, -2 + m + (4 - 2 * m) * u); *nn = mk(1, 0, 0); face = 2; }
    else { *c = mk(2 - gap, m + (2.5 - 2 * m) * v, -2 + m + (4 - 2 * m) * u); *nn = mk(-1, 0, 0); face = 3; }
    *rot = 2 * PI * rnd();
    if (!apart) return;
    v3 p[3];
    lamp_points(*c, *nn, edge, *rot, p);
    for (int k = 0; k < 3; k++) {
      tri[k][0] = face == 2 || face == 3 ? p[k].z : p[k].x;
      tri[k][1] = face == 0 ? p[k].z : p[k].y;
    }
    int clash = 0;
    for (int j = 0; j < i && !clash; j++) clash = face_of[j] == face && tri2_overlap(tri, (const double(*)[2])placed[j]);
    if (!clash) break;
  }
  memcpy(placed[i], tri, sizeof tri);
  face_of[i] = face;
}

/* n lamps lying flat on the walls (wall_place, none overlapping), equilateral, of edge
 * `edge`, radiance L0 times 1, 20^(1/2) or 20 (a third each), tinted. */
static void wall_lamps(FILE *obj, FILE *mtl, int n, double edge, double gap, double L0) {
  for (int i = 0; i < n && i < WALL_LAMPS_MAX; i++) {
    v3 c, nn;
    double rot;
    wall_place(i, edge, gap, 1, &c, &nn, &rot);
    double R, G, B;
    double sat = 0.1 + 0.4 * rnd(), hue = rnd();
    hsv(hue, sat, 1, &R, &G, &B);
    int level = (int)(3 * rnd());
    double L = L0 * pow(20.0, 0.5 * level);
    lamp(obj, mtl, i, c, nn, edge, rot, R * L, G * L, B * L);
  }
}

/* The held-out rooms' lamps: like wall_lamps, but tints from a palette of 8 drawn per seed,
 * and overlaps between lamps on one face allowed unless `apart`. */
static void heldout_lamps(FILE *obj, FILE *mtl, int n, double edge, double gap, double L0, int apart) {
  double pal[8][3];
  for (int t = 0; t < 8; t++) {
    double sat = 0.15 + 0.45 * rnd(), hue = rnd();
    hsv(hue, sat, 1, &pal[t][0], &pal[t][1], &pal[t][2]);
  }
  for (int i = 0; i < n && i < WALL_LAMPS_MAX; i++) {
    v3 c, nn;
    double rot;
    wall_place(i, edge, gap, apart, &c, &nn, &rot);
    int t = (int)(8 * rnd()), level = (int)(3 * rnd());
    double L = L0 * pow(20.0, 0.5 * level);
    lamp(obj, mtl, i, c, nn, edge, rot, pal[t][0] * L, pal[t][1] * L, pal[t][2] * L);
  }
}

static int heldout(const char *dir, const char *seed_s, int apart, int boxes) {
  char *end;
  unsigned long seed = strtoul(seed_s, &end, 10);
  if (end == seed_s || *end) { fprintf(stderr, "gen_manylight: \"%s\" is not a seed\n", seed_s); return 2; }
  st = 0x243f6a8885a308d3ULL ^ (0x9e3779b97f4a7c15ULL * (seed + 1));
  char po[4096], pm[4096], pj[4096];
  snprintf(po, sizeof po, "%s/heldout-%lu.obj", dir, seed);
  snprintf(pm, sizeof pm, "%s/heldout-%lu.mtl", dir, seed);
  snprintf(pj, sizeof pj, "%s/heldout-%lu.json", dir, seed);
  FILE *obj = fopen(po, "w"), *mtl = fopen(pm, "w"), *js = fopen(pj, "w");
  if (!obj || !mtl || !js) { fprintf(stderr, "gen_manylight: cannot write into %s\n", dir); return 1; }
  fprintf(obj, "# made by tools/gen_manylight.c (heldout %lu%s%s)\nmtllib heldout-%lu.mtl\n", seed, apart ? " apart" : "", boxes ? " boxes" : "", seed);
  fprintf(mtl, "newmtl white\nKd 0.7 0.7 0.7\n\nnewmtl red\nKd 0.6 0.1 0.08\n\nnewmtl green\nKd 0.12 0.5 0.15\n\nnewmtl grey\nKd 0.4 0.4 0.45\n\n");
  quad(obj, mk(-2, 0, -2), mk(-2, 0, 2), mk(2, 0, 2), mk(2, 0, -2), "white");
  quad(obj, mk(-2, 2.5, -2), mk(2, 2.5, -2), mk(2, 2.5, 2), mk(-2, 2.5, 2), "white");
  quad(obj, mk(-2, 0, -2), mk(2, 0, -2), mk(2, 2.5, -2), mk(-2, 2.5, -2), "white");
  quad(obj, mk(-2, 0, -2), mk(-2, 2.5, -2), mk(-2, 2.5, 2), mk(-2, 0, 2), "red");
  quad(obj, mk(2, 0, -2), mk(2, 0, 2), mk(2, 2.5, 2), mk(2, 2.5, -2), "green");
  if (boxes) {
    box(obj, mk(-1.2, 0, -1.3), mk(-0.4, 1.1, -0.5), "grey");
    box(obj, mk(0.4, 0, -0.8), mk(1.2, 0.6, 0.0), "white");
  }
  heldout_lamps(obj, mtl, 1536, 4.0 / 30, 0.004, 0.25, apart);
  /* a camera of its own per seed, from the open side */
  double cx = -1.2 + 2.4 * rnd(), cy = 0.9 + 0.8 * rnd(), lx = -0.5 + rnd(), ly = 0.5 + 0.5 * rnd();
  fprintf(js, "{\n  \"camera\": { \"position\": [%.3f, %.3f, 4.6], \"look_at\": [%.3f, %.3f, -1], \"up\": [0, 1, 0], \"fov\": 48 },\n"
              "  \"film\": { \"width\": 256, \"height\": 256 },\n  \"render\": { \"integrator\": \"restir-di\", \"spp\": 16 },\n"
              "  \"shapes\": [ { \"file\": \"heldout-%lu.obj\" }%s ]\n}\n",
          cx, cy, lx, ly, seed,
          boxes ? "" : ",\n    { \"file\": \"/work/shared/scenes/models/stanford-bunny.obj\", \"transform\": { \"scale\": 7, \"translate\": [0.1, -0.23, -0.3] } }");
  fclose(obj);
  fclose(mtl);
  fclose(js);
  printf("wrote %s, %s and %s\n", po, pm, pj);
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 4 && !strcmp(argv[1], "heldout")) {
    int apart = 0, boxes = 0;
    for (int i = 4; i < argc; i++) {
      if (!strcmp(argv[i], "apart")) apart = 1;
      else if (!strcmp(argv[i], "boxes")) boxes = 1;
      else if (strcmp(argv[i], "overlap")) { fprintf(stderr, "gen_manylight: unknown option \"%s\"\n", argv[i]); return 2; }
    }
    return heldout(argv[2], argv[3], apart, boxes);
  }
  if (argc != 3 || (strcmp(argv[1], "room") && strcmp(argv[1], "sponza") && strcmp(argv[1], "walls"))) {
    fprintf(stderr, "usage: gen_manylight room|sponza|walls DIR | heldout DIR SEED [overlap|apart] [boxes]\n");
    return 2;
  }
  int room = !strcmp(argv[1], "room"), walls = !strcmp(argv[1], "walls");
  const char *name = room ? "manylight-room" : walls ? "manylight-walls" : "sponza-lamps";
  char po[4096], pm[4096];
  snprintf(po, sizeof po, "%s/%s.obj", argv[2], name);
  snprintf(pm, sizeof pm, "%s/%s.mtl", argv[2], name);
  FILE *obj = fopen(po, "w"), *mtl = fopen(pm, "w");
  if (!obj || !mtl) { fprintf(stderr, "gen_manylight: cannot write %s\n", obj ? pm : po); return 1; }
  fprintf(obj, "# made by tools/gen_manylight.c (%s); do not edit\nmtllib %s\n", argv[1], strrchr(pm, '/') + 1);
  fprintf(mtl, "# made by tools/gen_manylight.c (%s); do not edit\n", argv[1]);
  if (walls) {
    fprintf(mtl, "newmtl white\nKd 0.7 0.7 0.7\n\nnewmtl red\nKd 0.6 0.1 0.08\n\nnewmtl green\nKd 0.12 0.5 0.15\n\nnewmtl grey\nKd 0.4 0.4 0.45\n\n");
    /* the same room shell as `room`: x, z in [-2, 2], y in [0, 2.5], open towards +z */
    quad(obj, mk(-2, 0, -2), mk(-2, 0, 2), mk(2, 0, 2), mk(2, 0, -2), "white");
    quad(obj, mk(-2, 2.5, -2), mk(2, 2.5, -2), mk(2, 2.5, 2), mk(-2, 2.5, 2), "white");
    quad(obj, mk(-2, 0, -2), mk(2, 0, -2), mk(2, 2.5, -2), mk(-2, 2.5, -2), "white");
    quad(obj, mk(-2, 0, -2), mk(-2, 2.5, -2), mk(-2, 2.5, 2), mk(-2, 0, 2), "red");
    quad(obj, mk(2, 0, -2), mk(2, 0, 2), mk(2, 2.5, 2), mk(2, 2.5, -2), "green");
    box(obj, mk(-1.0, 0, -1.0), mk(-0.3, 0.9, -0.3), "grey");
    box(obj, mk(0.3, 0, -0.4), mk(0.9, 0.5, 0.2), "white");
    box(obj, mk(-0.2, 0, 0.6), mk(0.2, 0.3, 1.0), "grey");
    /* edge 4/30 of the room's width, 1/1000 of it off the faces */
    wall_lamps(obj, mtl, 1536, 4.0 / 30, 0.004, 0.25);
  } else if (room) {
    fprintf(mtl, "newmtl white\nKd 0.7 0.7 0.7\n\nnewmtl red\nKd 0.6 0.1 0.08\n\nnewmtl green\nKd 0.12 0.5 0.15\n\nnewmtl grey\nKd 0.4 0.4 0.45\n\n");
    /* room: x, z in [-2, 2], y in [0, 2.5], open towards +z */
    quad(obj, mk(-2, 0, -2), mk(-2, 0, 2), mk(2, 0, 2), mk(2, 0, -2), "white");          /* floor, +y */
    quad(obj, mk(-2, 2.5, -2), mk(2, 2.5, -2), mk(2, 2.5, 2), mk(-2, 2.5, 2), "white");  /* ceiling, -y */
    quad(obj, mk(-2, 0, -2), mk(2, 0, -2), mk(2, 2.5, -2), mk(-2, 2.5, -2), "white");    /* back, +z */
    quad(obj, mk(-2, 0, -2), mk(-2, 2.5, -2), mk(-2, 2.5, 2), mk(-2, 0, 2), "red");      /* left, +x */
    quad(obj, mk(2, 0, -2), mk(2, 0, 2), mk(2, 2.5, 2), mk(2, 2.5, -2), "green");        /* right, -x */
    v3 blo[4] = {mk(-1.3, 0, -1.2), mk(0.4, 0, -0.3), mk(-0.2, 0, -1.9), mk(1.0, 1.2, -1.6)};
    v3 bhi[4] = {mk(-0.6, 1.4, -0.5), mk(1.1, 0.6, 0.4), mk(0.2, 2.5, -1.5), mk(1.6, 1.35, -1.0)};
    box(obj, blo[0], bhi[0], "grey");
    box(obj, blo[1], bhi[1], "white");
    box(obj, blo[2], bhi[2], "grey");   /* a pillar to the ceiling */
    box(obj, blo[3], bhi[3], "white");  /* a shelf */
    lamps(obj, mtl, 1024, mk(-1.85, 1.5, -1.85), mk(1.85, 2.42, 1.2), 0.06, 1.0, 2.0, blo, bhi, 4);
  } else {
    /* Sponza's atrium: x in [-13, 13], z in [-3.4, 3.4], from the floor to below the upper gallery */
    lamps(obj, mtl, 1200, mk(-13, 0.4, -3.4), mk(13, 7.0, 3.4), 0.2, 1.2, 3.0, NULL, NULL, 0);
  }
  fclose(obj);
  fclose(mtl);
  printf("wrote %s and %s\n", po, pm);
  return 0;
}
