/* options.h — owns resolving the public render options: the scene file's, then the
 * caller's, then the defaults; every value checked (ranges, names, what the integrator
 * allows); the integrator and its parameters found. */
#ifndef VALO_API_OPTIONS_H
#define VALO_API_OPTIONS_H
#include "integrator/integrator.h"

typedef struct resolved_options {
  valo_options o;                          /* every field set */
  const integrator_ops *integ;             /* the registry entry (path-spectral for --spectral) */
  double param[INTEGRATOR_MAX_PARAMS];     /* its parameter values */
  double ao_distance;                      /* the ao AOV's ray length parameter (ao.distance) */
} resolved_options;

valo_status options_resolve(const valo_options *file, const valo_options *caller, resolved_options *out, valo_error *err);
#endif
