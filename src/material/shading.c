/* shading.c — see shading.h. */
#include "material/shading.h"
#include "image/texture.h"
#include "core/rng.h"
#include <math.h>

/* Triangle ix's UV derivatives dp/du and dp/dv (constant over it): 0 when its texture
 * coordinates are degenerate. */
static int uv_derivatives(const scene *s, const uint32_t *ix, vec3 *dpdu, vec3 *dpdv) {
  vec3 e1 = v3_sub(s->pos[ix[1]], s->pos[ix[0]]), e2 = v3_sub(s->pos[ix[2]], s->pos[ix[0]]);
  float du1 = s->uv[2 * ix[1]] - s->uv[2 * ix[0]], dv1 = s->uv[2 * ix[1] + 1] - s->uv[2 * ix[0] + 1];
  float du2 = s->uv[2 * ix[2]] - s->uv[2 * ix[0]], dv2 = s->uv[2 * ix[2] + 1] - s->uv[2 * ix[0] + 1];
  float det = du1 * dv2 - du2 * dv1;
  if (!(fabsf(det) > 1e-20f)) return 0;
  float r = 1 / det;
  *dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), r);
  *dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), r);
  return 1;
}

/* Bump mapping (Blinn 1978, as pbrt's BumpMap and Mitsuba 3's bumpmap): the surface
 * displaced along the shading normal n by d(u,v) = scale * height(u,v) has tangents
 * dp/du + d_u n and dp/dv + d_v n (the d dn/du terms are dropped), whose cross product is
 * the new normal, turned to the geometric normal's side. dp/du and dp/dv are the
 * triangle's own UV derivatives, made orthogonal to n so that a flat height map leaves n
 * unchanged. Under Mitsuba's conventions d_u and d_v are its bitmap's: the exact slope of
 * the bilinear lookup in the texel cell of the hit (0 for a nearest lookup) of the texels'
 * luminance; with the mesh's tangents (map_tangents) central differences over half a
 * texel of the mean of RGB. Returns the bumped normal, or n. */
static vec3 bump_normal(const scene *s, const isect *it, const uint32_t *ix, vec3 n) {
  const texture *tx = &s->tex[it->m->tex_bump];
  vec3 dpdu, dpdv;
  if (!uv_derivatives(s, ix, &dpdu, &dpdv) || tx->w < 1 || tx->h < 1) return n;
  dpdu = v3_sub(dpdu, v3_scale(n, v3_dot(n, dpdu)));
  dpdv = v3_sub(dpdv, v3_scale(n, v3_dot(n, dpdv)));
  float d_u, d_v;
  if (!it->m->map_tangents) {
    static const float lum[3] = {0.212671f, 0.715160f, 0.072169f}; /* Mitsuba's luminance */
    texture_gradient(tx, it->u, it->v, lum, &d_u, &d_v);
    d_u *= it->m->bump_scale;
    d_v *= it->m->bump_scale;
  } else {
    float hu = 0.5f / (float)tx->w, hv = 0.5f / (float)tx->h, px[4], a, b;
    if (tx->smp.has_uvm) { /* half a texel after the map of the texture coordinates */
      float su = fmaxf(fabsf(tx->smp.uvm[0]) * tx->w, fabsf(tx->smp.uvm[3]) * tx->h), sv = fmaxf(fabsf(tx->smp.uvm[1]) * tx->w, fabsf(tx->smp.uvm[4]) * tx->h);
      if (su > 1e-6f) hu = 0.5f / su;
      if (sv > 1e-6f) hv = 0.5f / sv;
    }
    texture_lookup(tx, it->u + hu, it->v, px); a = px[0] + px[1] + px[2];
    texture_lookup(tx, it->u - hu, it->v, px); b = px[0] + px[1] + px[2];
    d_u = it->m->bump_scale * (a - b) / (3 * 2 * hu);
    texture_lookup(tx, it->u, it->v + hv, px); a = px[0] + px[1] + px[2];
    texture_lookup(tx, it->u, it->v - hv, px); b = px[0] + px[1] + px[2];
    d_v = it->m->bump_scale * (a - b) / (3 * 2 * hv);
  }
  vec3 nb = v3_cross(v3_add(dpdu, v3_scale(n, d_u)), v3_add(dpdv, v3_scale(n, d_v)));
  if (v3_dot(nb, it->m->map_tangents ? n : it->ng) < 0) nb = v3_neg(nb);
  return v3_len2(nb) > 1e-30f && v3_finite(nb) ? v3_norm(nb) : n;
}

/* A tangent-space normal map's normal: n = 2 rgb - 1 in the frame (T, B, N) at the hit.
 * Mitsuba's frame (Mitsuba 3.9's SurfaceInteraction::initialize_sh_frame): T = the
 * triangle's dp/du made orthogonal to N, B = N x T, whatever the handedness of the UVs;
 * with map_tangents, T from the mesh's per-vertex tangents and B = w N x T, w their
 * handedness (glTF's convention: B points along +v). Returns N when there is no frame. */
static vec3 mapped_normal(const scene *s, const isect *it, const uint32_t *ix, vec3 N) {
  vec3 T;
  float w = 1;
  if (!it->m->map_tangents) {
    vec3 dpdu, dpdv;
    if (!uv_derivatives(s, ix, &dpdu, &dpdv)) return N;
    T = dpdu;
  } else {
    if (!s->tan) return N;
    float b0 = 1 - it->b1 - it->b2;
    const float *t0 = &s->tan[4 * ix[0]], *t1 = &s->tan[4 * ix[1]], *t2 = &s->tan[4 * ix[2]];
    T = v3(b0 * t0[0] + it->b1 * t1[0] + it->b2 * t2[0], b0 * t0[1] + it->b1 * t1[1] + it->b2 * t2[1], b0 * t0[2] + it->b1 * t1[2] + it->b2 * t2[2]);
    w = t0[3];
  }
  T = v3_sub(T, v3_scale(N, v3_dot(N, T)));
  if (!(v3_len2(T) > 1e-12f) || !v3_finite(T)) return N;
  T = v3_norm(T);
  vec3 B = v3_scale(v3_cross(N, T), w);
  float px[4];
  texture_lookup(&s->tex[it->m->tex_normal], it->u, it->v, px);
  vec3 n2 = v3_add(v3_add(v3_scale(T, 2 * px[0] - 1), v3_scale(B, 2 * px[1] - 1)), v3_scale(N, 2 * px[2] - 1));
  return v3_len2(n2) > 1e-12f && v3_finite(n2) ? v3_norm(n2) : N;
}

/* The normal and bump maps of it's material applied to it->ns. Under Mitsuba's conventions
 * (normalmap.cpp and bumpmap.cpp, flip_invalid_normals): seen from behind through a
 * twosided around the map (map_back_mirror), the map's normal is mirrored in the tangent
 * plane, as that twosided turns only the frame's n; then a mapped normal on the other side
 * of the viewer wi than the surface's own normal has its tangential part mirrored, so the
 * surface stays lit; it->n0 keeps the surface's own normal for the shadowing term. */
static void apply_maps(const scene *s, const ray *r, isect *it, const uint32_t *ix) {
  vec3 n0 = it->ns, n = n0;
  if (it->m->tex_normal >= 0) n = mapped_normal(s, it, ix, n);
  if (it->m->tex_bump >= 0) n = bump_normal(s, it, ix, n);
  if (it->m->map_tangents) { it->ns = n; return; }
  vec3 wi = v3_neg(r->d);
  float side = v3_dot(wi, n0);
  if (it->m->map_back_mirror && side < 0) { /* the map's frame is (s, t, -n0) */
    n = v3_sub(n, v3_scale(n0, 2 * v3_dot(n, n0)));
    n0 = v3_neg(n0);
    side = -side;
  }
  if (side * v3_dot(wi, n) <= 0 && side != 0) n = v3_sub(v3_scale(n0, 2 * v3_dot(n, n0)), n);
  it->ns = n;
  it->n0 = n0;
  it->mapped = 1;
}

/* The direction of increasing u on triangle ix (the UV derivative dp/du); without texture
 * coordinates (or with degenerate ones) the triangle's first edge, which is dp/du of the
 * barycentric coordinates Mitsuba then takes as u and v. */
static vec3 surface_dpdu(const scene *s, const isect *it, const uint32_t *ix) {
  vec3 dpdu, dpdv;
  if ((s->tri_flags[it->tri] & TRI_HAS_UVS) && uv_derivatives(s, ix, &dpdu, &dpdv) && v3_len2(dpdu) > 1e-30f && v3_finite(dpdu)) return dpdu;
  return v3_sub(s->pos[ix[1]], s->pos[ix[0]]);
}

/* A weighted blend's weight at it (its weight map's first channel times its weight). */
static float blend_weight(const scene *s, const material *m, const isect *it) {
  float w = m->weight, px[4];
  if (m->tex_weight >= 0 && (s->tri_flags[it->tri] & TRI_HAS_UVS)) {
    texture_lookup(&s->tex[m->tex_weight], it->u, it->v, px);
    w *= px[0];
  }
  return w;
}
/* MAT_BLEND: one of its two materials, blend[1] with probability weight, chosen by a hash
 * of the ray and the triangle (as stochastic opacity is): over rays the hit scatters as
 * (1 - w) f0 + w f1. Blends inside blends are chosen in turn (at most 8 deep). Where both
 * are plain materials, isect_from_hit also keeps the two and the weight (isect.blend_a),
 * for bsdf_at_blend. */
static const material *blend_pick(const scene *s, const ray *r, const isect *it) {
  const material *m = it->m;
  uint64_t key = accel_ray_key(r->o, r->d) ^ ((uint64_t)it->tri * 0xD1B54A32D192ED03ull);
  for (int depth = 0; m->type == MAT_BLEND && depth < 8; depth++) {
    if (m->blend_by_side) {
      m = &s->mats[m->blend[v3_dot(r->d, it->ng) > 0]];
      continue;
    }
    float w = blend_weight(s, m, it);
    key = rng_mix64(key + 0x9E3779B97F4A7C15ull);
    m = &s->mats[m->blend[rng_to_float((uint32_t)(key >> 32)) < w]];
  }
  return m;
}

void isect_from_hit(const scene *s, const ray *r, const hit *h, isect *it) {
  const uint32_t *ix = &s->idx[3 * h->tri];
  vec3 p0 = s->pos[ix[0]], p1 = s->pos[ix[1]], p2 = s->pos[ix[2]];
  it->p = tri_point(p0, p1, p2, h->b1, h->b2, &it->perr);
  it->ng = v3_norm(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
  it->tri = h->tri;
  it->b1 = h->b1;
  it->b2 = h->b2;
  it->m = &s->mats[s->tri_mat[h->tri]];
  it->blend_a = it->blend_b = NULL;
  float b0 = 1 - h->b1 - h->b2;
  it->ns = it->ng;
  if (s->tri_flags[h->tri] & TRI_HAS_NORMALS) {
    vec3 n = v3_add(v3_add(v3_scale(s->nrm[ix[0]], b0), v3_scale(s->nrm[ix[1]], h->b1)), v3_scale(s->nrm[ix[2]], h->b2));
    float l2 = v3_len2(n);
    if (l2 > 0 && isfinite(l2)) it->ns = v3_scale(n, 1 / sqrtf(l2));
  }
  if ((s->tri_flags[h->tri] & TRI_SPHERE) && (material_has_maps(it->m) || it->m->type == MAT_BLEND)) { /* exact on a sphere */
    scene_tri_uv(s, h->tri, h->b1, h->b2, &it->u, &it->v);
  } else {
    it->u = b0 * s->uv[2 * ix[0]] + h->b1 * s->uv[2 * ix[1]] + h->b2 * s->uv[2 * ix[2]];
    it->v = b0 * s->uv[2 * ix[0] + 1] + h->b1 * s->uv[2 * ix[1] + 1] + h->b2 * s->uv[2 * ix[2] + 1];
  }
  it->mapped = 0;
  it->n0 = it->ns;
  if ((it->m->tex_normal >= 0 || it->m->tex_bump >= 0) && (s->tri_flags[h->tri] & TRI_HAS_UVS)) apply_maps(s, r, it, ix);
  int aniso = it->m->anisotropic;
  if (it->m->type == MAT_BLEND) {
    const material *bl = it->m;
    it->m = blend_pick(s, r, it); /* after the blend's own maps */
    if (!bl->blend_by_side) {
      const material *a = &s->mats[bl->blend[0]], *b = &s->mats[bl->blend[1]];
      float w = blend_weight(s, bl, it);
      int back = v3_dot(r->d, it->ng) > 0;
      if (a->type != MAT_BLEND && b->type != MAT_BLEND && w > 0 && w < 1 && !(back && (a->black_back || b->black_back))) {
        it->blend_a = a;
        it->blend_b = b;
        it->blend_w = w;
        aniso = a->anisotropic || b->anisotropic;
      }
    }
  }
  if (it->m->black_back && v3_dot(r->d, it->ng) > 0) it->m = &s->black;
  if (aniso || it->m->anisotropic) it->dpdu = surface_dpdu(s, it, ix);
}

static bsdf bsdf_of(const scene *s, const isect *it, const material *m) {
  int vc = m->vertex_colors && s->col;
  if (!vc && m->tex_kd < 0 && m->tex_ks < 0 && m->tex_mr < 0 && m->tex_ns < 0 && m->tex_rough < 0 && m->tex_metal < 0 && m->tex_cc < 0 && m->tex_ccr < 0 &&
      m->tex_sheen < 0)
    return bsdf_from_material(m);
  material mm = *m;
  float px[4];
  if (vc) mm.kd = c3_mul(mm.kd, scene_tri_color(s, it->tri, it->b1, it->b2));
  if (m->tex_kd >= 0) { texture_lookup(&s->tex[m->tex_kd], it->u, it->v, px); mm.kd = c3_mul(mm.kd, c3(px[0], px[1], px[2])); }
  if (m->tex_ks >= 0) { texture_lookup(&s->tex[m->tex_ks], it->u, it->v, px); mm.ks = c3_mul(mm.ks, c3(px[0], px[1], px[2])); }
  if (m->tex_ns >= 0) { texture_lookup(&s->tex[m->tex_ns], it->u, it->v, px); mm.exponent *= (px[0] + px[1] + px[2]) / 3; }
  if (m->tex_mr >= 0) { texture_lookup(&s->tex[m->tex_mr], it->u, it->v, px); mm.roughness *= px[1]; mm.metallic *= px[2]; }
  if (m->tex_rough >= 0) {
    texture_lookup(&s->tex[m->tex_rough], it->u, it->v, px);
    float r = fmaxf((px[0] + px[1] + px[2]) / 3, 0);
    float f = m->rough_is_alpha ? sqrtf(r) : r;
    mm.roughness *= f;
    mm.roughness_v *= f;
  }
  if (m->tex_metal >= 0) { texture_lookup(&s->tex[m->tex_metal], it->u, it->v, px); mm.metallic *= (px[0] + px[1] + px[2]) / 3; }
  if (m->tex_cc >= 0) { texture_lookup(&s->tex[m->tex_cc], it->u, it->v, px); mm.clearcoat *= px[0]; }
  if (m->tex_ccr >= 0) { texture_lookup(&s->tex[m->tex_ccr], it->u, it->v, px); mm.clearcoat_roughness *= px[1]; }
  if (m->tex_sheen >= 0) { texture_lookup(&s->tex[m->tex_sheen], it->u, it->v, px); mm.sheen_color = c3_mul(mm.sheen_color, c3(px[0], px[1], px[2])); }
  bsdf b = bsdf_from_material(&mm);
  if (b.sh_E) b.sh_E = m->sheen_E; /* the material's tables, not this copy's, which goes out of scope */
  if (b.coat_t) b.coat_t = m->coat_t;
  return b;
}
bsdf bsdf_at(const scene *s, const isect *it) { return bsdf_of(s, it, it->m); }

bsdf bsdf_at_blend(const scene *s, const isect *it, bsdf *second) {
  if (!it->blend_a) return bsdf_of(s, it, it->m);
  bsdf a = bsdf_of(s, it, it->blend_a);
  *second = bsdf_of(s, it, it->blend_b);
  if (bsdf_transmits(&a) != bsdf_transmits(second)) return bsdf_of(s, it, it->m); /* their frames differ: the pick */
  a.mix = second;
  a.mix_w = it->blend_w;
  return a;
}

static int material_has_smooth(const scene *s, const material *m, int depth) {
  if (m->type != MAT_BLEND) {
    bsdf b = bsdf_from_material(m);
    return bsdf_has_smooth(&b);
  }
  return depth < 8 && (material_has_smooth(s, &s->mats[m->blend[0]], depth + 1) || material_has_smooth(s, &s->mats[m->blend[1]], depth + 1));
}
int surface_has_smooth(const scene *s, uint32_t t) { return material_has_smooth(s, &s->mats[s->tri_mat[t]], 0); }

frame shading_frame(isect *it, bsdf *b, vec3 wo) {
  vec3 ns = it->ns, n0 = it->n0;
  if (!bsdf_transmits(b)) {
    if (v3_dot(it->ng, wo) < 0) it->ng = v3_neg(it->ng);
    if (v3_dot(ns, wo) < 0) { ns = v3_neg(ns); n0 = v3_neg(n0); }
  }
  frame f = frame_from_n(ns);
  if (bsdf_anisotropic(b) || (b->mix && bsdf_anisotropic(b->mix))) { /* s along the surface's u direction (Gram-Schmidt against ns) */
    vec3 t = v3_sub(it->dpdu, v3_scale(ns, v3_dot(ns, it->dpdu)));
    if (v3_len2(t) > 1e-20f && v3_finite(t)) {
      f.s = v3_norm(t);
      f.t = v3_cross(ns, f.s);
    }
  }
  b->mapped = it->mapped;
  if (it->mapped) b->n0 = frame_to_local(&f, n0);
  if (b->mix) { b->mix->mapped = b->mapped; b->mix->n0 = b->n0; }
  return f;
}

