/* light.c — owns sampling each kind of light (area, point, spot, directional, environment):
 * its radiance, power, sampled directions and their densities, emission for light tracing
 * (see light.h; choosing a light is light_select.c). */
#include "light/light.h"
#include "core/sampling.h"
#include "scene/envmap.h"
#include "image/texture.h"
#include <stdlib.h>
#include <string.h>

/* L times the emission map tex_ke (if any) at (u, v). */
static rgb emission_mapped(const scene *s, rgb L, int tex_ke, float u, float v) {
  if (tex_ke < 0 || c3_black(L)) return L;
  float px[4];
  texture_lookup(&s->tex[tex_ke], u, v, px);
  return c3_mul(L, c3(px[0], px[1], px[2]));
}

rgb light_area_radiance(const scene *s, const light *l, vec3 ng, vec3 w, float u, float v) {
  return emission_mapped(s, light_area_emitted(l, ng, w), l->tex_ke, u, v);
}

rgb light_tri_radiance(const scene *s, uint32_t tri, vec3 ng, vec3 w, float u, float v) {
  const material *m = &s->mats[s->tri_mat[tri]];
  float c = v3_dot(ng, w);
  return emission_mapped(s, (c > 0 || (m->two_sided && c < 0)) ? m->emission : c3(0, 0, 0), m->tex_ke, u, v);
}

static void area_uv_at(const scene *s, const light *l, vec3 pl, float *tu, float *tv);
/* Is p inside light l's triangle (p in its plane)? */
static int inside_light(const light *l, vec3 p) {
  vec3 e0 = v3_sub(l->v[1], l->v[0]), e1 = v3_sub(l->v[2], l->v[0]), q = v3_sub(p, l->v[0]);
  float n2 = v3_len2(l->ng);
  float b1 = v3_dot(v3_cross(q, e1), l->ng) / n2, b2 = v3_dot(v3_cross(e0, q), l->ng) / n2;
  return b1 >= 0 && b2 >= 0 && b1 + b2 <= 1;
}
/* The first light in the scene's order among li and the lights it overlaps that holds p. */
static uint32_t light_seen_at(const scene *s, uint32_t li, vec3 p) {
  uint32_t seen = li;
  if (!s->light_ov0) return li;
  for (uint32_t k = s->light_ov0[li]; k < s->light_ov0[li + 1]; k++) {
    uint32_t j = s->light_ov[k];
    if (j < seen && inside_light(&s->lights[j], p)) seen = j;
  }
  return seen;
}
/* Is point p of light l (one of s's) hidden by a light before it? */
static int hidden(const scene *s, const light *l, vec3 p) {
  return l->shares_plane && (size_t)(l - s->lights) < s->nlights && light_seen_at(s, (uint32_t)(l - s->lights), p) != (uint32_t)(l - s->lights);
}

rgb light_hit(const scene *s, uint32_t tri, vec3 p, vec3 ng, vec3 w, float u, float v, int32_t *lid) {
  *lid = s->tri_light[tri];
  if (*lid < 0) return c3(0, 0, 0);
  if (s->lights[*lid].shares_plane) {
    uint32_t seen = light_seen_at(s, (uint32_t)*lid, p);
    if (seen != (uint32_t)*lid) {
      const light *l = &s->lights[seen];
      float tu, tv;
      area_uv_at(s, l, p, &tu, &tv);
      *lid = (int32_t)seen;
      return light_area_radiance(s, l, l->n, w, tu, tv);
    }
  }
  return light_tri_radiance(s, tri, ng, w, u, v);
}

float light_power(const scene *s, const light *l) {
  switch (l->type) {
  case LIGHT_AREA: return PI_F * l->area * c3_avg(l->L) * (l->two_sided ? 2.0f : 1.0f);
  case LIGHT_POINT: return 4 * PI_F * c3_avg(l->L);
  case LIGHT_SPOT: return 2 * PI_F * c3_avg(l->L) * (1 - 0.5f * (l->cos_inner + l->cos_outer));
  case LIGHT_DIRECTIONAL: return PI_F * s->radius * s->radius * c3_avg(l->L);
  case LIGHT_ENV: return PI_F * PI_F * s->radius * s->radius * c3_avg(l->L);
  }
  return 0;
}

static float spot_falloff(const light *l, float cos_t) {
  if (cos_t >= l->cos_inner) return 1;
  if (cos_t <= l->cos_outer) return 0;
  if (l->spot_linear) return clampf((l->ang_outer - acosf(clampf(cos_t, -1, 1))) / (l->ang_outer - l->ang_inner), 0, 1); /* Mitsuba's */
  float d = (cos_t - l->cos_outer) / (l->cos_inner - l->cos_outer);
  return d * d * (3 - 2 * d); /* smoothstep, as pbrt-v4 */
}

/* Area lights are sampled uniformly in the solid angle they subtend (sample_spherical_
 * triangle) when they look large from the shading point (area / d^2 to the centroid at
 * least SPH_MIN_SOLID_ANGLE, and the solid angle at most SPH_MAX_SOLID_ANGLE, where it
 * nears a hemisphere and loses precision), else uniformly by area. Arvo's warp costs
 * about ten trigonometric calls, which on CornellBox-Original cost more time than the
 * 3 % less variance it gave when used for every light sample (pbrt-v4's lower bound,
 * 3e-4 sr); from 0.1 sr it is used where the area density varies most over the light
 * (docs/performance.md). Both light_sample and light_pdf_area decide by the same test,
 * so MIS sees the density that was used. */
#define SPH_MIN_SOLID_ANGLE 0.1f
#define SPH_MAX_SOLID_ANGLE 6.22f
/* A cheap stand-in for the solid angle that decides the method: area / d^2 to the
 * centroid (no trigonometry). */
static float tri_solid_angle_est(const light *l, vec3 p) {
  float d2 = v3_len2(v3_sub(l->centroid, p));
  return d2 > 0 ? l->area / d2 : INFINITY;
}
static float tri_solid_angle(const light *l, vec3 p, vec3 dir[3]) {
  for (int k = 0; k < 3; k++) {
    vec3 d = v3_sub(l->v[k], p);
    float len = v3_len(d);
    if (!(len > 0)) return 0;
    dir[k] = v3_scale(d, 1 / len);
  }
  float a = spherical_triangle_area(dir[0], dir[1], dir[2]);
  return isfinite(a) ? a : 0;
}
/* The solid angle of area light l from p if it is to be sampled by solid angle (directions
 * to its vertices in dir), else 0: the one decision light_sample and light_pdf_area share. */
static float solid_angle_if_used(const light *l, vec3 p, vec3 dir[3]) {
  if (tri_solid_angle_est(l, p) < SPH_MIN_SOLID_ANGLE) return 0;
  float omega = tri_solid_angle(l, p, dir);
  return omega > 0 && omega <= SPH_MAX_SOLID_ANGLE ? omega : 0;
}

/* Surface UV of point pl on area light l's triangle (barycentrics clamped into it); 0, 0
 * when its emission has no texture. */
static void area_uv_at(const scene *s, const light *l, vec3 pl, float *tu, float *tv) {
  *tu = *tv = 0;
  if (l->tex_ke < 0) return; /* the radiance reads no UV */
  vec3 a = l->v[0], b = l->v[1], c = l->v[2];
  vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a), q = v3_sub(pl, a);
  float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2), q1 = v3_dot(q, e1), q2 = v3_dot(q, e2);
  float den = d11 * d22 - d12 * d12;
  float bb1 = den != 0 ? (d22 * q1 - d12 * q2) / den : 0, bb2 = den != 0 ? (d11 * q2 - d12 * q1) / den : 0;
  bb1 = clampf(bb1, 0, 1); bb2 = clampf(bb2, 0, 1 - bb1);
  scene_tri_uv(s, l->tri, bb1, bb2, tu, tv);
}

/* A uniform point on area light l's triangle from (u1, u2), with its barycentrics
 * (of v[0] and v[1]). */
static vec3 area_point(const light *l, float u1, float u2, float *b0, float *b1) {
  sample_uniform_triangle(u1, u2, b0, b1);
  return v3_add(v3_add(v3_scale(l->v[0], *b0), v3_scale(l->v[1], *b1)), v3_scale(l->v[2], 1 - *b0 - *b1));
}

int light_eval_point(const scene *s, const light *l, vec3 p, vec3 y, light_li *o, float *g) {
  *g = 1;
  switch (l->type) {
  case LIGHT_AREA: {
    vec3 d = v3_sub(y, p);
    float d2 = v3_len2(d);
    if (!(d2 > 0)) return 0;
    float dist = sqrtf(d2);
    vec3 wi = v3_scale(d, 1 / dist), n = l->n;
    float cos_l = fabsf(v3_dot(n, wi));
    if (!(cos_l > 0)) return 0;
    if (hidden(s, l, y)) return 0;
    float tu, tv;
    area_uv_at(s, l, y, &tu, &tv);
    o->L = light_area_radiance(s, l, n, v3_neg(wi), tu, tv);
    if (c3_black(o->L)) return 0;
    o->wi = wi; o->dist = dist; o->p_light = y; o->n_light = n; o->pdf = 0; o->delta = 0;
    *g = cos_l / d2;
    return isfinite(*g);
  }
  case LIGHT_ENV:
    o->wi = y; o->dist = INFINITY; o->L = light_env_radiance(s, l, y); o->pdf = 0; o->delta = 0;
    o->p_light = v3_add(p, v3_scale(y, 2 * s->radius));
    o->n_light = v3(0, 0, 0);
    return !c3_black(o->L);
  case LIGHT_POINT: case LIGHT_SPOT: case LIGHT_DIRECTIONAL:
    return light_sample(s, l, p, 0, 0, o); /* delta lights: one point (or direction) */
  }
  return 0;
}

int light_sample(const scene *s, const light *l, vec3 p, float u1, float u2, light_li *o) {
  o->delta = 0;
  switch (l->type) {
  case LIGHT_AREA: {
    vec3 a = l->v[0];
    vec3 n = l->n;
    vec3 dir[3];
    float omega = solid_angle_if_used(l, p, dir);
    float b0, b1;
    vec3 pl;
    if (omega > 0) {
      /* Solid angle: a direction, then the point where it meets the triangle's plane. */
      vec3 w;
      if (!sample_spherical_triangle(dir[0], dir[1], dir[2], u1, u2, &w)) return 0;
      float dn = v3_dot(n, w);
      if (dn == 0) return 0;
      float t = v3_dot(n, v3_sub(a, p)) / dn;
      if (!(t > 0)) return 0;
      pl = v3_add(p, v3_scale(w, t));
      if (hidden(s, l, pl)) return 0;
      float tu, tv;
      area_uv_at(s, l, pl, &tu, &tv);
      o->L = light_area_radiance(s, l, n, v3_neg(w), tu, tv);
      if (c3_black(o->L)) return 0;
      o->wi = w; o->dist = t; o->p_light = pl; o->n_light = n;
      o->pdf = 1 / omega;
      return isfinite(o->pdf) && o->pdf > 0;
    }
    pl = area_point(l, u1, u2, &b0, &b1);
    if (hidden(s, l, pl)) return 0;
    vec3 d = v3_sub(pl, p);
    float d2 = v3_len2(d);
    if (!(d2 > 0)) return 0;
    float dist = sqrtf(d2);
    vec3 wi = v3_scale(d, 1 / dist);
    float cos_l = fabsf(v3_dot(n, wi));
    if (!(cos_l > 0)) return 0;
    float tu = 0, tv = 0;
    if (l->tex_ke >= 0) scene_tri_uv(s, l->tri, b1, 1 - b0 - b1, &tu, &tv);
    o->L = light_area_radiance(s, l, n, v3_neg(wi), tu, tv);
    if (c3_black(o->L)) return 0;
    o->wi = wi; o->dist = dist; o->p_light = pl; o->n_light = n;
    o->pdf = d2 / (cos_l * l->area);
    return isfinite(o->pdf) && o->pdf > 0;
  }
  case LIGHT_POINT:
  case LIGHT_SPOT: {
    vec3 d = v3_sub(l->p, p);
    float d2 = v3_len2(d);
    if (!(d2 > 0)) return 0;
    float dist = sqrtf(d2);
    o->wi = v3_scale(d, 1 / dist);
    o->dist = dist; o->p_light = l->p; o->n_light = v3(0, 0, 0);
    float fall = l->type == LIGHT_SPOT ? spot_falloff(l, v3_dot(v3_neg(o->wi), l->dir)) : 1.0f;
    o->L = c3_scale(l->L, fall / d2);
    o->pdf = 1; o->delta = 1;
    return !c3_black(o->L);
  }
  case LIGHT_DIRECTIONAL:
    o->wi = v3_neg(l->dir); o->dist = INFINITY; o->L = l->L; o->pdf = 1; o->delta = 1;
    o->p_light = v3_add(p, v3_scale(o->wi, 2 * s->radius));
    o->n_light = v3(0, 0, 0);
    return 1;
  case LIGHT_ENV:
    if (s->env_map) {
      if (!envmap_sample(s->env_map, u1, u2, &o->wi, &o->pdf)) return 0;
      o->L = envmap_eval(s->env_map, o->wi);
    } else {
      o->wi = sample_uniform_sphere(u1, u2); o->L = l->L; o->pdf = uniform_sphere_pdf();
    }
    o->dist = INFINITY;
    o->p_light = v3_add(p, v3_scale(o->wi, 2 * s->radius));
    o->n_light = v3(0, 0, 0);
    return 1;
  }
  return 0;
}

float light_pdf_area(const light *l, vec3 p, vec3 pl, vec3 nl) {
  vec3 dir[3];
  float omega = solid_angle_if_used(l, p, dir);
  if (omega > 0) return 1 / omega;
  vec3 d = v3_sub(pl, p);
  float d2 = v3_len2(d);
  float cos_l = fabsf(v3_dot(nl, v3_scale(d, 1 / sqrtf(d2))));
  if (!(cos_l > 0) || !(d2 > 0)) return 0;
  return d2 / (cos_l * l->area);
}
float light_pdf_env(const scene *s, const light *l, vec3 wi) {
  (void)l;
  return s->env_map ? envmap_pdf(s->env_map, wi) : uniform_sphere_pdf();
}
rgb light_env_radiance(const scene *s, const light *l, vec3 wi) { return s->env_map ? envmap_eval(s->env_map, wi) : l->L; }

int light_sample_emit(const scene *s, const light *l, const float u[4], light_emit *o) {
  o->n = v3(0, 0, 0);
  switch (l->type) {
  case LIGHT_AREA: {
    float b0, b1;
    o->o = area_point(l, u[0], u[1], &b0, &b1);
    vec3 n = l->n;
    float uu = u[2], side = 1;
    if (l->two_sided) { side = uu < 0.5f ? 1.0f : -1.0f; uu = uu < 0.5f ? 2 * uu : 2 * uu - 1; }
    vec3 nn = v3_scale(n, side);
    frame f = frame_from_n(nn);
    o->d = frame_to_world(&f, sample_cosine_hemisphere(uu, u[3]));
    o->n = nn;
    float tu, tv;
    scene_tri_uv(s, l->tri, b1, 1 - b0 - b1, &tu, &tv);
    rgb Le = hidden(s, l, o->o) ? c3(0, 0, 0) : light_area_radiance(s, l, n, o->d, tu, tv);
    /* Le cos / ((1/A) (cos/pi) (1/2 if two-sided)) */
    o->beta = c3_scale(Le, PI_F * l->area * (l->two_sided ? 2.0f : 1.0f));
    break;
  }
  case LIGHT_POINT:
    o->o = l->p;
    o->d = sample_uniform_sphere(u[0], u[1]);
    o->beta = c3_scale(l->L, 4 * PI_F);
    break;
  case LIGHT_SPOT: {
    o->o = l->p;
    frame f = frame_from_n(l->dir);
    o->d = frame_to_world(&f, sample_uniform_cone(u[0], u[1], l->cos_outer));
    o->beta = c3_scale(l->L, spot_falloff(l, v3_dot(o->d, l->dir)) * 2 * PI_F * (1 - l->cos_outer));
    break;
  }
  case LIGHT_DIRECTIONAL:
  case LIGHT_ENV: {
    vec3 wi; /* towards the light */
    rgb L;
    float pdf = 1;
    if (l->type == LIGHT_DIRECTIONAL) {
      wi = v3_neg(l->dir);
      L = l->L;
    } else if (s->env_map) {
      if (!envmap_sample(s->env_map, u[0], u[1], &wi, &pdf)) return 0;
      L = envmap_eval(s->env_map, wi);
    } else {
      wi = sample_uniform_sphere(u[0], u[1]);
      pdf = uniform_sphere_pdf();
      L = l->L;
    }
    float R = s->radius > 0 ? s->radius : 1;
    frame f = frame_from_n(wi);
    float dx, dy;
    sample_concentric_disk(u[2], u[3], &dx, &dy);
    vec3 disc = frame_to_world(&f, v3(dx * R, dy * R, 0));
    o->o = v3_add(v3_add(s->center, disc), v3_scale(wi, 2 * R));
    o->d = v3_neg(wi);
    o->beta = c3_scale(L, PI_F * R * R / pdf);
    break;
  }
  }
  return c3_finite(o->beta) && !c3_black(o->beta);
}

int light_sample_emit_toward(const scene *s, const light *l, const float u[4], vec3 c, float r, light_emit *o) {
  if (l->type != LIGHT_AREA && l->type != LIGHT_POINT) return 0;
  vec3 p = l->p;
  float b0 = 0, b1 = 0;
  if (l->type == LIGHT_AREA) p = area_point(l, u[0], u[1], &b0, &b1);
  vec3 dc = v3_sub(c, p);
  float dist = v3_len(dc);
  if (!(dist > r * 1.001f)) return 0; /* inside the sphere: every direction */
  float sin_max = r / dist, cos_max = sqrtf(fmaxf(0, 1 - sin_max * sin_max));
  frame f = frame_from_n(v3_scale(dc, 1 / dist));
  o->o = p;
  o->d = frame_to_world(&f, sample_uniform_cone(u[2], u[3], cos_max));
  float inv_pdf = 2 * PI_F * (1 - cos_max);
  if (l->type == LIGHT_POINT) {
    o->n = v3(0, 0, 0);
    o->beta = c3_scale(l->L, inv_pdf);
    return 1;
  }
  float cosn = v3_dot(o->d, l->n);
  o->n = v3_scale(l->n, cosn >= 0 ? 1.0f : -1.0f); /* the side it leaves from */
  float tu, tv;
  scene_tri_uv(s, l->tri, b1, 1 - b0 - b1, &tu, &tv);
  rgb Le = hidden(s, l, p) ? c3(0, 0, 0) : light_area_radiance(s, l, l->n, o->d, tu, tv); /* zero behind a one-sided light */
  /* Le |cos| / ((1/A) pdf_cone) */
  o->beta = c3_scale(Le, fabsf(cosn) * l->area * inv_pdf);
  return 1;
}
