/* output.h — owns writing a session's outputs: the image (through the output options'
 * exposure, tone curve and bloom for PNG) and the AOV and sample-count images named by
 * their prefixes (aov.h). Data AOVs written as PNG are mapped into a visible range and
 * stored linearly (docs/integrators.md). */
#ifndef VALO_OUTPUT_H
#define VALO_OUTPUT_H
#include "render/session.h"

/* One layer of the film into px (width*height*3 floats): "" the image, or an AOV named by
 * its prefix without the colon ("albedo" ... "spp"). */
valo_status output_layer(const session *ss, const char *layer, float *px, valo_error *err);
valo_status output_write(const session *ss, const char *path, const valo_output_options *o, valo_error *err);
#endif
