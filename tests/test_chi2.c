/* test_chi2.c — chi-square goodness-of-fit tests of every sampling routine against its
 * own pdf, as Mitsuba and pbrt-v4 do: 10^6 samples (10^7 with VALO_TEST_FULL=1) binned
 * over the sphere in (theta, phi); expected counts integrate the pdf over each cell
 * (16x16 midpoint rule with the sin(theta) Jacobian); samples that produce no direction
 * or a delta lobe form one extra cell whose expected count is N (1 - integral); cells
 * with expected count < 5 are pooled; significance 0.01 with the Sidak correction over
 * all CHI2_TESTS tests, so one run fails falsely with probability 1 %. Delta lobes get
 * binomial / exact checks instead. */
#include "harness.h"
#include "material/bsdf.h"
#include "material/sheen.h"
#include "material/plastic.h"
#include "material/fresnel.h"
#include "material/medium.h"
#include "light/light.h"
#include "scene/envmap.h"
#include "core/alias.h"
#include "integrator/guide.h"
#include "scene/filter.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "geometry/triangle.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NT 20
#define NP 40
#define CHI2_TESTS 88

/* Regularised upper incomplete gamma Q(a, x) (series for x < a+1, else Lentz's
 * continued fraction). */
static double gamma_q(double a, double x) {
  if (x <= 0) return 1;
  double gln = lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 100000; n++) { ap += 1; del *= x / ap; sum += del; if (fabs(del) < fabs(sum) * 1e-15) break; }
    return 1 - sum * exp(-x + a * log(x) - gln);
  }
  double b = x + 1 - a, c = 1 / 1e-300, d = 1 / b, h = d;
  for (int i = 1; i < 100000; i++) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b; if (fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c; if (fabs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (fabs(del - 1) < 1e-15) break;
  }
  return exp(-x + a * log(x) - gln) * h;
}

static long nsamples(void) { return test_full() ? 10000000L : 1000000L; }

/* Chi-square on observed/expected arrays of n cells; returns 0 if it passes. */
static int chi2_check(const char *what, const double *obs, const double *exp_, int n) {
  double chsq = 0, pooled_o = 0, pooled_e = 0;
  int dof = 0;
  for (int i = 0; i < n; i++) {
    if (exp_[i] < 5) { pooled_o += obs[i]; pooled_e += exp_[i]; continue; }
    chsq += (obs[i] - exp_[i]) * (obs[i] - exp_[i]) / exp_[i];
    dof++;
  }
  if (pooled_e >= 5) { chsq += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e; dof++; }
  else if (pooled_o > 20) { fprintf(stderr, "%s: %g samples fell where the pdf expects %g\n", what, pooled_o, pooled_e); return 1; }
  dof -= 1;
  double p = gamma_q(dof / 2.0, chsq / 2.0);
  double alpha = 1 - pow(1 - 0.01, 1.0 / CHI2_TESTS);
  fprintf(stderr, "%s: chi2 = %.1f, dof = %d, p = %.4f (alpha %.2e)\n", what, chsq, dof, p, alpha);
  return p < alpha;
}

static vec3 sph_dir(double theta, double phi) { return v3((float)(sin(theta) * cos(phi)), (float)(sin(theta) * sin(phi)), (float)cos(theta)); }

typedef int (*sample_fn)(void *ctx, sampler *s, vec3 *dir);  /* 0: no direction / delta */
typedef double (*pdf_fn)(void *ctx, vec3 dir);

/* Samples whose own pdf or weight disagreed with pdf() and eval() (bsdf_sf counts them):
 * any is a failure, not a sample quietly dropped. */
static long g_sample_mismatch;

static int run_chi2(const char *what, void *ctx, sample_fn sf, pdf_fn pf) {
  long n = nsamples();
  g_sample_mismatch = 0;
  int cells = NT * NP + 1;
  double *obs = calloc(cells, sizeof(double)), *ex = calloc(cells, sizeof(double));
  for (long i = 0; i < n; i++) {
    sampler s = sampler_make(1234, (uint64_t)i, 0);
    vec3 d;
    if (!sf(ctx, &s, &d)) { obs[NT * NP] += 1; continue; }
    double th = acos(fmin(1, fmax(-1, d.z))), ph = atan2(d.y, d.x);
    if (ph < 0) ph += 2 * M_PI;
    int it = (int)(th / M_PI * NT), ip = (int)(ph / (2 * M_PI) * NP);
    if (it >= NT) it = NT - 1;
    if (ip >= NP) ip = NP - 1;
    obs[it * NP + ip] += 1;
  }
  /* Pass 1: 16x16 midpoint rule per cell. Pass 2: cells where the pdf is partly zero
   * (edges of a light's solid angle, the horizon), and every neighbour of a non-zero
   * cell (a sliver may fall between midpoints), are integrated again at 128x128. */
  double total = 0;
  char *mixed = calloc(NT * NP, 1), *nonzero = calloc(NT * NP, 1);
  for (int pass = 0; pass < 2; pass++)
    for (int it = 0; it < NT; it++)
      for (int ip = 0; ip < NP; ip++) {
        int refine = mixed[it * NP + ip];
        for (int a = -1; a <= 1 && !refine; a++)
          for (int b = -1; b <= 1; b++) {
            int jt = it + a, jp = (ip + b + NP) % NP;
            if (jt >= 0 && jt < NT && nonzero[jt * NP + jp]) refine = 1;
          }
        if (pass == 1 && !refine) continue;
        int sub = pass == 0 ? 16 : 128, zeros = 0, nz = 0;
        double acc = 0, dth = M_PI / NT / sub, dph = 2 * M_PI / NP / sub;
        for (int a = 0; a < sub; a++)
          for (int b = 0; b < sub; b++) {
            double th = (it + (a + 0.5) / sub) * M_PI / NT, ph = (ip + (b + 0.5) / sub) * 2 * M_PI / NP;
            double pv = pf(ctx, sph_dir(th, ph));
            if (pv > 0) nz++; else zeros++;
            acc += pv * sin(th) * dth * dph;
          }
        if (pass == 0) { mixed[it * NP + ip] = zeros && nz; nonzero[it * NP + ip] = nz > 0; }
        ex[it * NP + ip] = acc * n;
      }
  for (int i = 0; i < NT * NP; i++) total += ex[i] / n;
  free(mixed); free(nonzero);
  ex[NT * NP] = fmax(0, 1 - total) * n;
  fprintf(stderr, "%s: pdf integrates to %.5f, %.5f of samples gave no (or a delta) direction\n", what, total, obs[NT * NP] / n);
  int rc = chi2_check(what, obs, ex, cells);
  free(obs); free(ex);
  if (total > 1.002) { fprintf(stderr, "%s: pdf integrates to more than 1\n", what); return 1; }
  if (g_sample_mismatch) { fprintf(stderr, "%s: %ld samples whose pdf or weight disagree with pdf() and eval()\n", what, g_sample_mismatch); return 1; }
  return rc;
}

/* ---- BSDFs */
typedef struct bsdf_ctx { bsdf b, second; vec3 wo; } bsdf_ctx;
static int bsdf_sf(void *c, sampler *s, vec3 *d);
static int test_bsdf_wo(const char *name, material m, vec3 wo);
static int test_bsdf(const char *name, material m, float theta_o_deg);
static double directional_albedo(const material *m, float theta_o_deg, uint64_t seed);

/* Rough conductor (6 tests per distribution, GGX and Beckmann, and 2 anisotropic) and
 * rough dielectric seen from outside and inside (4 per distribution, and 2 anisotropic). */
static int rough_conductor(void) {
  material m = material_default();
  m.type = MAT_CONDUCTOR;
  conductor_preset("Au", &m.eta, &m.k);
  float rough[3] = {0.3f, 0.6f, 0.9f}, th[2] = {20, 70};
  int rc = 0;
  for (int beck = 0; beck < 2; beck++)
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 2; j++) {
      m.roughness = rough[i];
      m.beckmann = beck;
      float t = th[j] * (float)M_PI / 180;
      char name[96];
      snprintf(name, sizeof name, "%s conductor roughness %.1f, theta_o %.0f", beck ? "Beckmann" : "GGX", rough[i], th[j]);
      rc |= test_bsdf_wo(name, m, v3(sinf(t) * 0.6f, sinf(t) * 0.8f, cosf(t)));
    }
  /* anisotropic: roughness u along the frame's s (x), v along t (y), wo off both axes */
  struct { float ru, rv, th; } an[2] = {{0.2f, 0.7f, 40}, {0.8f, 0.3f, 70}};
  for (int beck = 0; beck < 2; beck++)
    for (int i = 0; i < 2; i++) {
      m.roughness = an[i].ru; m.roughness_v = an[i].rv; m.anisotropic = 1; m.beckmann = beck;
      float t = an[i].th * (float)M_PI / 180;
      char name[96];
      snprintf(name, sizeof name, "%s conductor roughness u %.1f v %.1f, theta_o %.0f", beck ? "Beckmann" : "GGX", an[i].ru, an[i].rv, an[i].th);
      rc |= test_bsdf_wo(name, m, v3(sinf(t) * 0.6f, sinf(t) * 0.8f, cosf(t)));
    }
  return rc;
}
/* Mitsuba's plastics (material/plastic.h): the sampled directions against the pdf, smooth
 * (its mirror lobe is the delta share) and rough with either distribution (6 tests); then
 * a white smooth plastic (kd = ks = 1) reflects all it receives, since the coat passes
 * diffuse light out as much as in (1 - Fdr(eta) = eta^2 (1 - Fdr(1/eta))), and a white
 * rough one at most all (single scattering loses some). */
static int plastic(void) {
  struct { float rough, th; int beck; } cfg[6] = {{0, 20, 0}, {0, 70, 0}, {0.3f, 30, 1}, {0.3f, 75, 0}, {0.7f, 45, 1}, {0.7f, 80, 0}};
  int rc = 0;
  for (int i = 0; i < 6; i++) {
    material m = material_default();
    m.type = MAT_PLASTIC; m.ior = 1.49f; m.kd = c3(0.6f, 0.4f, 0.2f); m.ks = c3(1, 1, 1);
    m.roughness = cfg[i].rough; m.beckmann = cfg[i].beck; m.nonlinear = i & 1;
    plastic_prepare(&m);
    char name[96];
    snprintf(name, sizeof name, "%s plastic roughness %.1f", cfg[i].rough == 0 ? "smooth" : cfg[i].beck ? "Beckmann" : "GGX", cfg[i].rough);
    rc |= test_bsdf(name, m, cfg[i].th);
  }
  float rough[3] = {0, 0.3f, 0.7f}, th[3] = {0, 45, 80};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      material m = material_default();
      m.type = MAT_PLASTIC; m.ior = 1.49f; m.kd = c3(1, 1, 1); m.ks = c3(1, 1, 1); m.roughness = rough[i];
      plastic_prepare(&m);
      double albedo = directional_albedo(&m, th[j], 29);
      fprintf(stderr, "white plastic roughness %.1f theta_o %2.0f: albedo %.4f\n", rough[i], th[j], albedo);
      CHECK(albedo <= 1.0 + 5e-3, "albedo %.4f > 1", albedo);
      CHECK(rough[i] > 0 || fabs(albedo - 1) < 5e-3, "a white smooth plastic's albedo is %.4f, not 1", albedo);
      CHECK(albedo > 0.45, "albedo %.4f: implausibly low (single scattering at roughness 0.7 keeps about 0.55)", albedo);
    }
  return rc;
}

/* Mitsuba's principled: its lobes' mixture sampled (cosine, GGX visible normals reflected
 * or refracted, GTR1 normals) against the pdf it reports, chi-square; at several
 * roughnesses, metallic weights, a clearcoat and a sheen, grazing and not; transmissive
 * from outside and inside. */
static int principled(void) {
  struct { float rough, metal, cc, gloss, sheen, th; } cfg[6] = {{0.5f, 0, 0, 0, 0, 30},     {0.2f, 1, 0, 0, 0, 60},
                                                                 {0.6f, 0.5f, 1, 0.7f, 0, 45}, {0.3f, 0, 1, 0.2f, 0.8f, 75},
                                                                 {0.9f, 0, 0.5f, 0.9f, 0, 10}, {0.05f, 0.3f, 0, 0, 0.5f, 70}};
  int rc = 0;
  for (int i = 0; i < 6; i++) {
    material m = material_default();
    m.type = MAT_PRINCIPLED; m.ior = 1.5f; m.kd = c3(0.6f, 0.4f, 0.2f);
    m.roughness = cfg[i].rough; m.metallic = cfg[i].metal; m.clearcoat = cfg[i].cc; m.clearcoat_gloss = cfg[i].gloss;
    m.sheen = cfg[i].sheen; m.spec_tint = 0.3f; m.flatness = 0.2f;
    char name[128];
    snprintf(name, sizeof name, "principled roughness %.2f metallic %.1f clearcoat %.1f (gloss %.1f) sheen %.1f", cfg[i].rough, cfg[i].metal,
             cfg[i].cc, cfg[i].gloss, cfg[i].sheen);
    rc |= test_bsdf(name, m, cfg[i].th);
  }
  /* with its transmission lobe: from outside and from inside */
  struct { float trans, rough, th; int inside; } tc[4] = {{1, 0.3f, 30, 0}, {0.5f, 0.6f, 60, 0}, {1, 0.3f, 40, 1}, {0.5f, 0.5f, 20, 1}};
  for (int i = 0; i < 4; i++) {
    material m = material_default();
    m.type = MAT_PRINCIPLED; m.ior = 1.5f; m.kd = c3(0.8f, 0.6f, 0.4f); m.spec_trans = tc[i].trans; m.roughness = tc[i].rough;
    m.clearcoat = 0.5f; m.clearcoat_gloss = 0.5f;
    float t = tc[i].th * (float)M_PI / 180;
    char name[128];
    snprintf(name, sizeof name, "principled spec_trans %.1f roughness %.1f, theta_o %.0f, %s", tc[i].trans, tc[i].rough, tc[i].th,
             tc[i].inside ? "inside" : "outside");
    rc |= test_bsdf_wo(name, m, v3(sinf(t), 0, tc[i].inside ? -cosf(t) : cosf(t)));
  }
  /* anisotropic (Mitsuba's `anisotropic`): a half metal from outside, a glass from inside */
  for (int i = 0; i < 2; i++) {
    material m = material_default();
    m.type = MAT_PRINCIPLED; m.ior = 1.5f; m.kd = c3(0.7f, 0.5f, 0.3f); m.roughness = 0.4f; m.anisotropy = i ? 0.5f : 0.8f; m.anisotropic = 1;
    m.metallic = i ? 0 : 0.5f; m.spec_trans = i ? 1 : 0;
    float t = (i ? 35 : 55) * (float)M_PI / 180;
    char name[128];
    snprintf(name, sizeof name, "principled anisotropic %.1f, %s", m.anisotropy, i ? "glass, inside" : "half metal");
    rc |= test_bsdf_wo(name, m, v3(sinf(t) * 0.6f, sinf(t) * 0.8f, i ? -cosf(t) : cosf(t)));
  }
  return rc;
}

static int rough_dielectric(void) {
  material m = material_default();
  m.type = MAT_DIELECTRIC;
  m.ior = 1.5f;
  struct { float r, th; int inside; } cfg[4] = {{0.4f, 30, 0}, {0.4f, 30, 1}, {0.8f, 70, 0}, {0.8f, 50, 1}};
  int rc = 0;
  for (int beck = 0; beck < 2; beck++)
  for (int i = 0; i < 4; i++) {
    m.roughness = cfg[i].r;
    m.beckmann = beck;
    float t = cfg[i].th * (float)M_PI / 180;
    char name[96];
    snprintf(name, sizeof name, "%s dielectric roughness %.1f, theta_o %.0f, %s", beck ? "Beckmann" : "GGX", cfg[i].r, cfg[i].th,
             cfg[i].inside ? "inside" : "outside");
    rc |= test_bsdf_wo(name, m, v3(sinf(t), 0, cfg[i].inside ? -cosf(t) : cosf(t)));
  }
  struct { float ru, rv, th; int inside; } an[2] = {{0.3f, 0.7f, 40, 0}, {0.7f, 0.3f, 30, 1}};
  for (int beck = 0; beck < 2; beck++)
    for (int i = 0; i < 2; i++) {
      m.roughness = an[i].ru; m.roughness_v = an[i].rv; m.anisotropic = 1; m.beckmann = beck;
      float t = an[i].th * (float)M_PI / 180;
      char name[112];
      snprintf(name, sizeof name, "%s dielectric roughness u %.1f v %.1f, theta_o %.0f, %s", beck ? "Beckmann" : "GGX", an[i].ru, an[i].rv, an[i].th,
               an[i].inside ? "inside" : "outside");
      rc |= test_bsdf_wo(name, m, v3(sinf(t) * 0.6f, sinf(t) * 0.8f, an[i].inside ? -cosf(t) : cosf(t)));
    }
  return rc;
}

/* Directional albedo of `m` seen from the direction theta_o (degrees, in the xz plane):
 * the mean sample weight (green channel, radiance scaling across refraction undone)
 * over 2e5 samples of seed `seed`. */
static double directional_albedo(const material *m, float theta_o_deg, uint64_t seed) {
  bsdf b = bsdf_from_material(m);
  float t = theta_o_deg * (float)M_PI / 180;
  vec3 wo = v3(sinf(t), 0, cosf(t));
  double sum = 0;
  long n = 200000;
  for (long k = 0; k < n; k++) {
    sampler sm = sampler_make(seed, (uint64_t)k, 0);
    bsdf_sample bs;
    float ul = sampler_1d(&sm), u1 = sampler_1d(&sm), u2 = sampler_1d(&sm);
    if (bsdf_sample_dir(&b, wo, ul, u1, u2, &bs)) sum += bs.weight.g / bs.eta_scale;
  }
  return sum / n;
}

/* glTF metallic-roughness (4 tests): dielectric, metal and a half-metal mix, smooth to
 * rough; then its directional albedo with a white base colour stays at most 1. */
static int pbr_metallic_roughness(void) {
  struct { float metallic, rough, base, th; } cfg[4] = {{0, 0.3f, 0.5f, 20}, {0, 0.7f, 0.8f, 70}, {1, 0.4f, 0.9f, 45}, {0.5f, 0.2f, 0.6f, 60}};
  int rc = 0;
  for (int i = 0; i < 4; i++) {
    material m = material_default();
    m.type = MAT_PBR;
    m.metallic = cfg[i].metallic; m.roughness = cfg[i].rough; m.kd = c3(cfg[i].base, cfg[i].base * 0.8f, cfg[i].base * 0.5f);
    char name[96];
    snprintf(name, sizeof name, "glTF PBR metallic %.1f roughness %.1f", cfg[i].metallic, cfg[i].rough);
    rc |= test_bsdf(name, m, cfg[i].th);
  }
  /* glTF's clearcoat layer (KHR_materials_clearcoat): a third lobe, sampled with its own pdf */
  struct { float metallic, rough, cc, ccr, th; } ccfg[3] = {{0, 0.6f, 1, 0.05f, 30}, {1, 0.5f, 0.7f, 0.3f, 60}, {0, 0.3f, 0.5f, 0.6f, 75}};
  for (int i = 0; i < 3; i++) {
    material m = material_default();
    m.type = MAT_PBR;
    m.metallic = ccfg[i].metallic; m.roughness = ccfg[i].rough; m.kd = c3(0.7f, 0.5f, 0.3f);
    m.clearcoat = ccfg[i].cc; m.clearcoat_roughness = ccfg[i].ccr;
    char name[96];
    snprintf(name, sizeof name, "glTF PBR clearcoat %.1f of roughness %.2f", ccfg[i].cc, ccfg[i].ccr);
    rc |= test_bsdf(name, m, ccfg[i].th);
  }
  float rough[3] = {0.1f, 0.5f, 1.0f}, th[3] = {0, 45, 80};
  for (int metal = 0; metal < 2; metal++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        material m = material_default();
        m.type = MAT_PBR;
        m.metallic = (float)metal; m.roughness = rough[i]; m.kd = c3(1, 1, 1);
        double albedo = directional_albedo(&m, th[j], 23);
        fprintf(stderr, "glTF PBR white %s roughness %.1f theta_o %2.0f: albedo %.4f\n", metal ? "metal     " : "dielectric", rough[i], th[j], albedo);
        CHECK(albedo <= 1.0 + 5e-3, "albedo %.4f > 1", albedo);
        m.clearcoat = 1; m.clearcoat_roughness = rough[i];
        double coated = directional_albedo(&m, th[j], 23);
        CHECK(coated <= 1.0 + 5e-3, "under a clearcoat: albedo %.4f > 1", coated);
        CHECK(albedo > 0.25, "albedo %.4f: implausibly low (GGX single scattering at roughness 1 keeps about 0.3)", albedo);
      }
  return rc;
}

/* glTF's sheen layer (KHR_materials_sheen, material/sheen.h): the Charlie distribution
 * integrates to 1 over projected area at four roughnesses; samples of a pbr material
 * with a sheen against its density (the sheen a fourth lobe, cosine-weighted) with and
 * without a clearcoat; the tabulated albedo E(cos) against the directional albedo of the
 * sheen alone (base colour black, specular 0) estimated by sampling, within 1 % of the
 * white sheen's; and a white sheen over a white base keeps the albedo at most 1 (the base
 * scaled by 1 - E), where the sheen simply added would exceed it. */
static int pbr_sheen(void) {
  int rc = 0;
  float rs[4] = {0.07f, 0.3f, 0.6f, 1.0f};
  for (int k = 0; k < 4; k++) {
    double sum = 0;
    int n = 2000;
    for (int i = 0; i < n; i++) { /* integral of D(h) cos_h over the hemisphere, cos_h uniform */
      double ch = (i + 0.5) / n;
      double inv = 1 / (double)sheen_alpha(rs[k]), d = (2 + inv) * pow(1 - ch * ch, 0.5 * inv) / (2 * M_PI);
      sum += d * ch * 2 * M_PI / n;
    }
    fprintf(stderr, "sheen roughness %.2f: D integrates to %.5f\n", rs[k], sum);
    CHECK(fabs(sum - 1) < 1e-3, "sheen roughness %.2f: D integrates to %g", rs[k], sum);
  }
  struct { float metallic, rough, sheen, sr, cc, th; } cfg[4] = {{0, 0.6f, 1, 0.3f, 0, 40}, {1, 0.4f, 0.6f, 0.7f, 0, 70}, {0, 0.3f, 0.8f, 0.1f, 0.5f, 60}, {0.5f, 0.8f, 0.4f, 1, 0, 15}};
  for (int i = 0; i < 4; i++) {
    material m = material_default();
    m.type = MAT_PBR;
    m.metallic = cfg[i].metallic; m.roughness = cfg[i].rough; m.kd = c3(0.7f, 0.5f, 0.3f);
    m.sheen_color = c3(cfg[i].sheen, cfg[i].sheen * 0.7f, cfg[i].sheen * 0.9f); m.sheen_roughness = cfg[i].sr;
    m.clearcoat = cfg[i].cc; m.clearcoat_roughness = 0.2f;
    sheen_prepare(&m);
    char name[112];
    snprintf(name, sizeof name, "glTF PBR sheen %.1f of roughness %.2f%s", cfg[i].sheen, cfg[i].sr, cfg[i].cc > 0 ? " under a clearcoat" : "");
    rc |= test_bsdf(name, m, cfg[i].th);
  }
  float th[4] = {0, 40, 70, 85};
  for (int k = 0; k < 4; k++)
    for (int j = 0; j < 4; j++) {
      material m = material_default();
      m.type = MAT_PBR;
      m.kd = c3(0, 0, 0);
      material_pbr_specular(&m, 1.5f, 0, c3(1, 1, 1));
      m.sheen_color = c3(1, 1, 1); m.sheen_roughness = rs[k];
      sheen_prepare(&m);
      double mc = directional_albedo(&m, th[j], 29), tab = sheen_albedo(m.sheen_E, cosf(th[j] * (float)M_PI / 180));
      m.kd = c3(1, 1, 1);
      material_pbr_specular(&m, 1.5f, 1, c3(1, 1, 1));
      double both = directional_albedo(&m, th[j], 31);
      m.sheen_color = c3(0, 0, 0);
      double base = directional_albedo(&m, th[j], 31);
      fprintf(stderr, "sheen roughness %.2f theta_o %2.0f: E %.4f (table %.4f); white base %.4f, with the white sheen %.4f\n", rs[k], th[j], mc, tab, base, both);
      CHECK(fabs(mc - tab) < 0.01, "sheen roughness %.2f theta_o %.0f: sampled albedo %.4f, table %.4f", rs[k], th[j], mc, tab);
      CHECK(both <= 1.0 + 5e-3, "sheen roughness %.2f theta_o %.0f: albedo %.4f > 1", rs[k], th[j], both);
    }
  return rc;
}

/* White furnace for microfacets: the directional albedo of a near-perfect GGX mirror
 * (F = 1) and of rough glass (reflection + transmission, radiance scaling undone) is at
 * most 1; the shortfall is the energy single scattering loses (printed, and in
 * docs/scene-format.md: 0.2 % at roughness 0.2, about 10 % at 0.5, over 40 % at 0.8 —
 * multiple scattering between microfacets is not modelled). */
static int microfacet_furnace(void) {
  float rough[4] = {0.2f, 0.5f, 0.8f, 1.0f}, th[3] = {0, 45, 80};
  for (int kind = 0; kind < 4; kind++) {
    static const char *const label[4] = {"GGX mirror", "GGX glass ", "Beckmann mirror", "Beckmann glass "};
    material m = material_default();
    m.type = (kind & 1) ? MAT_DIELECTRIC : MAT_CONDUCTOR;
    m.beckmann = kind >> 1;
    m.eta = c3(1e-3f, 1e-3f, 1e-3f); m.k = c3(1e3f, 1e3f, 1e3f); m.ior = 1.5f;
    for (int i = 0; i < 5; i++) {
      for (int j = 0; j < 3; j++) {
        /* the fifth: anisotropic, roughness 0.3 along u and 0.9 along v */
        m.roughness = i < 4 ? rough[i] : 0.3f;
        m.roughness_v = 0.9f;
        m.anisotropic = i == 4;
        double albedo = directional_albedo(&m, th[j], 17);
        fprintf(stderr, "%s roughness %s%.1f theta_o %2.0f: albedo %.4f (single-scattering loss %.1f%%)\n", label[kind], i < 4 ? "" : "u 0.3 v ",
                i < 4 ? rough[i] : 0.9f, th[j], albedo, 100 * (1 - albedo));
        CHECK(albedo <= 1.0 + 5e-3, "albedo %.4f > 1", albedo);
        /* At normal incidence only 1/(1 + alpha^2) of the cosine-weighted normals reflect
         * above the horizon: 0.5 at roughness 1, before shadowing. */
        CHECK(albedo > 0.3, "albedo %.4f: implausibly low", albedo);
      }
    }
  }
  return 0;
}

/* The integral of eval(wo, wi) |cos wi| over the sphere by midpoint quadrature in
 * (theta, phi), n x 4n cells per hemisphere (uniform in angle, so narrow lobes about the
 * normal are resolved): valo's eval alone, no sampling. Green channel; for transmission
 * the radiance scaling across refraction is undone, as directional_albedo does. */
static double eval_quadrature(const bsdf *b, vec3 wo, int n) {
  double sum = 0;
  for (int side = 0; side < 2; side++)
    for (int i = 0; i < n; i++) {
      double th = 0.5 * M_PI * (i + 0.5) / n, ct = cos(th), st = sin(th);
      for (int j = 0; j < 4 * n; j++) {
        double ph = 2 * M_PI * (j + 0.5) / (4 * n);
        vec3 wi = v3((float)(st * cos(ph)), (float)(st * sin(ph)), (float)(side ? -ct : ct));
        double f = bsdf_eval(b, wo, wi).g;
        int transmitted = side == (wo.z > 0); /* wi (side 1: below) opposite wo */
        if (transmitted && b->type == BSDF_ROUGH_DIELECTRIC) f *= wo.z > 0 ? b->eta * b->eta : 1 / (b->eta * b->eta);
        sum += f * ct * st;
      }
    }
  return sum * (0.5 * M_PI / n) * (2 * M_PI / (4 * n));
}

/* GGX single-scattering albedo of an F = 1 conductor against values computed outside
 * valo: double-precision quadrature of D G / (4 cos_o cos_i) cos_i with the height-
 * correlated Smith G and alpha = roughness^2 (the same six numbers as docs/testing.md).
 * valo gets them two independent ways: the mean sample weight (its sampling routine) and
 * midpoint quadrature of its eval; the two must also agree with each other. */
static int ggx_albedo(void) {
  static const struct { float rough, th, albedo; } ref[6] = {{0.5f, 0, 0.916f}, {0.5f, 45, 0.886f}, {0.5f, 80, 0.856f},
                                                             {1.0f, 0, 0.307f}, {1.0f, 45, 0.377f}, {1.0f, 80, 0.668f}};
  material m = material_default();
  m.type = MAT_CONDUCTOR;
  m.eta = c3(1e-4f, 1e-4f, 1e-4f); m.k = c3(1e4f, 1e4f, 1e4f); /* F = 1 to 1e-7 */
  for (int i = 0; i < 6; i++) {
    m.roughness = ref[i].rough;
    bsdf b = bsdf_from_material(&m);
    float t = ref[i].th * (float)M_PI / 180;
    double sampled = directional_albedo(&m, ref[i].th, 29), quad = eval_quadrature(&b, v3(sinf(t), 0, cosf(t)), 300);
    fprintf(stderr, "roughness %.1f theta_o %2.0f: reference %.3f, mean sample weight %.4f, quadrature of eval %.4f\n", ref[i].rough, ref[i].th,
            ref[i].albedo, sampled, quad);
    CHECK(fabs(sampled - ref[i].albedo) <= 0.01, "sampled albedo %.4f vs %.3f", sampled, ref[i].albedo);
    CHECK(fabs(quad - ref[i].albedo) <= 0.01, "eval quadrature %.4f vs %.3f", quad, ref[i].albedo);
  }
  return 0;
}

/* Every non-delta BSDF: reciprocity f(wo, wi) = f(wi, wo) to 1e-4 (relative) on random
 * pairs (refraction: the generalised form f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2, to
 * 1e-3, float rounding at grazing angles)
 * (Veach 1997, 5.2); and the mean sample weight equals the quadrature of eval |cos|
 * (within 1 % or 0.005), so sampling and evaluation describe the same lobe. The one
 * model that is not reciprocal by design is glTF PBR's dielectric diffuse base, weighted
 * by 1 - F(n.wo) (bsdf.c says why); it is checked for the sampling agreement only, and its
 * specular layer (white metal; black base colour) for reciprocity. */
static int bsdf_reciprocity(void) {
  enum { N = 10 };
  material ms[N];
  const char *names[N] = {"diffuse", "phong n=20", "glTF PBR half-metal", "rough gold", "rough glass 0.3", "rough glass 0.7", "glTF PBR metal",
                          "glTF PBR black base", "rough gold u 0.2 v 0.6", "rough glass u 0.6 v 0.25"};
  for (int i = 0; i < N; i++) ms[i] = material_default();
  ms[6].type = MAT_PBR; ms[6].kd = c3(1, 1, 1); ms[6].metallic = 1; ms[6].roughness = 0.3f;
  ms[7].type = MAT_PBR; ms[7].kd = c3(0, 0, 0); ms[7].metallic = 0; ms[7].roughness = 0.6f;
  ms[0].type = MAT_DIFFUSE; ms[0].kd = c3(0.4f, 0.6f, 0.8f);
  ms[1].type = MAT_PHONG; ms[1].kd = c3(0.3f, 0.3f, 0.3f); ms[1].ks = c3(0.5f, 0.5f, 0.5f); ms[1].exponent = 20;
  ms[2].type = MAT_PBR; ms[2].kd = c3(0.9f, 0.6f, 0.3f); ms[2].metallic = 0.5f; ms[2].roughness = 0.4f;
  ms[3].type = MAT_CONDUCTOR; ms[3].eta = c3(0.143f, 0.374f, 1.442f); ms[3].k = c3(3.983f, 2.385f, 1.603f); ms[3].roughness = 0.4f;
  ms[4].type = MAT_DIELECTRIC; ms[4].ior = 1.5f; ms[4].roughness = 0.3f;
  ms[5].type = MAT_DIELECTRIC; ms[5].ior = 1.5f; ms[5].roughness = 0.7f;
  ms[8] = ms[3]; ms[8].roughness = 0.2f; ms[8].roughness_v = 0.6f; ms[8].anisotropic = 1;
  ms[9] = ms[4]; ms[9].roughness = 0.6f; ms[9].roughness_v = 0.25f; ms[9].anisotropic = 1;
  for (int i = 0; i < N; i++) {
    bsdf b = bsdf_from_material(&ms[i]);
    int transmits = b.type == BSDF_ROUGH_DIELECTRIC, reciprocal = i != 2;
    double worst = 0, worst_t = 0; /* reflection, refraction pairs */
    long tested = 0;
    for (long k = 0; k < 20000; k++) {
      sampler sm = sampler_make(31, (uint64_t)k, 0);
      float u[4];
      for (int q = 0; q < 4; q++) u[q] = sampler_1d(&sm);
      vec3 wo = sample_uniform_sphere(u[0], u[1]), wi = sample_uniform_sphere(u[2], u[3]);
      if (!transmits) { wo.z = fabsf(wo.z); wi.z = fabsf(wi.z); }
      rgb a = bsdf_eval(&b, wo, wi), c = bsdf_eval(&b, wi, wo);
      if (transmits && wo.z * wi.z < 0) { /* eta_o, eta_i: 1 outside (z > 0), ior inside */
        float eo = wo.z > 0 ? 1 : b.eta, ei = wi.z > 0 ? 1 : b.eta;
        a = c3_scale(a, 1 / (eo * eo)); /* f(wo, wi) = f_s(wi -> wo): Veach's (5.14) */
        c = c3_scale(c, 1 / (ei * ei));
      }
      float va[3] = {a.r, a.g, a.b}, vc[3] = {c.r, c.g, c.b};
      for (int ch = 0; ch < 3; ch++) {
        CHECK(isfinite(va[ch]) && isfinite(vc[ch]), "%s: non-finite eval", names[i]);
        double d = fabs(va[ch] - vc[ch]) / fmax(fmax(fabs(va[ch]), fabs(vc[ch])), 0.1); /* float tails: relative to at least 0.1 ~ 1/pi */
        if (transmits && wo.z * wi.z < 0) worst_t = fmax(worst_t, d);
        else worst = fmax(worst, d);
      }
      tested++;
    }
    fprintf(stderr, "%-20s reciprocity: worst relative difference %.2g (refraction %.2g) over %ld pairs\n", names[i], worst, worst_t, tested);
    CHECK(!reciprocal || worst <= 1e-4, "%s: f(wo,wi) and f(wi,wo) differ by %.3g", names[i], worst);
    /* refraction: single-precision rounding of the generalised half vector reaches 6e-4
     * where wo grazes (cos 0.04); a missing or wrong eta^2 factor would be 0.55 or more */
    CHECK(worst_t <= 1e-3, "%s: refraction f(wo,wi)/eta_o^2 and f(wi,wo)/eta_i^2 differ by %.3g", names[i], worst_t);
    CHECK(reciprocal || worst > 0.01, "%s: now reciprocal: update this test and bsdf.c's note", names[i]);
    for (int a = 0; a < 3; a++) {
      float th = (float)(a * 35 + 5) * (float)M_PI / 180;
      vec3 wo = v3(sinf(th), 0, cosf(th));
      double sampled = directional_albedo(&ms[i], (float)(a * 35 + 5), 37), quad = eval_quadrature(&b, wo, 300);
      fprintf(stderr, "%-20s theta_o %2d: mean sample weight %.4f, quadrature of eval cos %.4f\n", names[i], a * 35 + 5, sampled, quad);
      CHECK(fabs(sampled - quad) <= fmax(0.01 * quad, 0.005), "%s: sampling and eval disagree", names[i]);
    }
  }
  return 0;
}

static int bsdf_sf(void *c, sampler *s, vec3 *d) {
  bsdf_ctx *x = c;
  bsdf_sample bs;
  float ul = sampler_1d(s), u1 = sampler_1d(s), u2 = sampler_1d(s);
  if (!bsdf_sample_dir(&x->b, x->wo, ul, u1, u2, &bs) || bs.delta) return 0;
  /* The sample's pdf and weight must agree with pdf() and with eval() |cos| / pdf()
   * computed here (the sampling routines compute some weights in closed form, e.g. the
   * diffuse lobe's kd); a mismatch fails the test (run_chi2). */
  float p = bsdf_pdf(&x->b, x->wo, bs.wi);
  rgb f = bsdf_eval(&x->b, x->wo, bs.wi), w = c3_scale(f, fabsf(bs.wi.z) / p);
  int bad = !(fabsf(p - bs.pdf) <= 1e-3f * p);
  for (int k = 0; k < 3; k++) {
    float a = k == 0 ? w.r : k == 1 ? w.g : w.b, b = k == 0 ? bs.weight.r : k == 1 ? bs.weight.g : bs.weight.b;
    if (!(fabsf(a - b) <= 1e-3f * fmaxf(fabsf(a), 1e-6f) + 1e-6f)) bad = 1;
  }
  if (bad) {
    if (g_sample_mismatch++ < 3)
      fprintf(stderr, "sample pdf %g (pdf() %g), weight (%g %g %g) against eval cos / pdf (%g %g %g)\n", bs.pdf, p, bs.weight.r, bs.weight.g,
              bs.weight.b, w.r, w.g, w.b);
    return 0;
  }
  *d = bs.wi;
  return 1;
}
static double bsdf_pf(void *c, vec3 d) { bsdf_ctx *x = c; return bsdf_pdf(&x->b, x->wo, d); }

static int test_bsdf_wo(const char *name, material m, vec3 wo) {
  bsdf_ctx c;
  c.b = bsdf_from_material(&m);
  c.wo = v3_norm(wo);
  return run_chi2(name, &c, bsdf_sf, bsdf_pf);
}

static int test_bsdf(const char *name, material m, float theta_o_deg) {
  bsdf_ctx c;
  c.b = bsdf_from_material(&m);
  float th = theta_o_deg * (float)M_PI / 180;
  c.wo = v3(sinf(th) * 0.8f, sinf(th) * 0.6f, cosf(th));
  char what[128];
  snprintf(what, sizeof what, "%s, theta_o %.0f deg", name, theta_o_deg);
  return run_chi2(what, &c, bsdf_sf, bsdf_pf);
}

static int diffuse(void) {
  material m = material_default();
  int rc = 0;
  rc |= test_bsdf("diffuse", m, 5);
  rc |= test_bsdf("diffuse", m, 60);
  rc |= test_bsdf("diffuse", m, 85);
  return rc;
}
static int phong(void) {
  material m = material_default();
  m.type = MAT_PHONG;
  int rc = 0;
  float exps[3] = {1, 10, 100};
  for (int i = 0; i < 3; i++) {
    m.exponent = exps[i];
    m.kd = c3(0.3f, 0.3f, 0.3f); m.ks = c3(0.5f, 0.5f, 0.5f);
    char name[64];
    snprintf(name, sizeof name, "phong n=%.0f kd=.3 ks=.5", exps[i]);
    rc |= test_bsdf(name, m, 20);
    rc |= test_bsdf(name, m, 70);
  }
  m.kd = c3(0, 0, 0); m.ks = c3(0.9f, 0.9f, 0.9f); m.exponent = 30;
  rc |= test_bsdf("phong specular only n=30", m, 45);
  return rc;
}
/* A blend of two BSDFs (bsdf.mix, Mitsuba's blendbsdf): the directions sampled by the
 * pick of one and then its own sampling against the blend's pdf, and their weights against
 * the blend's f |cos| / pdf (bsdf_sf): diffuse with rough gold, a rough plastic with an
 * anisotropic rough conductor, and diffuse with a smooth conductor (its delta samples are
 * left out; the rest must follow (1 - w) of the diffuse density). */
static int blend_mixture(void) {
  struct { int kind; float w, th; } cfg[3] = {{0, 0.3f, 30}, {1, 0.6f, 65}, {2, 0.5f, 40}};
  int rc = 0;
  for (int i = 0; i < 3; i++) {
    material a = material_default(), b = material_default();
    a.kd = c3(0.2f, 0.5f, 0.8f);
    b.type = MAT_CONDUCTOR;
    conductor_preset("Au", &b.eta, &b.k);
    b.roughness = cfg[i].kind == 2 ? 0 : 0.4f;
    if (cfg[i].kind == 1) {
      a.type = MAT_PLASTIC; a.roughness = 0.3f; a.ks = c3(1, 1, 1);
      b.roughness_v = 0.8f; b.anisotropic = 1;
    }
    bsdf_ctx c;
    c.b = bsdf_from_material(&a);
    c.second = bsdf_from_material(&b);
    c.b.mix = &c.second;
    c.b.mix_w = cfg[i].w;
    float th = cfg[i].th * (float)M_PI / 180;
    c.wo = v3(sinf(th) * 0.8f, sinf(th) * 0.6f, cosf(th));
    static const char *const what[3] = {"diffuse + rough gold", "rough plastic + anisotropic rough gold", "diffuse + smooth gold"};
    char name[128];
    snprintf(name, sizeof name, "blend %s, weight %.1f, theta_o %.0f deg", what[i], cfg[i].w, cfg[i].th);
    rc |= run_chi2(name, &c, bsdf_sf, bsdf_pf);
    /* and the blend is the weighted sum of the two */
    vec3 wi = v3_norm(v3(-0.3f, 0.2f, 0.9f));
    bsdf ba = bsdf_from_material(&a), bb = bsdf_from_material(&b);
    float w = cfg[i].w;
    rgb f = bsdf_eval(&c.b, c.wo, wi), fa = bsdf_eval(&ba, c.wo, wi), fb = bsdf_eval(&bb, c.wo, wi);
    float want = (1 - w) * fa.g + w * fb.g, p = bsdf_pdf(&c.b, c.wo, wi), pwant = (1 - w) * bsdf_pdf(&ba, c.wo, wi) + w * bsdf_pdf(&bb, c.wo, wi);
    CHECK(fabsf(f.g - want) <= 1e-5f * want && fabsf(p - pwant) <= 1e-5f * pwant, "blend f %g pdf %g, want %g and %g", f.g, p, want, pwant);
  }
  return rc;
}

static int mirror_mixture(void) {
  material m = material_default();
  m.type = MAT_MIRROR;
  m.kd = c3(0.4f, 0.4f, 0.4f); m.ks = c3(0.5f, 0.5f, 0.5f);
  return test_bsdf("diffuse + mirror (illum 5), diffuse part", m, 30);
}

/* Energy: the albedo of diffuse and Phong estimated from their own samples never
 * exceeds 1 (energy conservation, digest 000). */
static int energy_conservation(void) {
  material m = material_default();
  m.type = MAT_PHONG;
  m.kd = c3(0.5f, 0.5f, 0.5f); m.ks = c3(0.5f, 0.5f, 0.5f);
  float exps[4] = {1, 5, 50, 500};
  for (int e = 0; e < 4; e++)
    for (int a = 0; a < 3; a++) {
      m.exponent = exps[e];
      double albedo = directional_albedo(&m, (float)(a * 40 + 5), 99);
      CHECK(albedo < 1.0 + 3e-3, "phong n=%g theta_o=%d: albedo %.4f > 1", exps[e], a * 40 + 5, albedo);
    }
  return 0;
}

/* Dielectric: reflection chosen with probability F (binomial, 6 sigma), refraction
 * obeys Snell's law; conductor weight equals the complex Fresnel term. */
static int delta_lobes(void) {
  material m = material_default();
  m.type = MAT_DIELECTRIC;
  m.ior = 1.5f;
  bsdf b = bsdf_from_material(&m);
  float angles[4] = {0, 30, 60, 85};
  for (int side = 0; side < 2; side++)
    for (int a = 0; a < 4; a++) {
      float th = angles[a] * (float)M_PI / 180;
      vec3 wo = v3(sinf(th), 0, side ? -cosf(th) : cosf(th));
      float F = fresnel_dielectric(wo.z, b.eta);
      long n = 200000, refl = 0;
      for (long i = 0; i < n; i++) {
        sampler s = sampler_make(7, (uint64_t)i, 0);
        bsdf_sample bs;
        float ul = sampler_1d(&s);
        CHECK(bsdf_sample_dir(&b, wo, ul, 0.5f, 0.5f, &bs), "dielectric sample failed");
        if (bs.wi.z * wo.z > 0) refl++;
        else {
          float eta_i = side ? 1.5f : 1.0f, eta_t = side ? 1.0f : 1.5f;
          float sin_i = sqrtf(fmaxf(0, 1 - wo.z * wo.z)), sin_t = sqrtf(fmaxf(0, 1 - bs.wi.z * bs.wi.z));
          CHECK(fabsf(eta_i * sin_i - eta_t * sin_t) < 1e-4f, "Snell's law violated");
        }
      }
      double sigma = sqrt(n * F * (1 - F)) + 1e-9;
      CHECK(fabs(refl - n * F) <= 6 * sigma + 1e-9, "side %d angle %g: %ld reflections, expected %.1f", side, angles[a], refl, n * F);
    }
  /* A thin pane: reflects 2R / (1 + R) of the light (both faces and every bounce between
   * them, R the single face's Fresnel term), from either side, and passes the rest
   * straight on. 2R/(1+R) is written here, not taken from bsdf.c's sum. */
  m.type = MAT_THIN_DIELECTRIC;
  b = bsdf_from_material(&m);
  for (int side = 0; side < 2; side++)
    for (int a = 0; a < 4; a++) {
      float th = angles[a] * (float)M_PI / 180;
      vec3 wo = v3(sinf(th), 0, side ? -cosf(th) : cosf(th));
      float R1 = fresnel_dielectric(fabsf(wo.z), 1.5f), R = 2 * R1 / (1 + R1);
      long n = 200000, refl = 0;
      for (long i = 0; i < n; i++) {
        sampler s = sampler_make(8, (uint64_t)i, 0);
        bsdf_sample bs;
        CHECK(bsdf_sample_dir(&b, wo, sampler_1d(&s), 0.5f, 0.5f, &bs) && bs.delta, "thin dielectric sample failed");
        CHECK(bs.weight.r == 1 && bs.eta_scale == 1, "thin dielectric weight %g, eta scale %g", bs.weight.r, bs.eta_scale);
        if (bs.wi.z * wo.z > 0) refl++;
        else CHECK(v3_len(v3_add(bs.wi, wo)) < 1e-6f, "a thin pane bent the ray");
      }
      double sigma = sqrt(n * R * (1 - R)) + 1e-9;
      CHECK(fabs(refl - n * R) <= 6 * sigma + 1e-9, "thin, side %d angle %g: %ld reflections, expected %.1f", side, angles[a], refl, n * R);
    }
  /* Normal incidence, n = 1.5: F = 0.04. Beyond the critical angle: F = 1. */
  CHECK(fabsf(fresnel_dielectric(1, 1.5f) - 0.04f) < 1e-6f, "F(0) = %g", fresnel_dielectric(1, 1.5f));
  CHECK(fresnel_dielectric(-0.3f, 1.5f) == 1.0f, "no total internal reflection");
  /* Conductor at normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2). */
  rgb eta, k;
  CHECK(conductor_preset("Au", &eta, &k) == 0, "no Au preset");
  float expect = ((eta.r - 1) * (eta.r - 1) + k.r * k.r) / ((eta.r + 1) * (eta.r + 1) + k.r * k.r);
  CHECK(fabsf(fresnel_conductor(1, eta, k).r - expect) < 1e-5f, "conductor F(0) %g vs %g", fresnel_conductor(1, eta, k).r, expect);
  CHECK(fabsf(fresnel_conductor1(0, 1.5f, 2.0f) - 1) < 1e-5f, "conductor F(90 deg) should be 1");
  return 0;
}

/* ---- lights */
typedef struct light_ctx { scene *s; light l; vec3 p; } light_ctx;
static int light_sf(void *c, sampler *s, vec3 *d) {
  light_ctx *x = c;
  light_li li;
  float u1 = sampler_1d(s), u2 = sampler_1d(s);
  if (!light_sample(x->s, &x->l, x->p, u1, u2, &li)) return 0;
  *d = li.wi;
  return 1;
}
static double light_pf(void *c, vec3 d) {
  light_ctx *x = c;
  if (x->l.type == LIGHT_ENV) return light_pdf_env(x->s, &x->l, d);
  const uint32_t *ix = &x->s->idx[3 * x->l.tri];
  float v[9];
  for (int k = 0; k < 3; k++) memcpy(&v[3 * k], &x->s->pos[ix[k]], sizeof(vec3));
  ray_shear sh = ray_shear_make(x->p, d);
  float t, b1, b2;
  if (!tri_intersect(&sh, v, INFINITY, &t, &b1, &b2)) return 0;
  vec3 pl = v3_add(x->p, v3_scale(d, t));
  return light_pdf_area(&x->l, x->p, pl, v3_norm(scene_tri_ng(x->s, x->l.tri)));
}
/* An emitting sphere's cone (light.h): from a point near it (a wide cone) and from one
 * 100 radii away (a cone of 3e-4 sr, where 1 - cos loses digits in float unless
 * computed as valo does), directions uniform in (1 - cos theta) / (1 - cos max) and in
 * phi about the axis, none outside, the density 1 / (2 pi (1 - cos max)); the
 * sphere's selection probability the sum of its triangles', in the grid and by power. */
typedef struct cone_ctx { light_cone k; } cone_ctx;
static int cone_sf(void *c, sampler *s, vec3 *d) {
  float u1 = sampler_1d(s), u2 = sampler_1d(s);
  *d = light_cone_sample(&((cone_ctx *)c)->k, u1, u2);
  return 1;
}
static double cone_pf(void *c, vec3 d) {
  const light_cone *k = &((cone_ctx *)c)->k;
  return v3_dot(d, k->axis) >= 1 - k->one_minus_cos ? k->pdf : 0;
}
static int sphere_cone(void) {
  scene *s = scene_new("chi2-sphere");
  material m = material_default();
  m.emission = c3(1, 1, 1);
  uint32_t mi = scene_add_material(s, &m);
  valo_error err;
  vec3 ctr = v3(0.3f, -0.2f, 0.5f);
  CHECK(scene_add_sphere(s, ctr, 0.5f, 2, 0, 1, mi, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  CHECK(s->nlights == 320 && s->nspheres == 1 && s->spheres[0].l1 == 320, "%u lights; the sphere's %u..%u", s->nlights, s->spheres[0].l0, s->spheres[0].l1);
  int rc = 0;
  for (int mode = 0; mode < 2; mode++) {
    light_sampler ls;
    CHECK(light_sampler_init(&ls, s, mode ? LIGHT_SELECT_POWER : LIGHT_SELECT_GRID, 1) == 0 && ls.unit0, "init");
    static const float dist[2] = {0.8f, 50.0f};
    for (int far = 0; far < 2; far++) {
      vec3 p = v3_add(ctr, v3_scale(v3_norm(v3(0.3f, 1, -0.4f)), dist[far]));
      cone_ctx c;
      CHECK(light_sphere_at(&ls, s, 17, p, &c.k), "no cone from %g radii", dist[far] / 0.5);
      double sum = 0;
      for (uint32_t i = 0; i < s->nlights; i++) sum += light_select_pmf(&ls, s, i, p);
      double range = light_range_pmf(&ls, 0, s->nlights, p);
      CHECK(fabs(range - sum) < 1e-5 && fabs(range - 1) < 1e-5, "%s: the sphere's pmf %.7f, its lights' %.7f", mode ? "power" : "grid", range, sum);
      if (mode) continue;
      double want = 2 * M_PI * (1 - sqrt(1 - 0.25 / ((double)dist[far] * dist[far])));
      CHECK(fabs(1 / (c.k.pdf * want) - 1) < 1e-4, "cone of %g sr, pdf %g", want, (double)c.k.pdf);
      if (!far) rc |= run_chi2("sphere light's cone from 1.6 radii", &c, cone_sf, cone_pf);
      /* In the cone's own terms: (1 - cos) / (1 - cos max) and phi, 10 x 10 cells. */
      double obs[100] = {0}, ex[100];
      long n = nsamples() / 4;
      frame f = frame_from_n(c.k.axis);
      for (long i = 0; i < n; i++) {
        sampler sm = sampler_make(99, (uint64_t)i, 0);
        vec3 d;
        cone_sf(&c, &sm, &d);
        vec3 l = frame_to_local(&f, d);
        double omc = (double)(l.x * l.x + l.y * l.y) / (1 + l.z); /* 1 - cos without cancellation */
        double ph = atan2(l.y, l.x);
        if (ph < 0) ph += 2 * M_PI;
        int a = (int)(omc / c.k.one_minus_cos * 10), b = (int)(ph / (2 * M_PI) * 10);
        CHECK(a <= 10, "a direction outside the cone (%g of its 1 - cos)", omc / c.k.one_minus_cos);
        obs[(a > 9 ? 9 : a) * 10 + (b > 9 ? 9 : b)]++;
      }
      for (int i = 0; i < 100; i++) ex[i] = n / 100.0;
      rc |= chi2_check(far ? "sphere light's cone from 100 radii, its own cells" : "sphere light's cone from 1.6 radii, its own cells", obs, ex, 100);
    }
    light_sampler_free(&ls);
  }
  scene_free(s);
  return rc;
}

static int light_sampling(void) {
  scene *s = scene_new("chi2");
  scene_reserve(s, 3, 1);
  s->pos[0] = v3(-1, 2, -1); s->pos[1] = v3(1.5f, 2, -0.5f); s->pos[2] = v3(0, 2.5f, 1.5f);
  s->nverts = 3;
  s->idx[0] = 0; s->idx[1] = 1; s->idx[2] = 2;
  s->tri_mat[0] = 0; s->tri_flags[0] = 0; s->ntris = 1;
  material m = material_default();
  m.emission = c3(1, 1, 1);
  CHECK(scene_add_material(s, &m) == 0, "material");
  light_ctx c = {s, {0}, v3(0.2f, 0.1f, 0.3f)};
  scene_area_light(s, 0, &c.l);
  c.l.L = c3(1, 1, 1); c.l.two_sided = 1;
  int rc = run_chi2("area light (triangle) from a point", &c, light_sf, light_pf);
  c.p = v3(0.1f, 1.9f, 0.0f); /* close: strongly varying density */
  rc |= run_chi2("area light (triangle) from a close point", &c, light_sf, light_pf);
  /* Both sample the solid angle uniformly (Arvo); far away, the triangle is sampled by
   * area instead (solid angle below 3e-4 sr). */
  {
    /* Far away: points uniform over the triangle (chi-square over barycentric cells: 45
     * squares and 10 diagonal halves of a 10x10 grid), with pdf = d^2 / (cos A). */
    vec3 pf = v3(0.3f, -120.0f, 0.2f);
    double obs[100] = {0}, ex[100] = {0};
    long n = nsamples() / 4;
    const uint32_t *ix = &s->idx[0];
    vec3 a = s->pos[ix[0]], e1 = v3_sub(s->pos[ix[1]], a), e2 = v3_sub(s->pos[ix[2]], a);
    double worst_pdf = 0;
    for (long k = 0; k < n; k++) {
      sampler sm = sampler_make(17, (uint64_t)k, 0);
      light_li li;
      float u1 = sampler_1d(&sm), u2 = sampler_1d(&sm);
      CHECK(light_sample(s, &c.l, pf, u1, u2, &li), "far area sample failed");
      vec3 q = v3_sub(li.p_light, a);
      float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2), q1 = v3_dot(q, e1), q2 = v3_dot(q, e2), den = d11 * d22 - d12 * d12;
      float b1 = (d22 * q1 - d12 * q2) / den, b2 = (d11 * q2 - d12 * q1) / den;
      int i = (int)(b1 * 10), j = (int)(b2 * 10);
      if (i > 9) i = 9;
      if (j > 9) j = 9;
      if (i + j > 9) { if (i > j) i = 9 - j; else j = 9 - i; }
      obs[i * 10 + j]++;
      double expect = light_pdf_area(&c.l, pf, li.p_light, li.n_light);
      double rel = fabs(li.pdf - expect) / expect;
      if (rel > worst_pdf) worst_pdf = rel;
    }
    for (int i = 0; i < 10; i++)
      for (int j = 0; j < 10; j++) ex[i * 10 + j] = i + j < 9 ? n * 0.02 : i + j == 9 ? n * 0.01 : 0;
    rc |= chi2_check("area light far away (sampled by area): points over the triangle", obs, ex, 100);
    fprintf(stderr, "far area light: sample pdf against light_pdf_area, worst relative difference %.2e\n", worst_pdf);
    CHECK(worst_pdf < 1e-3, "sample pdf and light_pdf_area disagree by %.2e", worst_pdf);
  }
  c.l.type = LIGHT_ENV;
  rc |= run_chi2("constant environment", &c, light_sf, light_pf);
  /* An equirectangular map with a bright spot, a dark hole and a gradient, upright,
   * turned by 30 degrees about y, turned any way (+y to +z, then 40 degrees about z: a
   * frame), and so with Mitsuba's rows (which move the lookups and the density with them). */
  for (int rot = 0; rot < 4; rot++) {
    int w = 64, h = 32;
    float *px = malloc(sizeof(float) * w * h * 3);
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++)
        for (int k = 0; k < 3; k++) {
          float v = 0.2f + (float)x / w + (y < h / 2 ? 0.5f : 0.0f);
          if (x >= 40 && x < 43 && y >= 10 && y < 12) v = 200;
          if (x >= 8 && x < 20 && y >= 20 && y < 26) v = 0;
          px[3 * (y * w + x) + k] = v * (k + 1) / 3.0f;
        }
    s->env_map = calloc(1, sizeof(envmap));
    CHECK(envmap_init(s->env_map, w, h, px, 1.0f, rot == 1 ? 30.0f : 0.0f) == 0, "envmap init");
    if (rot >= 2) {
      double ca = cos(40 * M_PI / 180), sa = sin(40 * M_PI / 180);
      const double fr[9] = {ca, 0, sa, sa, 0, -ca, 0, 1, 0}; /* Rz(40) Rx(90) */
      CHECK(envmap_set_frame(s->env_map, fr) == 0, "frame refused");
      CHECK(envmap_set_mitsuba_rows(s->env_map, rot == 3) == 0, "mitsuba rows");
    }
    static const char *const names[4] = {"environment map", "environment map, rotated 30 deg", "environment map, turned by a frame",
                                         "environment map, turned by a frame, Mitsuba's rows"};
    rc |= run_chi2(names[rot], &c, light_sf, light_pf);
    envmap_free(s->env_map);
    free(s->env_map);
    s->env_map = NULL;
  }
  scene_free(s);
  return rc;
}

/* ---- the piecewise-bilinear distribution that samples environment maps: points against
 * the density's integral over each of 48x48 bins (non-uniform vertices, zero cells, a
 * spike), each sample's pdf against bilin2d_pdf; then on a map with a one-texel lamp, the
 * ratio of radiance (largest channel) to density, which is what sets next-event
 * estimation's fireflies: at most 1.3x the map's integral (a piecewise-constant density
 * over 3x3 maxima gives 12x here). */
static double bilin_cell_mass(const bilin2d *d, double u0, double u1, double v0, double v1) {
  double m = 0;
  for (int a = 0; a < 24; a++)
    for (int b = 0; b < 24; b++)
      m += bilin2d_pdf(d, (float)(u0 + (u1 - u0) * (a + 0.5) / 24), (float)(v0 + (v1 - v0) * (b + 0.5) / 24));
  return m * (u1 - u0) * (v1 - v0) / (24 * 24);
}
static int bilinear_distribution(void) {
  const float xs[7] = {0, 0.05f, 0.2f, 0.5f, 0.55f, 0.9f, 1}, ys[5] = {0, 0.1f, 0.5f, 0.95f, 1};
  float f[35];
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 7; i++) f[j * 7 + i] = 0.3f + 0.4f * (float)((i * 5 + j * 3) % 7);
  for (int i = 0; i < 7; i++) f[1 * 7 + i] = 0; /* a whole row of zeros */
  f[2 * 7 + 4] = 40; /* a spike */
  f[4 * 7 + 6] = 0;
  bilin2d d;
  CHECK(bilin2d_init(&d, xs, 7, ys, 5, f) == 0, "init");
  enum { B = 48 };
  static double obs[B * B], ex[B * B];
  memset(obs, 0, sizeof obs);
  long n = nsamples();
  double worst = 0;
  for (long k = 0; k < n; k++) {
    sampler sm = sampler_make(11, (uint64_t)k, 0);
    float u, v, pdf, u1 = sampler_1d(&sm), u2 = sampler_1d(&sm);
    bilin2d_sample(&d, u1, u2, &u, &v, &pdf);
    CHECK(u >= 0 && u <= 1 && v >= 0 && v <= 1 && pdf > 0, "sample (%g, %g) pdf %g", u, v, pdf);
    double rel = fabs(pdf - bilin2d_pdf(&d, u, v)) / pdf;
    if (rel > worst) worst = rel;
    int bu = (int)(u * B), bv = (int)(v * B);
    obs[(bv < B ? bv : B - 1) * B + (bu < B ? bu : B - 1)] += 1;
  }
  for (int bv = 0; bv < B; bv++)
    for (int bu = 0; bu < B; bu++) ex[bv * B + bu] = n * bilin_cell_mass(&d, (double)bu / B, (double)(bu + 1) / B, (double)bv / B, (double)(bv + 1) / B);
  fprintf(stderr, "bilinear distribution: sample pdf against bilin2d_pdf, worst relative difference %.2e\n", worst);
  CHECK(worst < 1e-3, "sample pdf and bilin2d_pdf disagree by %.2e", worst);
  int rc = chi2_check("piecewise-bilinear 2D distribution", obs, ex, B * B);
  bilin2d_free(&d);
  /* L / pdf on a 64x32 map, uniform 0.05 with one texel at 5000 (and one at 500 on the seam). */
  int w = 64, h = 32;
  float *px = malloc(sizeof(float) * w * h * 3);
  for (int i = 0; i < w * h * 3; i++) px[i] = 0.05f;
  for (int c = 0; c < 3; c++) { px[3 * (12 * w + 40) + c] = 5000; px[3 * (20 * w + 63) + c] = 500; }
  for (int mr = 0; mr < 2; mr++) {
    envmap e;
    CHECK(envmap_init(&e, w, h, memcpy(malloc(sizeof(float) * w * h * 3), px, sizeof(float) * w * h * 3), 1, 0) == 0, "env init");
    CHECK(envmap_set_mitsuba_rows(&e, mr) == 0, "rows");
    double integral = 0, ratio = 0;
    int nu = 2048, nv = 1024;
    for (int b = 0; b < nv; b++)
      for (int a = 0; a < nu; a++) {
        double th = M_PI * (b + 0.5) / nv, ph = 2 * M_PI * (a + 0.5) / nu;
        vec3 dir = v3((float)(sin(th) * sin(ph)), (float)cos(th), (float)(-sin(th) * cos(ph)));
        double L = c3_max(envmap_eval(&e, dir)), p = envmap_pdf(&e, dir);
        integral += L * sin(th) * (M_PI / nv) * (2 * M_PI / nu);
        if (L > 0 && p > 0 && L / p > ratio) ratio = L / p;
      }
    fprintf(stderr, "environment map with a one-texel lamp%s: largest L/pdf is %.3f x its integral\n", mr ? " (Mitsuba's rows)" : "", ratio / integral);
    CHECK(ratio / integral < 1.3, "L/pdf reaches %.2f x the map's integral", ratio / integral);
    envmap_free(&e);
  }
  free(px);
  return rc;
}

/* ---- path guiding's directional quadtrees (guide.h): directions drawn from a leaf's
 * learned tree against guide_pdf, after two passes of records around three lobes (a
 * narrow one, so the tree refines many levels deep) and a hemisphere of dim light; and
 * the tree must have learned: the narrow lobe's cone gets far more than its solid angle. */
static int guide_sf(void *c, sampler *s, vec3 *dir) {
  float u1, u2, pdf;
  sampler_2d(s, &u1, &u2);
  *dir = guide_sample(c, 0, u1, u2, &pdf);
  return pdf > 0;
}
static double guide_pf(void *c, vec3 d) { return guide_pdf(c, 0, d); }
/* The light of the tests below: a dim upper half and three lobes (a narrow bright one). */
static const float lobe_widths[3] = {0.02f, 0.3f, 0.6f}, lobe_values[3] = {50, 5, 1};
static vec3 lobe_axis(int l) { return l == 0 ? v3_norm(v3(0.3f, 0.2f, 0.93f)) : l == 1 ? v3_norm(v3(-0.8f, 0.1f, -0.3f)) : v3(0, -1, 0); }
static float lobe_light(vec3 d) {
  float v = d.y > 0 ? 0.1f : 0;
  for (int l = 0; l < 3; l++)
    if (v3_dot(d, lobe_axis(l)) > 1 - lobe_widths[l]) v += lobe_values[l];
  return v;
}
/* A guide over the box [-1, 1]^3 whose fixed-point unit is 100. */
static int guide_for_test(guide *g) {
  bbox box = {v3(-1, -1, -1), v3(1, 1, 1)};
  if (guide_init(g, box, 1000000, 1e9) != 0) return -1;
  guide_set_scale(g, 100);
  return 0;
}

static int guide_quadtree(void) {
  guide g;
  CHECK(guide_for_test(&g) == 0, "init");
  const vec3 lobes[3] = {lobe_axis(0), lobe_axis(1), lobe_axis(2)};
  const float *widths = lobe_widths;
  for (int pass = 0; pass < 2; pass++) {
    for (int k = 0; k < 200000; k++) {
      sampler sm = sampler_make(21 + pass, (uint64_t)k, 0);
      float u1, u2;
      sampler_2d(&sm, &u1, &u2);
      vec3 d = sample_uniform_sphere(u1, u2);
      guide_record(&g, (gleaf *)guide_leaf(&g, v3(0.1f, 0.2f, 0.3f)), 0, d, lobe_light(d) * 4 * PI_F);
    }
    CHECK(guide_refine(&g) == 0, "refine");
  }
  const gleaf *l = guide_leaf(&g, v3(0.1f, 0.2f, 0.3f));
  CHECK(guide_can_sample(l, 0) && !guide_can_sample(l, 1), "nothing learned, or in the wrong bin");
  int rc = run_chi2("guide quadtree (learned from three lobes)", (void *)l, guide_sf, guide_pf);
  /* the narrow lobe: solid angle 2 pi 0.02 (0.32 % of the sphere), the recorded flux's
   * share 2 pi 0.02 50 over the total (about 38 %); its directions must be drawn often */
  long in = 0, n = 100000;
  for (long k = 0; k < n; k++) {
    sampler sm = sampler_make(5, (uint64_t)k, 0);
    vec3 d;
    guide_sf((void *)l, &sm, &d);
    in += v3_dot(d, lobes[0]) > 1 - widths[0];
  }
  fprintf(stderr, "guide quadtree: %.1f %% of directions in the narrow lobe (0.3 %% of the sphere)\n", 100.0 * in / n);
  CHECK(in > n / 10, "the narrow lobe got %.1f %% of the directions", 100.0 * in / n);
  guide_free(&g);
  return rc;
}

/* The learned BSDF fraction (guide_record_moments, chosen in guide_refine): a diffuse
 * surface facing +z under the three lobes above (bin 0) must keep the quadtree in its
 * mixture, and under uniform light (bin 1: cosine sampling of the BSDF is exact there)
 * must take fraction 1; vertices drawn from the mixture with fraction 1/2. */
static int guide_fraction_choice(void) {
  guide g;
  CHECK(guide_for_test(&g) == 0, "init");
  const vec3 at = v3(0.1f, 0.2f, 0.3f);
  for (int pass = 0; pass < 2; pass++) { /* the quadtrees: bin 0 the lobes, bin 1 uniform */
    for (int k = 0; k < 200000; k++) {
      sampler sm = sampler_make(31 + pass, (uint64_t)k, 0);
      float u1, u2;
      sampler_2d(&sm, &u1, &u2);
      vec3 d = sample_uniform_sphere(u1, u2);
      gleaf *l = (gleaf *)guide_leaf(&g, at);
      guide_record(&g, l, 0, d, lobe_light(d) * 4 * PI_F);
      guide_record(&g, l, 1, d, 4 * PI_F);
    }
    CHECK(guide_refine(&g) == 0, "refine");
  }
  const gleaf *l = guide_leaf(&g, at);
  CHECK(l->frac[0] < 0 && l->frac[1] < 0, "a fraction learned without moments");
  for (int k = 0; k < 100000; k++) {
    sampler sm = sampler_make(41, (uint64_t)k, 0);
    float ul = sampler_1d(&sm), u1, u2;
    sampler_2d(&sm, &u1, &u2);
    for (int b = 0; b < 2; b++) {
      vec3 d;
      float pg;
      if (ul < 0.5f) d = guide_sample(l, b, u1, u2, &pg);
      else { d = sample_cosine_hemisphere(u1, u2); pg = guide_pdf(l, b, d); }
      float pb = fmaxf(d.z, 0) * INV_PI_F, q = 0.5f * pb + 0.5f * pg, L = b ? 1 : lobe_light(d);
      double X = 0.8 * INV_PI_F * fmax(d.z, 0) * L / q;
      guide_record_moments(&g, (gleaf *)l, b, X / g.scale, q, pb, pg);
    }
  }
  CHECK(guide_refine(&g) == 0, "refine");
  l = guide_leaf(&g, at);
  fprintf(stderr, "guide fractions learned: lobes %.2f, uniform light %.2f\n", l->frac[0], l->frac[1]);
  CHECK(l->frac[0] >= 0 && l->frac[0] < 1, "under the lobes the quadtree was dropped (fraction %g)", l->frac[0]);
  CHECK(l->frac[1] == 1, "under uniform light the quadtree was kept (fraction %g)", l->frac[1]);
  CHECK(l->frac[2] < 0, "a bin without moments learned %g", l->frac[2]);
  guide_free(&g);
  return 0;
}

static int alias_table_chi2(void) {
  float w[7] = {1, 0, 3.5f, 0.01f, 7, 2, 0.5f};
  alias_table t;
  CHECK(alias_build(&t, w, 7) == 0, "build failed");
  double obs[7] = {0}, ex[7], sum = 0;
  for (int i = 0; i < 7; i++) sum += w[i];
  long n = nsamples();
  for (long i = 0; i < n; i++) {
    sampler s = sampler_make(5, (uint64_t)i, 0);
    float pmf;
    uint32_t k = alias_sample(&t, sampler_1d(&s), &pmf);
    CHECK(fabsf(pmf - w[k] / (float)sum) < 1e-6f, "pmf %g for %u", pmf, k);
    obs[k] += 1;
  }
  for (int i = 0; i < 7; i++) ex[i] = n * w[i] / sum;
  CHECK(obs[1] == 0, "a zero-weight entry was sampled");
  alias_free(&t);
  return chi2_check("alias table", obs, ex, 7);
}

/* The chi-square machinery itself must reject a wrong pdf (a test that cannot fail is a
 * defect): cosine samples checked against a uniform-hemisphere pdf. */
static double wrong_pf(void *c, vec3 d) { (void)c; return d.z > 0 ? 1 / (2 * M_PI) : 0; }
static int chi2_rejects_wrong_pdf(void) {
  material m = material_default();
  bsdf_ctx c = {.b = bsdf_from_material(&m), .wo = v3(0, 0, 1)};
  int rc = run_chi2("cosine samples vs uniform pdf (must fail)", &c, bsdf_sf, wrong_pf);
  CHECK(rc != 0, "chi-square accepted a wrong pdf");
  return 0;
}

/* ---- light selection: one-sided lights a point is behind are never picked; the others
 * are picked in proportion to power, as light_select_pmf says (chi-square). */
static int light_selection_facing(void) {
  scene *s = scene_new("select");
  scene_reserve(s, 6, 2);
  /* Triangle A faces +y, triangle B faces -y. */
  s->pos[0] = v3(0, 1, 0); s->pos[1] = v3(0, 1, 1); s->pos[2] = v3(1, 1, 0);
  s->pos[3] = v3(0, 1.5f, 0); s->pos[4] = v3(1, 1.5f, 0); s->pos[5] = v3(0, 1.5f, 1);
  s->nverts = 6;
  for (int k = 0; k < 6; k++) s->idx[k] = (uint32_t)k;
  s->tri_mat[0] = s->tri_mat[1] = 0; s->tri_flags[0] = s->tri_flags[1] = 0; s->ntris = 2;
  material m = material_default();
  m.emission = c3(2, 2, 2);
  CHECK(scene_add_material(s, &m) == 0, "material");
  light pt = {0};
  pt.type = LIGHT_POINT; pt.p = v3(3, 3, 3); pt.L = c3(1, 1, 1);
  CHECK(scene_add_light(s, &pt) == 0, "light");
  valo_error err;
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  light_sampler ls;
  CHECK(light_sampler_init(&ls, s, LIGHT_SELECT_GRID, 1) == 0, "init");
  /* Lights: [0] point, [1] A, [2] B (area lights are added at commit). */
  int ia = -1, ib = -1;
  for (uint32_t i = 0; i < s->nlights; i++)
    if (s->lights[i].type == LIGHT_AREA) { if (s->lights[i].tri == 0) ia = (int)i; else ib = (int)i; }
  CHECK(ia >= 0 && ib >= 0, "area lights missing");
  /* A's normal (0,0,1) x (1,0,0) = +y, B's (1,0,0) x (0,0,1) = -y: a point above both is
   * in front of A and behind B. */
  vec3 p = v3(0.2f, 1.7f, 0.2f);
  CHECK(light_select_pmf(&ls, s, (uint32_t)ib, p) == 0, "a light facing away has pmf %g", light_select_pmf(&ls, s, (uint32_t)ib, p));
  double total = 0, obs[3] = {0}, ex[3];
  for (uint32_t i = 0; i < s->nlights; i++) total += light_select_pmf(&ls, s, i, p);
  CHECK(fabs(total - 1) < 1e-5, "pmf sums to %g", total);
  long n = nsamples() / 10;
  for (long k = 0; k < n; k++) {
    sampler sm = sampler_make(3, (uint64_t)k, 0);
    float pmf;
    uint32_t li = light_select(&ls, s, p, sampler_1d(&sm), &pmf);
    CHECK(li < s->nlights, "no light picked");
    CHECK(fabsf(pmf - light_select_pmf(&ls, s, li, p)) < 1e-6f, "pmf mismatch");
    obs[li]++;
  }
  for (uint32_t i = 0; i < 3; i++) ex[i] = n * light_select_pmf(&ls, s, i, p);
  CHECK(obs[ib] == 0, "the light facing away was picked %g times", obs[ib]);
  double o2[2] = {obs[0], obs[ia]}, e2[2] = {ex[0], ex[ia]};
  int rc = chi2_check("light selection at a point (one light facing away)", o2, e2, 2);
  light_sampler_free(&ls);
  scene_free(s);
  return rc;
}

/* ns selections at p (sampler seed and stream): each must pick a light and report
 * light_select_pmf's pmf; counts added to obs. */
static int count_selections(const light_sampler *ls, const scene *s, vec3 p, long ns, uint64_t seed, uint64_t stream, double *obs) {
  for (long k = 0; k < ns; k++) {
    sampler sm = sampler_make(seed, (uint64_t)k, stream);
    float pmf;
    uint32_t li = light_select(ls, s, p, sampler_1d(&sm), &pmf);
    CHECK(li < s->nlights, "no light picked");
    CHECK(pmf == light_select_pmf(ls, s, li, p), "light %u: select says %g, pmf %g", li, pmf, light_select_pmf(ls, s, li, p));
    obs[li]++;
  }
  return 0;
}

/* ---- infinite lights (light.h): next-event estimation picks each of the n infinite
 * lights (the environment, a sun) with probability 1 / (n + 1), and the finite ones share
 * the rest by power (a bright lamp would get less than 1 % by the power rule here: the
 * environment's power grows with the scene's radius squared); photon and VPL tracing
 * (light_select_power) stay by power over all lights. Pmfs sum to 1, select agrees with
 * light_select_pmf, frequencies match (chi-square); with a black lamp, the infinite lights
 * take everything. */
static int light_selection_infinite(void) {
  int rc = 0;
  for (int black = 0; black < 2 && !rc; black++) {
    scene *s = scene_new("infinite");
    scene_reserve(s, 6, 2);
    s->pos[0] = v3(0, 1, 0); s->pos[1] = v3(0, 1, 1); s->pos[2] = v3(1, 1, 0);
    s->pos[3] = v3(-50, 0, -50); s->pos[4] = v3(50, 0, -50); s->pos[5] = v3(0, 0, 50); /* a big dark floor */
    s->nverts = 6;
    for (int k = 0; k < 6; k++) s->idx[k] = (uint32_t)k;
    s->tri_mat[0] = 0; s->tri_mat[1] = 1; s->tri_flags[0] = s->tri_flags[1] = 0; s->ntris = 2;
    material m = material_default();
    m.emission = black ? c3(0, 0, 0) : c3(20, 20, 20);
    CHECK(scene_add_material(s, &m) == 0, "material");
    material f = material_default();
    CHECK(scene_add_material(s, &f) == 1, "material");
    light pt = {0};
    pt.type = LIGHT_POINT; pt.p = v3(3, 3, 3); pt.L = black ? c3(0, 0, 0) : c3(1, 1, 1);
    CHECK(scene_add_light(s, &pt) == 0, "light");
    light sun = {0};
    sun.type = LIGHT_DIRECTIONAL; sun.dir = v3(0, -1, 0); sun.L = c3(2, 2, 2);
    CHECK(scene_add_light(s, &sun) == 0, "light");
    s->has_env = 1;
    s->env_radiance = c3(0.5f, 0.5f, 0.5f);
    valo_error err;
    CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
    light_sampler ls;
    CHECK(light_sampler_init(&ls, s, LIGHT_SELECT_GRID, 1) == 0, "init");
    uint32_t n = s->nlights;
    CHECK(n == (black ? 3u : 4u) && ls.ninf == 2, "%u lights, %u infinite", n, ls.ninf); /* a black lamp has no light */
    vec3 p = v3(0.2f, 1.7f, 0.2f);
    double total = 0, obs[4] = {0}, ex[4], pw_inf = 0, pw_all = 0;
    for (uint32_t i = 0; i < n; i++) {
      float pm = light_select_pmf(&ls, s, i, p);
      total += pm;
      int inf = s->lights[i].type == LIGHT_ENV || s->lights[i].type == LIGHT_DIRECTIONAL;
      float want = inf ? (black ? 0.5f : 1.0f / 3) : -1;
      CHECK(!inf || fabsf(pm - want) < 1e-6f, "infinite light %u: pmf %g, want %g", i, pm, want);
      CHECK(!black || inf || pm == 0, "black light %u: pmf %g", i, pm);
      pw_all += ls.power[i];
      if (inf) pw_inf += ls.power[i];
    }
    CHECK(fabs(total - 1) < 1e-5, "pmfs sum to %g", total);
    CHECK(black || pw_inf / pw_all > 0.99, "the power rule would give the infinite lights only %.3f", pw_inf / pw_all);
    long ns = nsamples() / 10;
    CHECK(count_selections(&ls, s, p, ns, 5, (uint64_t)black, obs) == 0, "selection");
    double o[4], e[4];
    int m2 = 0;
    for (uint32_t i = 0; i < n; i++) {
      ex[i] = ns * light_select_pmf(&ls, s, i, p);
      if (ex[i] > 0) { o[m2] = obs[i]; e[m2++] = ex[i]; } else CHECK(obs[i] == 0, "light %u of pmf 0 picked %g times", i, obs[i]);
    }
    rc = chi2_check(black ? "light selection, infinite lights and black lamps" : "light selection with infinite lights", o, e, m2);
    /* light tracing keeps the power rule */
    for (int k = 0; k < 64 && !rc; k++) {
      float pmf;
      uint32_t li = light_select_power(&ls, (k + 0.5f) / 64, &pmf);
      CHECK(li < n && fabsf(pmf - ls.power[li] / (float)pw_all) < 1e-5f * pmf + 1e-9f, "light tracing: light %u pmf %g, power share %g", li, pmf,
            ls.power[li] / pw_all);
    }
    light_sampler_free(&ls);
    scene_free(s);
  }
  return rc;
}

static float u01(uint64_t *st) {
  uint64_t z = (*st += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return (float)((z ^ (z >> 31)) >> 40) * 0x1p-24f;
}

/* ---- the light grid (light.h): 300 one-sided emissive triangles of varied size, facing
 * and power scattered through a 10 m box, a point light and a directional light. At
 * points in the box: the pmfs sum to 1, every light keeps at least the power share's
 * fraction LIGHT_GRID_POWER (so nothing that can reach the point is starved), the
 * choice light_select reports is light_select_pmf's, frequencies match the pmfs
 * (chi-square), and the nearest lamp is picked far more often than by power. */
static int light_grid_selection(void) {
  const int nt = 300;
  scene *s = scene_new("grid");
  CHECK(scene_reserve(s, 3 * nt, nt) == 0, "reserve");
  uint64_t st = 12345;
  for (int t = 0; t < nt; t++) {
    vec3 c = v3(10 * u01(&st), 10 * u01(&st), 10 * u01(&st));
    for (int k = 0; k < 3; k++)
      s->pos[3 * t + k] = v3_add(c, v3(0.3f * (u01(&st) - 0.5f), 0.3f * (u01(&st) - 0.5f), 0.3f * (u01(&st) - 0.5f)));
    for (int k = 0; k < 3; k++) s->idx[3 * t + k] = (uint32_t)(3 * t + k);
    s->tri_mat[t] = (uint32_t)(t % 3);
    s->tri_flags[t] = 0;
  }
  s->nverts = 3 * nt;
  s->ntris = nt;
  for (int k = 0; k < 3; k++) {
    material m = material_default();
    m.emission = c3(1.0f + 4 * k, 2, 1);
    CHECK(scene_add_material(s, &m) == (uint32_t)k, "material");
  }
  light pt = {0};
  pt.type = LIGHT_POINT; pt.p = v3(5, 5, 5); pt.L = c3(3, 3, 3);
  CHECK(scene_add_light(s, &pt) == 0, "light");
  light sun = {0};
  sun.type = LIGHT_DIRECTIONAL; sun.dir = v3(0, -1, 0); sun.L = c3(0.5f, 0.5f, 0.5f);
  CHECK(scene_add_light(s, &sun) == 0, "light");
  valo_error err;
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  light_sampler ls, lp;
  CHECK(light_sampler_init(&ls, s, LIGHT_SELECT_GRID, 1) == 0 && ls.grid_cdf, "grid not built");
  CHECK(light_sampler_init(&lp, s, LIGHT_SELECT_POWER, 1) == 0 && !lp.grid_cdf, "power selection built a grid");
  uint32_t n = s->nlights;
  double *obs = calloc(n, sizeof *obs), *ex = calloc(n, sizeof *ex);
  int rc = 0;
  for (int q = 0; q < 4 && !rc; q++) {
    vec3 p = v3(10 * u01(&st), 10 * u01(&st), 10 * u01(&st));
    double total = 0;
    uint32_t nearest = 0;
    float dmin = INFINITY;
    for (uint32_t i = 0; i < n; i++) {
      float pg = light_select_pmf(&ls, s, i, p), pp = light_select_pmf(&lp, s, i, p);
      total += pg;
      CHECK(pg >= LIGHT_GRID_POWER * pp * (1 - 1e-5f), "light %u: pmf %g below the power share's %g", i, pg, LIGHT_GRID_POWER * pp);
      const light *l = &s->lights[i];
      if (l->type == LIGHT_AREA) {
        const uint32_t *ix = &s->idx[3 * l->tri];
        vec3 cen = v3_scale(v3_add(v3_add(s->pos[ix[0]], s->pos[ix[1]]), s->pos[ix[2]]), 1.0f / 3);
        float d = v3_len(v3_sub(cen, p));
        if (d < dmin && v3_dot(scene_tri_ng(s, l->tri), v3_sub(p, cen)) > 0) { dmin = d; nearest = i; }
      }
    }
    CHECK(fabs(total - 1) < 1e-4, "pmfs sum to %g", total);
    for (uint32_t i = 0; i < n; i++) /* the only infinite light: half of the choice */
      CHECK(s->lights[i].type != LIGHT_DIRECTIONAL || light_select_pmf(&ls, s, i, p) == 0.5f, "the sun's pmf %g, not 1/2",
            light_select_pmf(&ls, s, i, p));
    /* lamps whose back faces the whole cell around p (p behind their plane by more than
     * the cell's diagonal) get the power share alone: the grid's own part is 0, up to the
     * rounding of its float running sums (two ulps of 1) */
    int behind = 0;
    float diag = v3_len(v3(1 / ls.ginv.x, 1 / ls.ginv.y, 1 / ls.ginv.z));
    for (uint32_t i = 0; i < n; i++) {
      const light *l = &s->lights[i];
      if (l->type != LIGHT_AREA || l->two_sided) continue;
      const uint32_t *ix = &s->idx[3 * l->tri];
      if (v3_dot(v3_norm(scene_tri_ng(s, l->tri)), v3_sub(p, s->pos[ix[0]])) > -diag) continue;
      behind++;
      float pg = light_select_pmf(&ls, s, i, p), pp = light_select_pmf(&lp, s, i, p);
      CHECK(fabsf(pg - LIGHT_GRID_POWER * pp) <= (1 - LIGHT_GRID_POWER) * 2 * FLT_EPSILON, "light %u behind the cell: pmf %g, power share %g", i, pg,
            LIGHT_GRID_POWER * pp);
    }
    CHECK(behind > 10, "only %d lamps behind the cell", behind);
    double gain = light_select_pmf(&ls, s, nearest, p) / light_select_pmf(&lp, s, nearest, p);
    CHECK(gain > 5, "the nearest lamp facing the point (%.2f m) is picked only %.2f times as often as by power", dmin, gain);
    memset(obs, 0, n * sizeof *obs);
    long ns = nsamples();
    CHECK(count_selections(&ls, s, p, ns, 7, (uint64_t)q, obs) == 0, "selection");
    for (uint32_t i = 0; i < n; i++) ex[i] = ns * light_select_pmf(&ls, s, i, p);
    fprintf(stderr, "point %d: nearest lamp %.2f m, picked %.1fx as often as by power\n", q, dmin, gain);
    rc = chi2_check("light grid selection", obs, ex, (int)n);
  }
  free(obs); free(ex);
  light_sampler_free(&ls);
  light_sampler_free(&lp);
  scene_free(s);
  return rc;
}

/* ---- the Sobol sampler (core/rng.h): a pixel's first 2^k samples are stratified in
 * every dimension (1D: one per interval of 2^-k; 2D: one in every elementary interval of
 * area 2^-k, a (0,k,2)-net), and across pixels each sample is uniformly distributed (so
 * estimators stay unbiased): chi-square over 1D and 2D bins. */
static int sobol_sampler(void) {
  for (int pix = 0; pix < 32; pix++)
    for (uint32_t dim = 0; dim < 24; dim++)
      for (int logn = 4; logn <= 8; logn += 2) {
        int n = 1 << logn;
        int one[256] = {0};
        static int two[9][256];
        memset(two, 0, sizeof two);
        for (int i = 0; i < n; i++) {
          sampler a = sampler_make_kind(99, (uint64_t)pix, (uint64_t)i, SAMPLER_SOBOL), b = a;
          sampler_set_dim(&a, dim);
          sampler_set_dim(&b, dim);
          float x = sampler_1d(&a), u, v;
          sampler_2d(&b, &u, &v);
          CHECK(x >= 0 && x < 1 && u >= 0 && u < 1 && v >= 0 && v < 1, "value out of [0,1)");
          one[(int)(x * n)]++;
          for (int ax = 0; ax <= logn; ax++) {
            int bx = (int)(u * (1 << ax)), by = (int)(v * (1 << (logn - ax)));
            two[ax][(bx << (logn - ax)) + by]++;
          }
        }
        for (int k = 0; k < n; k++) {
          CHECK(one[k] == 1, "pixel %d dim %u: 1D interval %d of %d holds %d samples", pix, dim, k, n, one[k]);
          for (int ax = 0; ax <= logn; ax++)
            CHECK(two[ax][k] == 1, "pixel %d dim %u: 2D elementary interval %d (%dx%d) of %d samples holds %d", pix, dim, k, 1 << ax,
                  1 << (logn - ax), n, two[ax][k]);
        }
      }
  /* Uniform across pixels, at a few sample indices and dimensions. */
  int rc = 0;
  long np = nsamples() / 5;
  double obs1[100], exp1[100], obs2[256], exp2[256];
  static const uint32_t idxs[3] = {0, 5, 1000}, dims[3] = {0, 7, 40};
  for (int t = 0; t < 3; t++) {
    for (int k = 0; k < 100; k++) { obs1[k] = 0; exp1[k] = np / 100.0; }
    for (int k = 0; k < 256; k++) { obs2[k] = 0; exp2[k] = np / 256.0; }
    for (long pix = 0; pix < np; pix++) {
      sampler a = sampler_make_kind(7, (uint64_t)pix, idxs[t], SAMPLER_SOBOL), b = a;
      sampler_set_dim(&a, dims[t]);
      sampler_set_dim(&b, dims[t] + 1);
      obs1[(int)(sampler_1d(&a) * 100)]++;
      float u, v;
      sampler_2d(&b, &u, &v);
      obs2[(int)(u * 16) * 16 + (int)(v * 16)]++;
    }
    char what[96];
    snprintf(what, sizeof what, "Sobol 1D, sample %u, dimension %u, over pixels", idxs[t], dims[t]);
    rc |= chi2_check(what, obs1, exp1, 100);
    snprintf(what, sizeof what, "Sobol 2D, sample %u, dimension %u, over pixels", idxs[t], dims[t] + 1);
    rc |= chi2_check(what, obs2, exp2, 256);
  }
  return rc;
}

/* The pixel filters' offsets (pixel_filter_sample) against their density
 * (pixel_filter_pdf): 64 cells over [-radius, radius], each cell's expectation integrated
 * from the density (Simpson, 64 steps); nothing outside. The density integrates to 1, and
 * the tabulated filters' |filter| stays within 0.2 % of its peak of the continuous ones
 * (or within half a bin's rise at the steepest slope, which the cubics pass)
 * (Mitsuba's Gaussian; Cycles' Blackman-Harris, filter_func_blackman_harris over twice
 * its width; Mitchell and Netravali's cubics at B = C = 1/3 and B = 0, C = 1/2 written out;
 * Lanczos' sinc(x) sinc(x/r)). With negative lobes, each sample's weight is the sign of
 * the continuous filter there (but within a bin of its zeros) times integral |f| /
 * integral f, and the weights average to 1 (within 4 standard errors). */
static double continuous_filter(filter_kind kind, double x, double r) {
  double t = fabs(2 * x / r), sx = M_PI * x;
  if (kind == FILTER_MITCHELL) return t < 1 ? (7 * t * t * t - 12 * t * t + 16.0 / 3) / 6 : t < 2 ? (-7.0 / 3 * t * t * t + 12 * t * t - 20 * t + 32.0 / 3) / 6 : 0;
  if (kind == FILTER_CATMULL_ROM) return t < 1 ? 1.5 * t * t * t - 2.5 * t * t + 1 : t < 2 ? -0.5 * t * t * t + 2.5 * t * t - 4 * t + 2 : 0;
  if (kind == FILTER_LANCZOS) return x == 0 ? 1 : sin(sx) / sx * sin(sx / r) / (sx / r);
  if (kind == FILTER_GAUSSIAN) {
    double sd = r / 4, a = -1 / (2 * sd * sd);
    return exp(a * x * x) - exp(a * r * r);
  }
  double v = 2 * M_PI * (x / (2 * r) + 0.5);
  return 0.35875 - 0.48829 * cos(v) + 0.14128 * cos(2 * v) - 0.01168 * cos(3 * v);
}
static int pixel_filters(void) {
  static const struct { const char *name; double radius; } fs[] = {{"box", 0}, {"box", 1.5}, {"tent", 0}, {"gaussian", 0}, {"gaussian", 1.5}, {"blackman-harris", 0},
                                                                      {"mitchell", 0}, {"mitchell", 1.5}, {"catmull-rom", 0}, {"lanczos", 0}, {"lanczos", 2}};
  int rc = 0;
  for (size_t k = 0; k < sizeof fs / sizeof fs[0]; k++) {
    pixel_filter f;
    CHECK(pixel_filter_make(&f, fs[k].name, fs[k].radius) == 0, "%s", fs[k].name);
    enum { CELLS = 64 };
    double r = f.radius, obs[CELLS] = {0}, ex[CELLS], total = 0;
    long n = nsamples(), outside = 0, wrong_sign = 0;
    double abs_int = 0, signed_int = 0, wsum = 0, wsq = 0;
    for (int j = 0; j < 20000; j++) {
      double v = continuous_filter(f.kind, -r + (j + 0.5) * 2 * r / 20000, r);
      abs_int += fabs(v);
      signed_int += v;
    }
    double want_w = abs_int / signed_int;
    for (long i = 0; i < n; i++) {
      sampler s = sampler_make(9, (uint64_t)i, k);
      float w;
      double x = pixel_filter_sample(&f, sampler_1d(&s), &w);
      wsum += w;
      wsq += (double)w * w;
      double v = continuous_filter(f.kind, x, r), bin = 2 * r / FILTER_BINS;
      int near_zero = continuous_filter(f.kind, x - bin, r) * continuous_filter(f.kind, x + bin, r) <= 0;
      if (!near_zero && fabs(w - (v < 0 ? -want_w : want_w)) > 2e-3 * want_w) wrong_sign++;
      int c = (int)floor((x + r) / (2 * r) * CELLS);
      if (c < 0 || c >= CELLS) { outside++; continue; }
      obs[c] += 1;
    }
    for (int c = 0; c < CELLS; c++) {
      double a = -r + 2 * r * c / CELLS, h = 2 * r / CELLS / 64, sum = 0;
      for (int j = 0; j <= 64; j++) sum += (j == 0 || j == 64 ? 1 : j % 2 ? 4 : 2) * pixel_filter_pdf(&f, (float)(a + j * h));
      ex[c] = sum * h / 3;
      total += ex[c];
      ex[c] *= n;
    }
    CHECK(outside == 0, "%s: %ld offsets beyond the radius", fs[k].name, outside);
    CHECK(fabs(total - 1) < 2e-3, "%s: the density integrates to %g", fs[k].name, total);
    double mean_w = wsum / n, se = sqrt(fmax(wsq / n - mean_w * mean_w, 0) / n);
    CHECK(wrong_sign == 0, "%s: %ld samples' weights are not sign(filter) x %g", fs[k].name, wrong_sign, want_w);
    CHECK(fabs(mean_w - 1) <= 4 * se + 1e-6, "%s: the weights average %g (standard error %g)", fs[k].name, mean_w, se);
    if (f.kind != FILTER_BOX && f.kind != FILTER_TENT) {
      double norm = 0, worst = 0;
      for (int j = 0; j < 4096; j++) norm += fabs(continuous_filter(f.kind, -r + (j + 0.5) * 2 * r / 4096, r)) * 2 * r / 4096;
      for (int j = 0; j < 4096; j++) {
        double x = -r + (j + 0.5) * 2 * r / 4096;
        worst = fmax(worst, fabs(pixel_filter_pdf(&f, (float)x) - fabs(continuous_filter(f.kind, x, r)) / norm));
      }
      /* a bin's step is at most half a bin times the steepest slope (the cubics' is 1.4 per pixel) */
      double slope = 0, bin = 2 * r / FILTER_BINS;
      for (int j = 0; j < 4096; j++) {
        double x = -r + (j + 0.5) * 2 * r / 4096;
        slope = fmax(slope, fabs(continuous_filter(f.kind, x + 1e-4, r) - continuous_filter(f.kind, x - 1e-4, r)) / 2e-4);
      }
      CHECK(worst < fmax(2e-3 * continuous_filter(f.kind, 0, r), 0.55 * slope * bin) / norm, "%s: the table is %g from the continuous filter", fs[k].name, worst);
    }
    char what[64];
    snprintf(what, sizeof what, "pixel filter %s, radius %.2f", fs[k].name, r);
    rc |= chi2_check(what, obs, ex, CELLS);
  }
  return rc;
}

/* ---- participating media */
/* The Henyey-Greenstein phase function: samples against its density for forward,
 * backward and isotropic lobes around an oblique wo; each sample's pdf must be the
 * phase value (its weight 1). */
typedef struct phase_ctx { float g; vec3 wo; } phase_ctx;
static int phase_sf(void *c, sampler *s, vec3 *d) {
  phase_ctx *x = c;
  float u1 = sampler_1d(s), u2 = sampler_1d(s);
  float pdf = phase_hg_sample(x->wo, x->g, u1, u2, d);
  float want = phase_hg(v3_dot(x->wo, *d), x->g);
  if (!(fabsf(pdf - want) <= 1e-3f * want + 1e-6f)) g_sample_mismatch++;
  return 1;
}
static double phase_pf(void *c, vec3 d) { phase_ctx *x = c; return phase_hg(v3_dot(x->wo, v3_norm(d)), x->g); }
static int hg_phase(void) {
  static const float gs[] = {0, 0.3f, -0.6f, 0.9f};
  int rc = 0;
  for (int k = 0; k < 4; k++) {
    phase_ctx c = {gs[k], v3_norm(v3(0.3f, -0.5f, 0.8f))};
    char what[64];
    snprintf(what, sizeof what, "Henyey-Greenstein g = %.1f", (double)gs[k]);
    rc |= run_chi2(what, &c, phase_sf, phase_pf);
  }
  return rc;
}
/* Free-flight distances (medium_sample_distance): in a grey medium the distances up to a
 * surface at tmax against sigma_t exp(-sigma_t t), and the surface's share against
 * exp(-sigma_t tmax); in a chromatic one, per channel, the weights' means against
 * transmittance to the surface and 1 - that (the probability of an event before it):
 * picking the channel uniformly or by a throughput, with MIS, must be unbiased for every
 * channel. */
static int free_flight(void) {
  enum { CELLS = 64 };
  const float tmax = 1.5f;
  medium grey = {c3(0.4f, 0.4f, 0.4f), c3(0.8f, 0.8f, 0.8f), 0, NULL, {0, 0, 0}, "grey"};
  mcoef greyc = medium_coef(&grey, NULL);
  double obs[CELLS + 1] = {0}, ex[CELLS + 1];
  long n = nsamples();
  double st = 1.2;
  for (long i = 0; i < n; i++) {
    sampler s = sampler_make(17, (uint64_t)i, 0);
    float uc = sampler_1d(&s), ud = sampler_1d(&s), t;
    spec4 w, trp;
    if (medium_sample_distance(&greyc, NULL, uc, ud, tmax, &t, &w, &trp)) {
      int c = (int)(t / tmax * CELLS);
      obs[c < CELLS ? c : CELLS - 1] += 1;
      CHECK(fabsf(w.v[0] - 0.8f / 1.2f) < 1e-5f, "grey event weight %g, want albedo %g", (double)w.v[0], 0.8 / 1.2);
    } else {
      obs[CELLS] += 1;
      CHECK(fabsf(w.v[0] - 1) < 1e-5f, "grey surface weight %g, want 1", (double)w.v[0]);
    }
  }
  for (int c = 0; c < CELLS; c++) ex[c] = n * (exp(-st * tmax * c / CELLS) - exp(-st * tmax * (c + 1) / CELLS));
  ex[CELLS] = n * exp(-st * tmax);
  int rc = chi2_check("free-flight distances, grey medium", obs, ex, CELLS + 1);

  medium col = {c3(0.1f, 0.5f, 0.0f), c3(0.4f, 1.5f, 3.0f), 0, NULL, {0, 0, 0}, "col"};
  mcoef colc = medium_coef(&col, NULL);
  rgb sig_t = c3_add(col.sigma_a, col.sigma_s);
  /* the channel chosen uniformly, and in proportion to a throughput sel */
  static const spec4 sels[2] = {{{1, 1, 1, 0}}, {{0.2f, 1, 3, 0}}};
  for (int v = 0; v < 2; v++) {
    double pass[3] = {0}, event[3] = {0}, pass2[3] = {0}, event2[3] = {0};
    for (long i = 0; i < n; i++) {
      sampler s = sampler_make(18 + v, (uint64_t)i, 0);
      float uc = sampler_1d(&s), ud = sampler_1d(&s), t;
      spec4 w, trp;
      int ev = medium_sample_distance(&colc, v ? &sels[v] : NULL, uc, ud, tmax, &t, &w, &trp);
      float wv[3] = {w.v[0], w.v[1], w.v[2]}, sa[3] = {col.sigma_s.r, col.sigma_s.g, col.sigma_s.b}, stv[3] = {sig_t.r, sig_t.g, sig_t.b};
      for (int c = 0; c < 3; c++) {
        /* an event's weight sigma_s Tr / pdf, times sigma_t / sigma_s, estimates P(event) */
        double x = ev ? wv[c] * stv[c] / sa[c] : wv[c];
        double *acc = ev ? event : pass, *acc2 = ev ? event2 : pass2;
        acc[c] += x;
        acc2[c] += x * x;
      }
    }
    for (int c = 0; c < 3; c++) {
      double stc = c == 0 ? sig_t.r : c == 1 ? sig_t.g : sig_t.b, tr = exp(-stc * tmax);
      double mp = pass[c] / n, me = event[c] / n;
      double sp = sqrt((pass2[c] / n - mp * mp) / n), se = sqrt((event2[c] / n - me * me) / n);
      fprintf(stderr, "free flight (%s), channel %d: surface %.5f (want %.5f, sd %.5f), events %.5f (want %.5f, sd %.5f)\n",
              v ? "by throughput" : "uniform", c, mp, tr, sp, me, 1 - tr, se);
      CHECK(fabs(mp - tr) < 5 * sp + 1e-6, "channel %d: surface weight mean %g, transmittance %g", c, mp, tr);
      CHECK(fabs(me - (1 - tr)) < 5 * se + 1e-6, "channel %d: event weight mean %g, want %g", c, me, 1 - tr);
    }
  }
  return rc;
}

/* Light selection with emitting spheres as units (light.h): 40 small lamps of 20
 * triangles and one of 80, two lone triangles and a point light; in the grid, by power
 * alone and for light tracing (light_select_power), at three points: the pmfs sum to 1,
 * each sphere's lights sum to its light_range_pmf, the light reported is light_select_pmf's,
 * and the frequencies of the units and of the large sphere's triangles (drawn within its
 * unit from the number left of the unit's choice) match the pmfs (chi-square); the grid
 * holds a sum per unit (42), not per light (881). */
static int light_units(void) {
  scene *s = scene_new("chi2-units");
  material m = material_default();
  m.emission = c3(1, 0.8f, 0.6f);
  uint32_t mi = scene_add_material(s, &m);
  m.emission = c3(40, 40, 40);
  uint32_t hot = scene_add_material(s, &m);
  valo_error err;
  uint64_t st = 777;
  for (int i = 0; i < 40; i++) {
    float x = 8 * u01(&st), y = 8 * u01(&st), z = 8 * u01(&st), r = 0.05f + 0.2f * u01(&st);
    CHECK(scene_add_sphere(s, v3(x, y, z), r, 0, 0, 1, i % 3 ? mi : hot, &err) == VALO_OK, "%s", err.message);
  }
  CHECK(scene_add_sphere(s, v3(4, 4, 4), 0.7f, 1, 0, 1, mi, &err) == VALO_OK, "%s", err.message);
  light pt = {0};
  pt.type = LIGHT_POINT; pt.p = v3(1, 7, 2); pt.L = c3(30, 30, 30);
  CHECK(scene_add_light(s, &pt) == 0, "light");
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  const sphere_shape *big = &s->spheres[40];
  CHECK(s->nlights == 40 * 20 + 80 + 1 && big->l1 - big->l0 == 80, "%u lights", s->nlights);
  int rc = 0;
  for (int mode = 0; mode < 3 && !rc; mode++) {
    light_sampler ls;
    CHECK(light_sampler_init(&ls, s, mode == 0 ? LIGHT_SELECT_GRID : LIGHT_SELECT_POWER, 1) == 0 && ls.unit0 && ls.nu == 42, "%u units", ls.nu);
    CHECK(mode != 0 || ls.grid_cdf, "no grid");
    for (int q = 0; q < 3 && !rc; q++) {
      vec3 p = q == 0 ? v3(4, 5.2f, 4) : q == 1 ? v3(0.5f, 0.5f, 7) : v3(6, 2, 1);
      double all = 0;
      for (uint32_t i = 0; i < s->nlights; i++) all += mode == 2 ? 0 : light_select_pmf(&ls, s, i, p);
      CHECK(mode == 2 || fabs(all - 1) < 1e-4, "pmfs sum to %.6f", all);
      for (uint32_t g = 0; g < s->nspheres && mode != 2; g++) {
        double sum = 0;
        for (uint32_t i = s->spheres[g].l0; i < s->spheres[g].l1; i++) sum += light_select_pmf(&ls, s, i, p);
        double r = light_range_pmf(&ls, s->spheres[g].l0, s->spheres[g].l1, p);
        CHECK(fabs(r - sum) < 1e-5 * fmax(r, 1e-3) + 1e-7, "sphere %u: range pmf %.7g, its lights' %.7g", g, r, sum);
      }
      long n = nsamples();
      double *obs = calloc(42 + 80, sizeof *obs), *ex = calloc(42 + 80, sizeof *ex);
      CHECK(obs && ex, "memory");
      double pu[42] = {0};
      light_site at = light_locate(&ls, p);
      for (long k = 0; k < n; k++) {
        sampler sm = sampler_make(31 + mode * 7 + q, (uint64_t)k, 0);
        float pmf, u = sampler_1d(&sm);
        uint32_t li = mode == 2 ? light_select_power(&ls, u, &pmf) : light_select_at(&ls, s, &at, u, &pmf);
        CHECK(li < s->nlights, "no light");
        float want = mode == 2 ? pmf : light_select_pmf(&ls, s, li, p);
        CHECK(pmf == want, "light %u: select says %g, pmf %g", li, pmf, want);
        if (mode != 2) { /* next-event estimation's choice: the same unit, a sphere whole */
          light_cone kc, kl;
          float cpmf;
          uint32_t lc = light_select_cone(&ls, s, p, u, &cpmf, &kc), un = ls.unit_of[li];
          if (light_sphere_at(&ls, s, li, p, &kl)) {
            uint32_t l0 = kl.sp->l0, l1 = kl.sp->l1;
            CHECK(kc.sp == kl.sp && lc == l0 && cpmf == light_range_pmf(&ls, l0, l1, p) && ls.unit0[un] == l0,
                  "light %u: the cone's choice is light %u, pmf %g", li, lc, cpmf);
          } else
            CHECK(!kc.sp && lc == li && cpmf == pmf, "light %u: the cone's choice is light %u, pmf %g", li, lc, cpmf);
        }
        obs[ls.unit_of[li]]++;
        if (li >= big->l0 && li < big->l1) obs[42 + li - big->l0]++;
      }
      for (uint32_t u = 0; u < 42; u++) {
        uint32_t l0 = ls.unit0[u], l1 = ls.unit0[u + 1];
        for (uint32_t i = l0; i < l1; i++)
          pu[u] += mode == 2 ? (double)ls.table.bins[u].p * ls.power[i] / ls.upower[u] : light_select_pmf(&ls, s, i, p);
        ex[u] = n * pu[u];
      }
      uint32_t ub = ls.unit_of[big->l0];
      for (uint32_t i = 0; i < 80; i++) ex[42 + i] = obs[ub] * ls.power[big->l0 + i] / ls.upower[ub];
      char what[96];
      snprintf(what, sizeof what, "%s at point %d: units", mode == 0 ? "grid" : mode == 1 ? "power" : "light tracing", q);
      rc |= chi2_check(what, obs, ex, 42);
      snprintf(what, sizeof what, "%s at point %d: the large sphere's triangles", mode == 0 ? "grid" : mode == 1 ? "power" : "light tracing", q);
      rc |= chi2_check(what, obs + 42, ex + 42, 80);
      free(obs);
      free(ex);
    }
    light_sampler_free(&ls);
  }
  scene_free(s);
  return rc;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"diffuse", diffuse},
                                    {"phong", phong},
                                    {"mirror_mixture", mirror_mixture},
                                    {"energy_conservation", energy_conservation},
                                    {"delta_lobes", delta_lobes},
                                    {"light_sampling", light_sampling}, {"sphere_cone", sphere_cone},
                                    {"alias_table", alias_table_chi2},
                                    {"bilinear_distribution", bilinear_distribution},
                                    {"guide_quadtree", guide_quadtree},
                                    {"guide_fraction_choice", guide_fraction_choice},
                                    {"chi2_rejects_wrong_pdf", chi2_rejects_wrong_pdf},
                                    {"rough_conductor", rough_conductor},
                                    {"rough_dielectric", rough_dielectric},
                                    {"microfacet_furnace", microfacet_furnace}, {"ggx_albedo", ggx_albedo}, {"bsdf_reciprocity", bsdf_reciprocity},
                                    {"pbr_metallic_roughness", pbr_metallic_roughness}, {"pbr_sheen", pbr_sheen}, {"plastic", plastic}, {"principled", principled},
                                    {"sobol_sampler", sobol_sampler},
                                    {"blend_mixture", blend_mixture}, {"light_selection_facing", light_selection_facing}, {"light_selection_infinite", light_selection_infinite}, {"light_grid_selection", light_grid_selection}, {"light_units", light_units},
                                    {"pixel_filters", pixel_filters}, {"hg_phase", hg_phase}, {"free_flight", free_flight}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
