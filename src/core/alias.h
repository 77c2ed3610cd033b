/* alias.h — owns the alias table (Walker/Vose): O(1) sampling of a discrete
 * distribution, used for light selection proportional to power. */
#ifndef VALO_ALIAS_H
#define VALO_ALIAS_H
#include <stdint.h>

typedef struct alias_bin { float q; uint32_t alias; float p; } alias_bin;
typedef struct alias_table { alias_bin *bins; uint32_t n; } alias_table;

/* Builds from n non-negative weights (sum > 0). Returns 0 on success, -1 on bad input/OOM.
 * The table owns bins; free with alias_free. */
int alias_build(alias_table *t, const float *weights, uint32_t n);
void alias_free(alias_table *t);
/* Samples an index with probability p_i; u in [0,1). *pmf receives p_i. */
uint32_t alias_sample(const alias_table *t, float u, float *pmf);
/* The same choice, and *rest: where u fell within the choice's share, a fresh number in
 * [0, 1) for a choice that follows (pbrt's and Mitsuba's sample reuse). */
uint32_t alias_sample_rest(const alias_table *t, float u, float *pmf, float *rest);
static inline float alias_pmf(const alias_table *t, uint32_t i) { return t->bins[i].p; }
#endif
