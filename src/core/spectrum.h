/* spectrum.h — owns spectral rendering's colour science (digest 000: "light is a
 * spectrum; solve per wavelength and convert"): hero-wavelength sampling of 4 wavelengths
 * in [380, 720] nm (Wilkie et al. 2014), the CIE 1931 2-degree colour-matching functions
 * (the multi-lobe Gaussian fit of Wyman, Sloan & Shirley 2013), XYZ to linear sRGB, and
 * RGB-to-spectrum upsampling: a smooth three-band partition of unity whose mixing matrix is
 * solved so that RGB -> spectrum -> RGB is the identity and RGB white is the flat spectrum
 * (negative spectral values of very saturated colours are clamped to 0). The film's white
 * is the flat (equal-energy) spectrum; RGB and spectral renders of grey scenes agree. */
#ifndef VALO_SPECTRUM_H
#define VALO_SPECTRUM_H
#include "core/vec.h"

#define LAMBDA_MIN 380.0f
#define LAMBDA_MAX 720.0f
#define N_LAMBDA 4

typedef struct spec4 { float v[N_LAMBDA]; } spec4;
typedef struct wavelengths { float lambda[N_LAMBDA]; float weight[N_LAMBDA]; /* 1/pdf, 0 once terminated */ } wavelengths;

/* The hero wavelength from u, the others spaced by (range / 4), wrapping around. */
wavelengths wavelengths_sample(float u);
/* Keeps only the hero wavelength (at a dispersive interface), weighting it by 4. */
void wavelengths_terminate_secondary(wavelengths *w);
spec4 spec_from_rgb(rgb c, const wavelengths *w);
rgb spec_to_rgb(spec4 L, const wavelengths *w);
static inline spec4 spec_const(float f) { spec4 s = {{f, f, f, f}}; return s; }
static inline spec4 spec_mul(spec4 a, spec4 b) { for (int i = 0; i < N_LAMBDA; i++) a.v[i] *= b.v[i]; return a; }
static inline spec4 spec_add(spec4 a, spec4 b) { for (int i = 0; i < N_LAMBDA; i++) a.v[i] += b.v[i]; return a; }
static inline spec4 spec_scale(spec4 a, float s) { for (int i = 0; i < N_LAMBDA; i++) a.v[i] *= s; return a; }
static inline float spec_max(spec4 a) { float m = a.v[0]; for (int i = 1; i < N_LAMBDA; i++) m = a.v[i] > m ? a.v[i] : m; return m; }
static inline int spec_black(spec4 a) { for (int i = 0; i < N_LAMBDA; i++) if (a.v[i] != 0) return 0; return 1; }
void cie_xyz(float lambda_nm, float *x, float *y, float *z);
/* A quantity tabulated at n >= 1 increasing wavelengths nm[]: linear between points,
 * constant beyond the ends. */
float tab_eval(const float *nm, const float *v, int n, float lambda);
/* Its linear sRGB as the film sees a spectrum (CIE 1931 over [380, 720] nm, white
 * balanced so that a constant c reads (c, c, c)): how RGB mode takes a tabulated
 * conductor index. */
rgb tab_to_rgb(const float *nm, const float *v, int n);
/* Linear sRGB of a spectrum listed at n >= 1 increasing wavelengths (linear between them,
 * 0 outside) as Mitsuba's RGB modes read one: CIE 1931 over [360, 830] nm; a reflectance
 * seen under D65 and divided by D65's Y (a constant 1 reads about (1, 1, 1)), an emitter's
 * (emitter != 0) divided by the equal-energy spectrum's Y (a constant 1 reads about
 * (1.2048, 0.9483, 0.9088)). */
rgb spectrum_list_to_rgb(const float *nm, const float *v, int n, int emitter);

/* Dispersion (digest 000, thesis table 2.1): index of refraction at wavelength lambda. */
typedef enum dispersion { DISP_NONE, DISP_FUSED_SILICA, DISP_SAPPHIRE, DISP_WATER, DISP_CAUCHY_GLASS, DISP_DENSE_FLINT } dispersion;
int dispersion_parse(const char *name, dispersion *d);
float dispersion_ior(dispersion d, float lambda_nm);
#endif
