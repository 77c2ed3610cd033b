/* scene.h — owns the scene model: flattened world-space triangle geometry (flat arrays),
 * materials, textures, lights and the environment as data, the camera and its keyframes.
 * Loaders (src/load/) append through the scene_add_* builders; scene_commit() then
 * validates and derives what rendering needs (bounds, area lights, tangents). After
 * commit the scene is immutable and shared by all threads without locks. The model knows
 * no file format and no render setting. */
#ifndef VALO_SCENE_H
#define VALO_SCENE_H
#include "core/vec.h"
#include "valo/valo.h"

typedef enum mat_type {
  MAT_DIFFUSE,     /* Lambertian kd */
  MAT_PHONG,       /* kd/pi + normalised Phong lobe ks (n+2)/(2pi) cos^n */
  MAT_MIRROR,      /* kd/pi + ideal mirror ks, no Fresnel (MTL illum 5; JSON mirror: kd=0) */
  MAT_DIELECTRIC,  /* smooth dielectric, index ior */
  MAT_CONDUCTOR,   /* smooth conductor, complex index eta + i k per channel */
  MAT_PBR,         /* glTF 2.0 metallic-roughness: base colour kd, metallic, roughness */
  MAT_NULL,        /* no surface: rays pass straight through (a medium's boundary) */
  MAT_THIN_DIELECTRIC, /* a thin pane of glass, index ior: reflects as both faces do, transmits without bending */
  MAT_PLASTIC,     /* diffuse kd under a dielectric coat of index ior, specular tint ks, smooth or rough
                      (Mitsuba's plastic / roughplastic; material/plastic.h) */
  MAT_PRINCIPLED,  /* Mitsuba's principled (Disney) BSDF: base colour kd, metallic, roughness, ior,
                      and the fields below (material/principled.h) */
  MAT_BLEND        /* blend[1] with probability weight (times tex_weight), else blend[0], chosen per
                      hit (Mitsuba's blendbsdf; isect_from_hit resolves it) */
} mat_type;

/* MAT_PLASTIC's coat, tabulated by plastic_prepare: its transmittance at cos theta =
 * i / (PLASTIC_RES - 1), and the reflectance it shows to diffuse light from inside. */
#define PLASTIC_RES 64
/* MAT_PBR's sheen (glTF's KHR_materials_sheen): its directional albedo E(cos) at
 * SHEEN_RES cosines i / (SHEEN_RES - 1), filled by sheen_prepare (material/sheen.h). */
#define SHEEN_RES 32

struct tex_sampling; /* image/texture.h */
typedef struct material {
  mat_type type;
  rgb kd, ks;
  float exponent;
  float ior;
  rgb eta, k;
  rgb tint;          /* conductor: multiplies its Fresnel reflectance (Mitsuba's specular_reflectance), 1 by default */
  rgb transmittance; /* dielectrics: multiplies the light they transmit at each crossing (Mitsuba's
                        specular_transmittance, glTF's base colour on transmission), 1 by default */
  float roughness;   /* conductor/dielectric: GGX alpha = roughness^2; < 0.0316 is smooth */
  int anisotropic;   /* conductor/dielectric: roughness along the surface's u direction, roughness_v along v */
  float roughness_v;
  float metallic;    /* MAT_PBR: 0 dielectric .. 1 metal */
  int beckmann;      /* conductor/dielectric roughness: Beckmann's distribution (JSON "distribution"), else GGX */
  int smith_separable; /* conductor/dielectric/plastic roughness: Smith's separable G (JSON "smith"), else height-correlated */
  int metal_flat;    /* MAT_PBR: metal reflectance kd at every angle, no Schlick term (MTL PBR extension) */
  rgb f0;            /* MAT_PBR: the dielectric's Fresnel at normal incidence (0.04, ior 1.5; glTF's
                        KHR_materials_ior and _specular set it) */
  float f90;         /* MAT_PBR: ... and at grazing incidence (1; KHR_materials_specular's factor) */
  int tex_mr;        /* MAT_PBR: metallic-roughness map (linear; G roughness, B metallic), -1 = none */
  int tex_cc, tex_ccr; /* MAT_PBR: clearcoat map (linear; R multiplies clearcoat) and clearcoat
                          roughness map (linear; G multiplies clearcoat_roughness), -1 = none */
  int tex_sheen;     /* MAT_PBR: sheen colour map (sRGB; RGB multiplies sheen_color), -1 = none */
  int dispersion;    /* dielectric: a core/spectrum.h dispersion preset, 0 = none */
  rgb emission;      /* emitted radiance (front side unless two_sided) */
  int two_sided;     /* emission on both sides */
  int vertex_colors; /* kd (diffuse, base colour) times the mesh's vertex colours, white
                        where a mesh has none (JSON "vertex_colors", glTF's COLOR_0) */
  int black_back;    /* black seen from behind (the side against the winding's normal): no
                        scattering there, as Mitsuba's BSDFs outside a twosided (JSON "black_back") */
  int tex_kd, tex_ks, tex_ke;  /* texture indices multiplying kd, ks, emission; -1 = none */
  int tex_alpha;     /* alpha-cutout texture (opacity map when alpha_stochastic), -1 = none */
  int tex_normal;    /* tangent-space normal map (linear, OpenGL +Y), -1 = none */
  int tex_ns;        /* Phong exponent map (MTL map_Ns; linear, mean of RGB multiplies exponent), -1 = none */
  int tex_bump;      /* height map for bump mapping (mean of RGB, linear), -1 = none */
  int tex_rough;     /* multiplies roughness by its value (mean of RGB, linear), or alpha when
                        rough_is_alpha (MTL map_Pr, Mitsuba's alpha textures); -1 = none */
  int rough_is_alpha;
  int tex_metal;     /* multiplies metallic (mean of RGB, linear; MTL map_Pm), -1 = none */
  float bump_scale;  /* displacement in scene units = bump_scale * height */
  int map_tangents;  /* normal and bump maps: 1, the mesh's per-vertex tangents with their
                        handedness (glTF's TANGENT, else computed), as glTF asks; 0 (JSON's
                        and Mitsuba's default), Mitsuba 3's conventions: the frame s = the
                        triangle's dp/du, t = n x s, a mapped normal facing away from the
                        viewer mirrored, and the shadowing term for mapped normals */
  int map_back_mirror; /* Mitsuba's twosided around the map: seen from behind, the map's
                          frame is (s, t, -n) (only n turned); else the whole frame turns */
  int alpha_channel; /* 1: cutout reads the texture's alpha channel, 0: its red channel */
  float alpha_cutoff;/* a hit counts where alpha >= cutoff */
  float opacity;     /* a hit counts with probability opacity (times tex_alpha's value when
                        alpha_stochastic): 1 = opaque, the default */
  int alpha_stochastic; /* 1: tex_alpha is an opacity map, not a cutout */
  float spec_tint, sheen, sheen_tint, flatness, clearcoat, clearcoat_gloss, spec_trans; /* MAT_PRINCIPLED (clearcoat: MAT_PBR's too) */
  float clearcoat_roughness; /* MAT_PBR: glTF's KHR_materials_clearcoat layer (weight clearcoat) */
  float anisotropy;  /* MAT_PRINCIPLED: Mitsuba's "anisotropic", 0..1 (sets anisotropic when > 0) */
  int blend[2];      /* MAT_BLEND: the two materials' indices */
  int blend_by_side; /* MAT_BLEND: blend[0] seen from the front (the winding's normal side), blend[1] from the back
                        (JSON "sided", Mitsuba's twosided of two BSDFs), not by weight */
  float weight;      /* MAT_BLEND: blend[1]'s share */
  int tex_weight;    /* MAT_BLEND: a map multiplying weight (its first channel), -1 = none */
  int nonlinear;     /* MAT_PLASTIC: the base's internal scattering tints (Mitsuba's nonlinear) */
  float coat_t[PLASTIC_RES], coat_ri; /* MAT_PLASTIC: filled by plastic_prepare */
  rgb sheen_color;   /* MAT_PBR: KHR_materials_sheen's colour (black: no sheen) and roughness */
  float sheen_roughness;
  float sheen_E[SHEEN_RES]; /* MAT_PBR with a sheen: filled by sheen_prepare */
  int nk;            /* MAT_CONDUCTOR: 1 + index into scene.nk (eta and k per wavelength,
                        which --spectral evaluates per wavelength), 0 = RGB eta, k only */
  char name[64];
} material;

/* A conductor's complex index tabulated against wavelength (JSON "spectrum"): linear
 * between points, constant beyond the ends (core/spectrum.h tab_eval). */
#define NK_MAX 256
typedef struct nk_curve { int n; float nm[NK_MAX], eta[NK_MAX], k[NK_MAX]; } nk_curve;

/* A participating medium (JSON "media"): absorption and scattering coefficients per
 * unit length (RGB, scale applied), the Henyey-Greenstein g and the emitted radiance Le
 * (the source term is sigma_a Le, as pbrt's); homogeneous, or (grid not NULL) both
 * coefficients times the grid's density at each point. */
typedef struct medium { rgb sigma_a, sigma_s; float g; struct density_grid *grid; rgb Le; char name[64]; } medium;
/* 1 when the medium emits light (its source term sigma_a Le is not black). */
static inline int medium_glows(const medium *m) { return !c3_black(m->Le) && !c3_black(m->sigma_a); }
#define MEDIUM_NONE (-1)  /* vacuum */
#define MEDIUM_KEEP (-2)  /* tri_media: the triangle is no medium boundary */
/* The media of one JSON shape's triangles [first, end): inside (against the winding
 * normal) and outside (MEDIUM_NONE: vacuum). */
typedef struct shape_media { uint32_t first, end; int32_t interior, exterior; } shape_media;

typedef enum light_type { LIGHT_AREA, LIGHT_POINT, LIGHT_SPOT, LIGHT_DIRECTIONAL, LIGHT_ENV } light_type;
typedef struct light {
  light_type type;
  vec3 p;          /* point/spot position */
  vec3 dir;        /* spot axis, or directional light's direction of travel (unit) */
  rgb L;           /* area/env radiance; point/spot intensity; directional irradiance */
  float cos_inner, cos_outer; /* spot falloff */
  int spot_linear;   /* spot: falloff linear in the angle between the two (Mitsuba's), else smoothstep in the cosine (pbrt's) */
  float ang_inner, ang_outer; /* spot_linear: the two angles (radians) */
  uint32_t tri;    /* area: triangle index */
  float area;      /* area: triangle area */
  int two_sided;
  /* area, filled by scene_area_light: copies of what sampling the light reads, so that
   * it does not chase the triangle's indices and material */
  vec3 v[3];       /* its vertices */
  vec3 ng, n;      /* scene_tri_ng and its unit vector */
  vec3 centroid;   /* (v0 + v1 + v2) / 3 */
  int tex_ke;      /* its material's emission texture, -1: none */
  uint32_t sphere; /* area, after commit: 1 + the index of the emitting sphere (scene.spheres)
                      whose triangles it is one of, when that sphere is sampled whole; 0: none */
  int shares_plane; /* area, after commit: another area light overlaps it in its plane
                       (light_overlap.c): its shadow rays ask which one a ray meets first */
} light;

/* A sphere of scene_add_sphere: its triangles [first, end), its centre and radius (its
 * vertices lie on the sphere, its faces inside it); flip: facing inwards. After commit,
 * when it emits outwards and each of its triangles is an area light, its lights are
 * [l0, l1), in triangle order, and light sampling may take it whole (light.h); else
 * l0 == l1. */
typedef struct sphere_shape {
  vec3 c; float r; uint32_t first, end; int flip; uint32_t l0, l1;
  int mitsuba_uv; float rot[9]; /* its texture layout (scene_sphere_uv) */
} sphere_shape;

typedef struct camera {
  vec3 pos, look_at, up;
  float fov_deg;          /* vertical (a perspective camera) */
  float ortho_height;     /* > 0: orthographic, the view's height in scene units (fov_deg
                             unused); 0: perspective */
  int spherical;          /* 1: the whole sphere of directions, equirectangular (fov_deg
                             and ortho_height unused) */
  float aperture_radius, focus_distance;
} camera;

/* One keyframe of a camera animation: the camera at frame `frame` (frames between
 * keyframes interpolate position, look_at, up and fov, or an orthographic camera's
 * height, linearly; before the first and after the last the camera holds still). */
typedef struct cam_key { float frame; vec3 pos, look_at, up; float fov_deg, ortho_height; } cam_key;

/* Triangle flags. */
enum { TRI_HAS_NORMALS = 1, TRI_HAS_UVS = 2, TRI_ALPHA = 4, TRI_SPHERE = 8 /* one of scene.spheres' */ };

/* Proximity-AO settings of one JSON shape (its triangles [first, end)); a negative
 * value (not given) takes the proximity-ao integrator's parameter. */
typedef struct shape_ao { uint32_t first, end; float spacing, radius, strength; } shape_ao;

typedef struct scene {
  char path[1024];
  /* geometry */
  vec3 *pos, *nrm;         /* per vertex; nrm may hold zeros where the file had none */
  float *tan;              /* 4 per vertex (tangent xyz, bitangent sign), after commit when
                              a material has a normal map; else NULL */
  float *uv;               /* 2 per vertex */
  valo_error tex_fatal;     /* a map that would not fit in memory (status VALO_ERR_NOMEM):
                               the loader refuses the scene with it rather than ignoring
                               the map (VALO_OK when none) */
  char tex_user[1200];      /* while a loader reads a material's maps: "file: material 'x'",
                              named in the warning when one cannot be read */
  float *col;              /* 3 per vertex: a colour the file gave (linear RGB; PLY's colours,
                              glTF's COLOR_0), 1 where it gave none; NULL until a file gives
                              one (then grown with the other vertex arrays) */
  float *tan_file;         /* 4 per vertex: a tangent the file gave (glTF TANGENT: xyz and
                              the bitangent sign); w = 0 where it gave none; NULL until a
                              file gives one (then grown with the other vertex arrays) */
  uint32_t nverts, cap_verts; /* after commit cap_verts > nverts, pos[nverts] readable (accel_create) */
  uint32_t *idx;           /* 3 per triangle */
  uint32_t *tri_mat;
  uint8_t *tri_flags;
  uint32_t ntris, cap_tris;
  material *mats;
  uint32_t nmats, cap_mats;
  material black;    /* what a black_back material is seen from behind: black diffuse */
  struct texture *tex;
  uint32_t ntex, cap_tex;
  nk_curve *nk;            /* spectral conductor data (material.nk), nnk of them */
  uint32_t nnk;
  light *lights;
  uint32_t nlights, cap_lights;
  int32_t *tri_light;      /* per triangle: its area light or -1 (after commit) */
  uint32_t *light_ov0, *light_ov; /* after commit, when lights overlap: the lights light i
                                     overlaps in its plane are light_ov[light_ov0[i] ..
                                     light_ov0[i + 1]) (light_overlap.c); else NULL */
  rgb env_radiance;        /* constant environment */
  int has_env;
  struct envmap *env_map;  /* equirectangular map (owned), or NULL for constant */
  camera cam;
  int has_camera;
  cam_key *cam_keys;       /* camera animation (JSON camera.keyframes), sorted by frame; or NULL */
  uint32_t ncam_keys;
  int up_z;                /* automatic framing: the model's up axis is +z (else +y) */
  int cam_auto;            /* the camera was framed automatically (scene_camera_fit) */
  shape_ao *shape_ao;      /* per-shape proximity-AO settings (JSON "proximity"), sorted by first */
  uint32_t nshape_ao;
  medium *media;           /* participating media (JSON "media"), nmedia of them */
  uint32_t nmedia;
  shape_media *shape_media;/* shapes that bound media, in triangle order */
  uint32_t nshape_media;
  sphere_shape *spheres;   /* the spheres scene_add_sphere made, nspheres of them */
  uint32_t nspheres;
  int32_t *tri_media;      /* after commit, when a shape bounds a medium: 2 per triangle,
                              interior and exterior medium (MEDIUM_KEEP: no boundary);
                              else NULL */
  int32_t cam_medium;      /* the medium around the camera (JSON camera.medium), or MEDIUM_NONE */
  int has_media;           /* after commit: media or null surfaces (path renders them) */
  bbox bounds;
  vec3 center;
  float radius;
} scene;

scene *scene_new(const char *path);
void scene_free(scene *s);
/* Builders: return 0 or -1 on out of memory. */
int scene_reserve(scene *s, uint32_t more_verts, uint32_t more_tris);
uint32_t scene_add_material(scene *s, const material *m); /* UINT32_MAX on OOM */
int scene_add_light(scene *s, const light *l);
/* An area light on triangle t: type, tri, area and the copies above (L and two_sided are
 * the caller's). */
void scene_area_light(const scene *s, uint32_t t, light *l);
material material_default(void);
/* Adds (or finds, by key) a texture from a file; returns its index, or -1 when it cannot
 * be read: with err, err says why (the caller refuses the scene); without, a warning
 * names the file and the map is ignored. */
int scene_texture_file(scene *s, const char *path, int srgb, valo_error *err);
int scene_texture_memory(scene *s, const char *key, const unsigned char *data, size_t len, int srgb);
/* Texture base sampled as smp says: base itself when it already is, else (found or added)
 * a texture sharing base's pixels. base < 0 is returned as is. */
int scene_texture_sampled(scene *s, int base, const struct tex_sampling *smp);
/* Texture base as one number per texel, its luminance (linear sRGB's Y: 0.212671 R +
 * 0.715160 G + 0.072169 B) in every channel and alpha 1, as Mitsuba reads a bitmap given
 * for a number: found or added (its own pixels); -1 when out of memory, base < 0 as is. */
int scene_texture_luminance(scene *s, int base);
/* Mitsuba's checkerboard (texture_checkerboard), found or added; -1 when out of memory. */
int scene_texture_checkerboard(scene *s, const float c0[3], const float c1[3], valo_error *err);
/* Surface UV of triangle t at barycentrics (b1, b2): interpolated, or on a sphere's
 * triangle the sphere's own layout at the point's direction from its centre (exact, so a
 * texture shows no facets). */
void scene_tri_uv(const scene *s, uint32_t t, float b1, float b2, float *u, float *v);
/* The vertex colour of triangle t at barycentrics (b1, b2); white when the scene has none. */
rgb scene_tri_color(const scene *s, uint32_t t, float b1, float b2);
/* Alpha test: 1 if the hit on triangle t at (b1, b2) counts. A cutout compares the map
 * with alpha_cutoff; an opacity a < 1 lets the hit count with probability a, decided by a
 * hash of key (the ray's, geometry/accel.h) and t: the same ray meets the same answer
 * each time, two triangles on its way answer independently. */
int scene_alpha_pass(const scene *s, uint32_t t, float b1, float b2, uint64_t key);
/* The triangles from first to the last added bound the media interior (against their
 * winding normal) and exterior (MEDIUM_NONE: vacuum); later entries win. 0, or -1 when out
 * of memory. */
int scene_add_shape_media(scene *s, uint32_t first, int32_t interior, int32_t exterior);
/* MAT_PBR's dielectric Fresnel as glTF's KHR_materials_ior and _specular give it: F0 =
 * min(((ior - 1) / (ior + 1))^2 color, 1) factor (0.04 at ior 1.5, factor and color 1),
 * F90 = factor. */
void material_pbr_specular(material *m, float ior, float factor, rgb color);
/* 1 if the material reads any texture map (which needs texture coordinates). */
int material_has_maps(const material *m);
/* Validates and derives bounds and area lights; frames a camera if none was given. */
valo_status scene_commit(scene *s, valo_error *err);
/* Sets light.shares_plane on the area lights (light_overlap.c); -1 when out of memory. */
int scene_flag_light_overlaps(scene *s);
/* The proximity-AO settings of the JSON shape triangle t belongs to (NULL: none). */
const shape_ao *scene_shape_ao(const scene *s, uint32_t t);
/* The medium a ray in medium `cur` is in after crossing triangle t (winding normal ng)
 * in direction d: the triangle's interior or exterior when it bounds a medium, else cur. */
static inline int32_t scene_medium_after(const scene *s, uint32_t t, vec3 ng, vec3 d, int32_t cur) {
  if (!s->tri_media || s->tri_media[2 * t] == MEDIUM_KEEP) return cur;
  return s->tri_media[2 * t + (v3_dot(d, ng) < 0 ? 0 : 1)];
}
/* Geometric (unnormalised cross product) normal of triangle t. */
static inline vec3 scene_tri_ng(const scene *s, uint32_t t) {
  const uint32_t *i = &s->idx[3 * t];
  return v3_cross(v3_sub(s->pos[i[1]], s->pos[i[0]]), v3_sub(s->pos[i[2]], s->pos[i[0]]));
}

/* The scene's camera for a film of this aspect: an automatic camera moved along its axis
 * to the nearest distance that frames the bounds; any other camera as it is. */
camera scene_camera_fit(const scene *s, float aspect);
/* The camera at frame f: the keyframes' interpolation when the scene has an animation,
 * else `still` (the lens of `still` is kept either way). */
camera scene_camera_at(const scene *s, const camera *still, float f);

/* A triangle mesh in a file's own arrays, for scene_add_mesh: 3 floats per vertex for
 * positions and normals (NULL: none), uv_stride floats per vertex for texture coordinates
 * (v up, as valo reads them; NULL: none), 3 indices per triangle. where names it in
 * messages ("file: mesh 'x'"); flat: shade with the triangles' own normals; smooth: when
 * nrm is NULL, shade with vertex normals computed from the faces, angle-weighted (as
 * Mitsuba does for a mesh file without normals). */
typedef struct mesh_data {
  const char *where;
  uint32_t nverts, ntris;
  const float *pos, *nrm, *uv;
  int uv_stride;
  const uint32_t *idx;
  int flat, smooth;
  const float *col;        /* col_stride floats per vertex, RGB first (NULL: none) */
  int col_stride;
} mesh_data;
/* Appends m placed by xf (3x4 row-major, NULL = identity; a mirroring one keeps each
 * triangle's front side), every triangle of material mat (< s->nmats). Non-finite
 * positions and indices out of range are errors; zero-area triangles are skipped.
 * *added and *degenerate count the triangles kept and skipped. */
valo_status scene_add_mesh(scene *s, const mesh_data *m, const float *xf, uint32_t mat, uint64_t *added, uint64_t *degenerate,
                           valo_error *err);
/* Adds a tessellated sphere (icosphere with `subdiv` subdivisions); flip: normals
 * inward; smooth: exact sphere normals as shading normals (else flat facets). */
valo_status scene_add_sphere(scene *s, vec3 center, float radius, int subdiv, int flip,
                             int smooth, uint32_t mat, valo_error *err);
/* Scales sphere g's triangles about its centre so that their area is the exact sphere's
 * (4 pi r^2: an emitter then gives the exact sphere's power); its radius becomes its
 * vertices' (r times the scale), so that the cone it subtends holds every facet. */
void scene_sphere_exact_area(scene *s, uint32_t g);
/* Lays out sphere g's texture coordinates as an equirectangular map, a triangle across
 * the seam keeping its u's together (the map repeats) and a pole vertex taking the mean u
 * of the other two. rot NULL: valo's own, +y the pole at the image's top, u = 1/2 +
 * atan2(z, x) / 2 pi (scene_add_sphere makes it so); else Mitsuba's layout in the sphere's
 * local frame (3x3 row-major, local to world, orthogonal): u = phi / 2 pi from its x towards
 * its y, v = 1 - theta / pi from its z (turned up to valo's convention). */
valo_status scene_sphere_uv(scene *s, uint32_t g, const float *rot);
/* The UV of sphere sp's layout at point p (its direction from the centre). */
void scene_sphere_point_uv(const sphere_shape *sp, vec3 p, float *u, float *v);
/* Mitsuba's unit shapes, flat-shaded: the rectangle [-1, 1]^2 at z = 0 facing +z, the
 * cube [-1, 1]^3 facing out, the disk of radius 1 at z = 0 facing +z (256 segments); and
 * smooth-shaded the cylinder of radius 1 around z from 0 to 1, open, facing out (256
 * facets, the true cylinder's normals); placed by xf (3x4 row-major, NULL = identity; a
 * mirroring one keeps the front side); flip: facing the other way. UVs span [0, 1]^2 on
 * each (each face of the cube; the cylinder's (phi / 2 pi, z)), or with mitsuba_uv as
 * Mitsuba lays them out (its cube's faces, its disk's polar (r, phi / 2 pi), its
 * cylinder's (phi / 2 pi, z)), v turned up to valo's convention, so a Mitsuba scene's
 * textures land where Mitsuba puts them. */
typedef enum { PRIM_RECTANGLE, PRIM_CUBE, PRIM_DISK, PRIM_CYLINDER } primitive_kind;
valo_status scene_add_primitive(scene *s, primitive_kind kind, const float *xf, int flip, int mitsuba_uv, uint32_t mat, valo_error *err);
/* xf (3x4 row-major) times the placement of the unit cylinder from p0 to p1 (p0 != p1) of
 * radius r, its x axis where Mitsuba's cylinder puts it (its u = 0). */
void scene_cylinder_place(vec3 p0, vec3 p1, float r, float xf[12]);
/* Conductor presets by Mitsuba's material names (scene/conductors.c): 0 on success, -1
 * for a name it does not hold. */
int conductor_preset(const char *name, rgb *eta, rgb *k);
#endif
