/* guide.h — owns the SD-tree of path guiding (Müller, Gross, Novák 2017, "Practical Path
 * Guiding"): a binary tree over the scene's box (split at the middle, axes in turn) whose
 * leaves each hold, for each of six bins of the shading normal (its major axis: a floor
 * and a ceiling in one leaf learn apart), two quadtrees over the sphere of directions (the square
 * [0,1]^2 of (cos theta + 1)/2 and phi/2pi, an equal-area map: density on the sphere =
 * density on the square / 4 pi). A pass samples from the `sampling` quadtrees and records
 * incident radiance / pdf into the `building` ones; guide_refine then makes the building
 * trees the sampling ones, splits leaves where more than c sqrt(2^k) path vertices fell
 * in pass k, and gives each leaf a new building tree whose quadrants are split where the
 * last pass put more than 1 % of the leaf's flux (to depth 20).
 * Records are added as 64-bit fixed-point integers (a quantum of guide->scale * 2^-32,
 * each record cut at 16 x scale: a sum wraps only past 2^28 such records), so the trees
 * do not depend on the order in which threads add them: a pass gives the same trees for
 * any thread count. Sampling trees hold each node's quadrant shares as floats.
 * The node count is capped (guide->max_nodes over all quadtrees); past it no quadtree
 * grows further.
 * Each leaf and bin also learns its BSDF fraction (the share of directions drawn from
 * the BSDF rather than the quadtree), as Müller's 2019 production guiding learns it, here
 * by choosing among GUIDE_FRACTIONS values: every recorded vertex adds, for each value
 * a, the second moment its contribution X (drawn with the mixture pdf q) would have under
 * a, X^2 q / (a p_bsdf + (1 - a) p_guide) (its expectation is the second moment of
 * sampling with a), in the same fixed point (cut at 4096 units: a sum wraps only past
 * 2^20 such records, and a leaf splits long before); guide_refine picks the smallest, and
 * fraction 1 (no quadtree at all, cheaper) when it is within GUIDE_PURE_MARGIN of it. */
#ifndef VALO_GUIDE_H
#define VALO_GUIDE_H
#include "core/vec.h"
#include "scene/scene.h"
#include <stdatomic.h>
#include <stdint.h>

typedef struct qnode {
  uint32_t child[4];          /* 0: none (quadrant q: bit 0 u >= 1/2, bit 1 v >= 1/2) */
  _Atomic uint64_t sum[4];    /* flux recorded in each quadrant (fixed point) */
} qnode;
typedef struct qtree { qnode *n; uint32_t count, cap; } qtree;   /* a building tree */
typedef struct snode {           /* p: the quadrants' shares; for sampling, the u-half's share  */
  uint32_t child[4];             /* pu = p0 + p2 and each column's lower share pv[c] = p[c] / (p[c] + p[c+2]) */
  float p[4], pu, pv[2];
} snode;
typedef struct stree { snode *n; uint32_t count; } stree;        /* a sampling tree; count 0: none */

#define GUIDE_BINS 6 /* a leaf's quadtrees, one per major axis of the shading normal (+x, -x, +y, ...) */
#define GUIDE_FRACTIONS 4    /* the BSDF fractions a leaf's bin chooses among: guide_fraction[] */
#define GUIDE_PURE_MARGIN 1.1 /* fraction 1 is taken within this factor of the best second moment */
extern const float guide_fraction[GUIDE_FRACTIONS];
typedef struct gleaf {
  stree sampling[GUIDE_BINS];
  qtree building[GUIDE_BINS];
  float frac[GUIDE_BINS];     /* the learned BSDF fraction; < 0: none learned (the integrator's default) */
  _Atomic uint64_t m2[GUIDE_BINS][GUIDE_FRACTIONS]; /* this pass's second moments per fraction (fixed point) */
  _Atomic uint32_t records;   /* path vertices recorded in this pass (lit or not) */
} gleaf;
typedef struct gsnode { vec3 lo, hi; float mid; int axis; uint32_t child; uint32_t leaf; } gsnode; /* split at mid (the middle of axis); child 0: a leaf */

typedef struct guide {
  bbox box;
  gsnode *sn; uint32_t nsn, capsn;
  gleaf *leaves; uint32_t nleaves, capleaves;
  double scale;               /* the fixed point's unit; 0 until guide_set_scale */
  uint64_t nodes;             /* quadtree nodes held (sampling + building) */
  uint64_t max_nodes;
  int full;                   /* the cap stopped a quadtree from growing */
  int pass;                   /* passes refined so far */
  double spatial_c;           /* leaves split past spatial_c sqrt(2^pass) records */
} guide;

int guide_init(guide *g, bbox box, uint64_t max_nodes, double spatial_c);
void guide_free(guide *g);
void guide_set_scale(guide *g, double scale);
/* The leaf holding p (points outside the box go to the nearest leaf). */
const gleaf *guide_leaf(const guide *g, vec3 p);
/* Directions <-> the quadtrees' square. */
void guide_dir_to_square(vec3 d, float *u, float *v);
vec3 guide_square_to_dir(float u, float v);
/* The bin of a shading normal: its major axis and sign. */
int guide_bin(vec3 n);
/* Whether the leaf's sampling tree of bin b holds anything to sample. */
int guide_can_sample(const gleaf *l, int b);
/* Samples a direction from the leaf's sampling tree of bin b; *pdf per steradian. */
vec3 guide_sample(const gleaf *l, int b, float u1, float u2, float *pdf);
float guide_pdf(const gleaf *l, int b, vec3 d);
/* Adds value (radiance / pdf, >= 0) at direction d to the building tree of bin b of leaf
 * l (of g), and counts a vertex there. */
void guide_record(const guide *g, gleaf *l, int b, vec3 d, float value);
/* Adds a recorded vertex's second moments: x = its contribution X over the guide's scale,
 * q its mixture pdf, pb and pg the BSDF's and the quadtree's pdfs of its direction. */
void guide_record_moments(const guide *g, gleaf *l, int b, double x, float q, float pb, float pg);
/* The share of leaf-bins (of those that learned one) whose fraction is 1. */
double guide_pure_share(const guide *g);
/* Ends a pass (serial): the building trees become the sampling ones, leaves split, new
 * building trees refined. Returns -1 when out of memory. */
int guide_refine(guide *g);

/* Ends learning: the building trees are freed; the sampling ones stay. */
void guide_stop(guide *g);

/* A sampling tree alone: sample and pdf on the square. */
void stree_sample(const stree *t, float u1, float u2, float *u, float *v, float *pdf);
float stree_pdf(const stree *t, float u, float v);
#endif
