/* report.c — see report.h. index.html is self-contained: no script, no network; its
 * images are the PNGs beside it, its plot an SVG drawn here (relMSE against seconds, both
 * on log axes, a polyline per integrator through the moments compare.c kept). */
#include "cli/report.h"
#include "cli/run_stats.h"
#include "valo/valo.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#000000", "#aec7e8"};

static void put_html(FILE *f, const char *s) {
  for (; *s; s++) {
    if (*s == '<') fputs("&lt;", f);
    else if (*s == '>') fputs("&gt;", f);
    else if (*s == '&') fputs("&amp;", f);
    else if (*s == '"') fputs("&quot;", f);
    else fputc(*s, f);
  }
}

/* dir/name, made in memory and written by cli_out_write (run_stats.h). */
static FILE *open_in(cli_out *o, char *path, size_t n, const char *dir, const char *name) {
  snprintf(path, n, "%s/%s", dir, name);
  return cli_out_open(o, path);
}

/* The width an image is shown at: small films scaled up by a whole factor (pixelated) to
 * at least 240 pixels, large ones down to 400. */
static int shown_width(int w) {
  if (w >= 240) return w > 400 ? 400 : w;
  return w * ((240 + w - 1) / w);
}

static const char *ref_name(const cmp_report *r) { return r->reference[0] ? r->reference : r->runs[r->ref_run - 1].name; }

int report_write_summary(const cmp_report *r, const char *dir) {
  cli_out o;
  char path[4400];
  FILE *f = open_in(&o, path, sizeof path, dir, "summary.json");
  if (!f) return -1;
  fprintf(f, "{\n  \"scene\": ");
  json_put_string(f, r->scene);
  fprintf(f, ",\n  \"budget\": {\"seconds\": %.9g, \"spp\": %d},\n  \"reference\": ", r->time_budget, r->spp_budget);
  json_put_string(f, ref_name(r));
  fprintf(f, ",\n  \"reference_is_a_render\": %s,\n  \"crop\": [%d, %d, %d, %d],\n  \"integrators\": [", r->reference[0] ? "false" : "true", r->crop[0],
          r->crop[1], r->crop[2], r->crop[3]);
  for (int k = 0; k < r->nruns; k++) {
    const cmp_run *u = &r->runs[k];
    char image[64];
    snprintf(image, sizeof image, "%s.exr", u->name);
    fprintf(f, "%s\n    {\"name\": ", k ? "," : "");
    json_put_string(f, u->name);
    fprintf(f, ", \"image\": ");
    json_put_string(f, image);
    fprintf(f, ", \"seconds\": %.9g, \"spp\": %d, \"rays\": %llu, \"rays_per_second\": %.9g, \"relmse\": %.9g, \"mean_bias\": %.9g,\n     \"curve\": [",
            u->seconds, u->spp, (unsigned long long)u->rays, u->seconds > 0 ? (double)u->rays / u->seconds : 0.0, u->relmse, u->bias);
    for (int s = 0; s < u->nsnap; s++)
      fprintf(f, "%s{\"seconds\": %.9g, \"spp\": %d, \"relmse\": %.9g}", s ? ", " : "", u->snap_t[s], u->snap_spp[s], u->snap_err[s]);
    fprintf(f, "]}");
  }
  fprintf(f, "\n  ]\n}\n");
  return cli_out_write(&o, path);
}

/* The relMSE-against-time plot: log10 axes over the decades the curves span. */
static void put_svg(FILE *f, const cmp_report *r) {
  double t0 = 1e300, t1 = 0, e0 = 1e300, e1 = 0;
  for (int k = 0; k < r->nruns; k++)
    for (int s = 0; s < r->runs[k].nsnap; s++) {
      double t = r->runs[k].snap_t[s], e = r->runs[k].snap_err[s];
      if (!(t > 0) || !(e > 0)) continue;
      t0 = t < t0 ? t : t0; t1 = t > t1 ? t : t1;
      e0 = e < e0 ? e : e0; e1 = e > e1 ? e : e1;
    }
  const int W = 640, H = 400, L = 70, R = 150, T = 20, B = 50;
  fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H, W, H);
  fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#444\"/>\n", L, T, W - L - R, H - T - B);
  if (!(t1 > 0) || !(e1 > 0)) {
    fprintf(f, "<text x=\"%d\" y=\"%d\">no error to plot (every image equals the reference)</text>\n</svg>\n", L + 10, T + 30);
    return;
  }
  double lt0 = floor(log10(t0)), lt1 = ceil(log10(t1)), le0 = floor(log10(e0)), le1 = ceil(log10(e1));
  if (lt1 <= lt0) lt1 = lt0 + 1;
  if (le1 <= le0) le1 = le0 + 1;
#define PX(t) (L + (log10(t) - lt0) / (lt1 - lt0) * (W - L - R))
#define PY(e) (H - B - (log10(e) - le0) / (le1 - le0) * (H - T - B))
  for (double d = lt0; d <= lt1; d++) {
    double x = PX(pow(10, d));
    fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/><text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%g s</text>\n", x, T, x,
            H - B, x, H - B + 16, pow(10, d));
  }
  for (double d = le0; d <= le1; d++) {
    double y = PY(pow(10, d));
    fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/><text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">1e%d</text>\n", L, y, W - R,
            y, L - 6, y + 4, (int)d);
  }
  fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">render time (seconds, log)</text>\n", L + (W - L - R) / 2, H - 12);
  fprintf(f, "<text x=\"16\" y=\"%d\" transform=\"rotate(-90 16 %d)\" text-anchor=\"middle\">relMSE (log)</text>\n", T + (H - T - B) / 2,
          T + (H - T - B) / 2);
  for (int k = 0; k < r->nruns; k++) {
    const cmp_run *u = &r->runs[k];
    const char *c = colours[k % (int)(sizeof colours / sizeof *colours)];
    fprintf(f, "<polyline class=\"curve\" data-name=\"%s\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", u->name, c);
    for (int s = 0; s < u->nsnap; s++)
      if (u->snap_t[s] > 0 && u->snap_err[s] > 0) fprintf(f, "%.1f,%.1f ", PX(u->snap_t[s]), PY(u->snap_err[s]));
    fprintf(f, "\"/>\n");
    for (int s = 0; s < u->nsnap; s++)
      if (u->snap_t[s] > 0 && u->snap_err[s] > 0) fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.5\" fill=\"%s\"/>\n", PX(u->snap_t[s]), PY(u->snap_err[s]), c);
    fprintf(f, "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"3\"/><text x=\"%d\" y=\"%d\">%s</text>\n", W - R + 12, T + 14 + 18 * k,
            W - R + 32, T + 14 + 18 * k, c, W - R + 38, T + 18 + 18 * k, u->name);
  }
#undef PX
#undef PY
  fprintf(f, "</svg>\n");
}

/* One row of figures: every integrator's NAME<suffix>.png, captioned with its name;
 * scaled: shown at shown_width (the crops are shown at their own 4x size). */
static void put_figures(FILE *f, const cmp_report *r, const char *suffix, int scaled) {
  fprintf(f, "<div>\n");
  for (int k = 0; k < r->nruns; k++) {
    const char *name = r->runs[k].name;
    fprintf(f, "<figure><img src=\"%s%s.png\"", name, suffix);
    if (scaled) fprintf(f, " width=\"%d\"", shown_width(r->runs[k].w));
    fprintf(f, " alt=\"%s%s\"><figcaption>%s</figcaption></figure>\n", name, suffix, name);
  }
  fprintf(f, "</div>\n");
}

int report_write_html(const cmp_report *r, const char *dir) {
  cli_out o;
  char path[4400];
  FILE *f = open_in(&o, path, sizeof path, dir, "index.html");
  if (!f) return -1;
  fprintf(f, "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>valo compare: ");
  put_html(f, r->scene);
  fprintf(f, "</title>\n<style>body{font-family:sans-serif;margin:16px;}table{border-collapse:collapse;}td,th{border:1px solid #ccc;padding:4px 8px;"
             "text-align:right;}th{background:#eee;}figure{display:inline-block;margin:4px;text-align:center;}img{image-rendering:pixelated;}"
             "figcaption{font-size:13px;}</style></head>\n<body>\n<h1>valo compare</h1>\n<p>Scene <code>");
  put_html(f, r->scene);
  if (r->time_budget > 0) fprintf(f, "</code>, equal time: %g s per integrator.", r->time_budget);
  else fprintf(f, "</code>, equal samples: %d spp per integrator.", r->spp_budget);
  fprintf(f, " Reference: ");
  if (r->reference[0]) { fprintf(f, "the file <code>"); put_html(f, r->reference); fprintf(f, "</code>.</p>\n"); }
  else fprintf(f, "<b>no reference was given: the errors are against the longest render, <code>%s</code></b> (its own error is 0).</p>\n",
               r->runs[r->ref_run - 1].name);
  fprintf(f, "<p>relMSE: the mean over pixels and channels of (x &minus; r)&sup2; / (r&sup2; + 0.01). Mean bias: (mean(x) &minus; mean(r)) / mean(r).</p>\n");
  fprintf(f, "<table id=\"figures\">\n<tr><th>integrator</th><th>seconds</th><th>spp</th><th>Mrays/s</th><th>relMSE</th><th>mean bias</th></tr>\n");
  for (int k = 0; k < r->nruns; k++) {
    const cmp_run *u = &r->runs[k];
    fprintf(f, "<tr data-name=\"%s\"><td style=\"text-align:left\">%s</td><td class=\"seconds\">%.3f</td><td class=\"spp\">%d</td><td>%.3f</td>"
               "<td class=\"relmse\">%.6g</td><td class=\"bias\">%+.4f</td></tr>\n",
            u->name, u->name, u->seconds, u->spp, u->seconds > 0 ? (double)u->rays / u->seconds * 1e-6 : 0.0, u->relmse, u->bias);
  }
  fprintf(f, "</table>\n<h2>Images</h2>\n");
  put_figures(f, r, "", 1);
  fprintf(f, "<h2>Crop: x %d, y %d, %d &times; %d pixels, 4&times;</h2>\n", r->crop[0], r->crop[1], r->crop[2], r->crop[3]);
  put_figures(f, r, "_crop", 0);
  fprintf(f, "<h2>Per-pixel error</h2>\n<p>log<sub>10</sub> of the pixel's relative squared error from 10<sup>&minus;4</sup> (dark blue) "
             "to 1 (yellow).</p>\n");
  put_figures(f, r, "_error", 1);
  fprintf(f, "<h2>relMSE against time</h2>\n");
  put_svg(f, r);
  fprintf(f, "<p>Made by valo %s.</p>\n</body></html>\n", valo_version());
  return cli_out_write(&o, path);
}
