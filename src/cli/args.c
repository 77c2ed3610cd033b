/* args.c — owns `valo render`'s argument parsing: the declared options (valo_option_at),
 * the command line's own flags (-o, -q, --help, --help-integrators, --stats-json,
 * --checkpoint, --checkpoint-every, --resume), the default output name, the outputs'
 * formats, AOV prefixes and frame patterns, and the render --help text. No file is
 * touched: main.c checks the folders and renders. */
#include "cli/args.h"
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void usage_render(FILE *f);
void usage_render(FILE *f) {
  fprintf(f,
          "Usage: valo render SCENE [options]\n\n"
          "SCENE is a .json scene file (docs/scene-format.md), a Mitsuba scene (.xml: Mitsuba 3\n"
          "or 0.6; what it holds that valo cannot render is an error or a warning naming the\n"
          "line), or a mesh file read by Assimp (OBJ/MTL, glTF 2.0, PLY, ...; its camera is\n"
          "used, or the view is framed automatically).\n"
          "Options override the scene file:\n"
          "  -o, --output FILE      output image; .exr/.pfm linear float, .hdr Radiance RGBE,\n"
          "                         .png/.jpg 8-bit sRGB;\n"
          "                         repeat for several outputs (default: SCENE-NAME.png);\n"
          "                         albedo:FILE, normal:FILE, depth:FILE write those AOVs,\n"
          "                         ao:FILE ambient occlusion (ao.distance), bent:FILE the bent normal,\n"
          "                         spp:FILE the samples each pixel received\n");
  /* the declared options (one table: their flags, defaults, ranges and help) */
  for (int i = 0; valo_option_at(i); i++) {
    const valo_option_info *o = valo_option_at(i);
    if (!o->flag) continue;
    char head[64];
    snprintf(head, sizeof head, "%s%s%s", o->flag, o->metavar ? " " : "", o->metavar ? o->metavar : "");
    const char *h = o->help;
    int first = 1;
    while (*h) {
      size_t n = strcspn(h, "\n");
      fprintf(f, "  %-22s %.*s\n", first ? head : "", (int)n, h);
      first = 0;
      h += n;
      if (*h) h++;
    }
    if (!strcmp(o->flag, "--integrator")) {
      fprintf(f, "  %-22s one of:", "");
      for (const char *const *n = valo_integrator_names(); *n; n++) fprintf(f, " %s", *n);
      fprintf(f, "\n");
    }
  }
  fprintf(f,
          "  --checkpoint FILE      save the render's state to FILE at pass boundaries (atomically)\n"
          "  --checkpoint-every S   at most every S seconds (default 60; 0: every pass)\n"
          "  --resume FILE          go on from a checkpoint (and keep checkpointing to it);\n"
          "                         the same scene and options; --time is this run's budget\n"
          "  --stats-json FILE      write the run's figures as JSON: load, build and render\n"
          "                         seconds, spp, rays, rays/s, peak memory, lost samples\n"
          "  --help-integrators     the integrators' parameters, with defaults and ranges\n"
          "  --denoise              write the image outputs denoised (their raw images: leave\n"
          "                         this out and name -o denoised:FILE beside them)\n"
          "  -q, --quiet            no progress or summary\n"
          "  -h, --help             this text\n");
}

/* Length of an output's AOV prefix ("albedo:", "normal:", "depth:", "spp:"), or 0. */
size_t aov_prefix(const char *out) {
  static const char *const prefixes[] = {"albedo:", "normal:", "depth:", "ao:", "bent:", "spp:", "denoised:"};
  for (size_t k = 0; k < sizeof prefixes / sizeof prefixes[0]; k++)
    if (!strncmp(out, prefixes[k], strlen(prefixes[k]))) return strlen(prefixes[k]);
  return 0;
}

/* Where the frame number goes in an output name: a "%d" or "%0Nd" (N < 10). Returns the
 * offset of the '%' and the conversion's length in *len, -1 when there is none, -2 when
 * the name has another '%' (not allowed). */
int frame_pattern(const char *name, int *len) {
  const char *p = strchr(name, '%');
  if (!p) return -1;
  const char *q = p + 1;
  if (*q == '0') { q++; if (*q >= '1' && *q <= '9') q++; else return -2; }
  if (*q != 'd' || strchr(q + 1, '%')) return -2;
  *len = (int)(q + 1 - p);
  return (int)(p - name);
}
/* name with its frame pattern replaced by frame f. */
void frame_name(const char *name, int f, char *out, size_t n) {
  int len, at = frame_pattern(name, &len);
  if (at < 0) { snprintf(out, n, "%s", name); return; }
  int width = len > 2 ? name[at + 2] - '0' : 0;
  snprintf(out, n, "%.*s%0*d%s", at, name, width, f, name + at + len);
}

int cli_parse_render(int argc, char **argv, cli_args *ca, FILE *out, FILE *err) {
  memset(ca, 0, sizeof *ca);
  valo_options_init(&ca->opt);
  valo_output_options_init(&ca->oo);
  valo_load_options_init(&ca->lo);
  ca->ckpt_every = 60;
  valo_options *opt = &ca->opt;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    const char *val = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) { usage_render(out); return 0; }
    if (!strcmp(a, "--help-integrators")) {
      char buf[8192];
      for (const char *const *n = valo_integrator_names(); *n; n++)
        if (!valo_integrator_describe(*n, buf, sizeof buf)) fputs(buf, out);
      return 0;
    }
    if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) { ca->quiet = 1; continue; }
    if (!strcmp(a, "--denoise")) { ca->denoise = 1; continue; }
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (!val) { fprintf(err, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      i++;
      if (ca->nout == CLI_MAX_OUTPUTS) { fprintf(err, "valo: at most %d outputs\n", CLI_MAX_OUTPUTS); return EXIT_USAGE; }
      ca->outputs[ca->nout++] = val;
      continue;
    }
    if (!strcmp(a, "--stats-json") || !strcmp(a, "--checkpoint") || !strcmp(a, "--resume") || !strcmp(a, "--checkpoint-every")) {
      if (!val) { fprintf(err, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      i++;
      if (a[2] == 's') ca->stats_json = val;
      else if (a[2] == 'r') ca->resume = val;
      else if (!strcmp(a, "--checkpoint")) ca->ckpt = val;
      else {
        char *end;
        ca->ckpt_every = strtod(val, &end);
        if (end == val || *end || !(ca->ckpt_every >= 0 && ca->ckpt_every <= 1e9)) {
          fprintf(err, "valo: --checkpoint-every: \"%s\" is not a number of seconds from 0 to 1e9\n", val);
          return EXIT_USAGE;
        }
      }
      continue;
    }
    if (!strcmp(a, "-D")) a = "--define"; /* Mitsuba's spelling */
    if (a[0] == '-' && a[1]) {
      /* a declared option (valo_option_at): a flag alone, or a flag and its value */
      const valo_option_info *info = NULL;
      for (int k = 0; valo_option_at(k); k++)
        if (valo_option_at(k)->flag && !strcmp(valo_option_at(k)->flag, a)) info = valo_option_at(k);
      if (!info) { fprintf(err, "valo: unknown option \"%s\" (see valo render --help)\n", a); return EXIT_USAGE; }
      if (info->metavar && !val) { fprintf(err, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      valo_error perr;
      if (valo_option_set(a, info->metavar ? val : NULL, opt, &ca->lo, &ca->oo, &perr)) {
        fprintf(err, "valo: %s: %s\n", a, perr.message);
        return EXIT_USAGE;
      }
      if (info->metavar) i++;
      continue;
    }
    if (!ca->scene_path) ca->scene_path = a;
    else { fprintf(err, "valo: more than one scene given (\"%s\" and \"%s\")\n", ca->scene_path, a); return EXIT_USAGE; }
  }
  if (!ca->scene_path) { fprintf(err, "valo: no scene given\n"); usage_render(err); return EXIT_USAGE; }
  if (opt->noise_threshold != VALO_UNSET && !(opt->adaptive > 0)) {
    opt->adaptive = VALO_ADAPTIVE_ERROR;
    if (!ca->quiet) fprintf(err, "valo: note: --noise-threshold turns on adaptive sampling (--adaptive)\n");
  }
  if (ca->nout == 0) {
    const char *base = strrchr(ca->scene_path, '/');
    base = base ? base + 1 : ca->scene_path;
    const char *dot = strrchr(base, '.');
    int len = dot ? (int)(dot - base) : (int)strlen(base);
    snprintf(ca->default_out, sizeof ca->default_out, "%.*s.png", len, base);
    ca->outputs[ca->nout++] = ca->default_out;
  }
  for (int i = 0; ca->denoise && i < ca->nout; i++) /* --denoise: each image output becomes a denoised one */
    if (!aov_prefix(ca->outputs[i])) {
      snprintf(ca->denoised[i], sizeof ca->denoised[i], "denoised:%s", ca->outputs[i]);
      ca->outputs[i] = ca->denoised[i];
    }
  int aovs = 0; /* the AOVs the outputs ask for */
  for (int i = 0; i < ca->nout; i++) {
    if (aov_prefix(ca->outputs[i]) && strncmp(ca->outputs[i], "spp:", 4)) aovs |= 1;
    if (!strncmp(ca->outputs[i], "ao:", 3) || !strncmp(ca->outputs[i], "bent:", 5)) aovs |= VALO_AOVS_AO;
    if (!strncmp(ca->outputs[i], "denoised:", 9)) aovs |= VALO_AOVS_VARIANCE;
    int plen, pat = frame_pattern(ca->outputs[i], &plen);
    if (pat == -2) { fprintf(err, "valo: %s: a '%%' in an output name must be a frame pattern, %%d or %%04d\n", ca->outputs[i]); return EXIT_USAGE; }
    if (pat >= 0 && opt->frames == VALO_UNSET) { fprintf(err, "valo: %s: a frame pattern needs --frames\n", ca->outputs[i]); return EXIT_USAGE; }
    const char *dot = strrchr(ca->outputs[i], '.');
    static const char *const formats[] = {".exr", ".pfm", ".hdr", ".png", ".jpg", ".jpeg"};
    int known = 0;
    for (size_t k = 0; dot && k < sizeof formats / sizeof formats[0]; k++) known |= !strcasecmp(dot, formats[k]);
    if (!known) {
      fprintf(err, "valo: %s: unknown output format (use .exr, .pfm, .hdr, .png or .jpg)\n", ca->outputs[i]);
      return EXIT_USAGE;
    }
  }
  if (aovs) opt->aovs = aovs;

  return -1;
}

int cli_parse_with_own(int argc, char **argv, const char *const *own, const char **values, cli_args *ca, FILE *err) {
  char **rest = calloc((size_t)argc + 1, sizeof *rest);
  if (!rest) { fprintf(err, "valo: out of memory\n"); return 1; }
  int nrest = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) { free(rest); return CLI_HELP; }
    int k = 0;
    while (own[k] && strcmp(own[k], a)) k++;
    if (!own[k]) { rest[nrest++] = argv[i]; continue; }
    if (i + 1 >= argc) { fprintf(err, "valo: %s needs a value\n", a); free(rest); return EXIT_USAGE; }
    values[k] = argv[++i];
  }
  int rc = cli_parse_render(nrest, rest, ca, stdout, err);
  free(rest);
  return rc;
}
