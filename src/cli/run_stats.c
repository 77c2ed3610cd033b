/* run_stats.c — owns the peak-memory figure (getrusage) and the `--stats-json` file:
 * load, build and render seconds, spp, samples, rays, rays/s, peak memory and the lost
 * samples by cause, written as valo writes its images (valo_file_write). */
#include "cli/run_stats.h"
#include "valo/valo.h"
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

uint64_t run_peak_memory(void) {
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru)) return 0;
  return (uint64_t)ru.ru_maxrss * 1024; /* Linux: kilobytes */
}

void json_put_string(FILE *f, const char *s) {
  fputc('"', f);
  for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
    if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
    else if (*p < 0x20) fprintf(f, "\\u%04x", *p);
    else fputc(*p, f);
  }
  fputc('"', f);
}

static void put_report(FILE *f, const run_report *r) {
  const valo_stats *st = r->st;
  fprintf(f, "{\n  \"valo_version\": ");
  json_put_string(f, valo_version());
  fprintf(f, ",\n  \"scene\": ");
  json_put_string(f, r->scene);
  fprintf(f, ",\n  \"status\": ");
  json_put_string(f, r->status);
  fprintf(f, ",\n  \"exit_code\": %d,\n  \"integrator\": ", r->exit_code);
  json_put_string(f, st->integrator);
  fprintf(f, ",\n  \"accel\": ");
  json_put_string(f, st->accel);
  fprintf(f, ",\n  \"threads\": %d,\n  \"width\": %d,\n  \"height\": %d,\n  \"triangles\": %llu,\n", st->threads, st->width, st->height,
          (unsigned long long)st->triangles);
  fprintf(f, "  \"load_seconds\": %.9f,\n  \"build_seconds\": %.9f,\n  \"render_seconds\": %.9f,\n", r->load_seconds, st->build_seconds,
          st->render_seconds);
  fprintf(f, "  \"spp\": %d,\n  \"frames\": %d,\n  \"samples\": %llu,\n  \"rays\": %llu,\n  \"rays_per_second\": %.9g,\n", st->spp_done,
          st->frames_done, (unsigned long long)st->samples, (unsigned long long)st->rays,
          st->render_seconds > 0 ? (double)st->rays / st->render_seconds : 0.0);
  fprintf(f, "  \"peak_memory_bytes\": %llu,\n  \"surface_samples\": %llu,\n  \"lost\": {", (unsigned long long)r->peak_memory,
          (unsigned long long)st->surface_samples);
  for (int k = 0; k < VALO_LOSS_COUNT; k++) {
    fprintf(f, "%s\n    ", k ? "," : "");
    json_put_string(f, valo_loss_name(k));
    fprintf(f, ": %llu", (unsigned long long)st->lost[k]);
  }
  fprintf(f, "\n  }");
  if (r->nranks > 0) {
    fprintf(f, ",\n  \"ranks\": [");
    for (int k = 0; k < r->nranks; k++) {
      const valo_rank_stats *q = &r->ranks[k];
      fprintf(f, "%s\n    {\"rank\": %d, \"host\": ", k ? "," : "", k);
      json_put_string(f, q->host);
      fprintf(f, ", \"threads\": %d, \"tiles\": %llu, \"samples\": %llu, \"rays\": %llu, \"busy_seconds\": %.9f, \"rays_per_second\": %.9g, \"peak_memory_bytes\": %llu}",
              q->threads, (unsigned long long)q->tiles, (unsigned long long)q->samples, (unsigned long long)q->rays, q->busy_seconds,
              q->busy_seconds > 0 ? (double)q->rays / q->busy_seconds : 0.0, (unsigned long long)q->peak_memory_bytes);
    }
    fprintf(f, "\n  ]");
  }
  fprintf(f, "\n}\n");
}

FILE *cli_out_open(cli_out *o, const char *path) {
  o->buf = NULL;
  o->len = 0;
  o->f = open_memstream(&o->buf, &o->len);
  if (!o->f) fprintf(stderr, "valo: error: %s: cannot write: out of memory\n", path);
  return o->f;
}

int cli_out_write(cli_out *o, const char *path) {
  valo_error err;
  int rc = 0;
  if (fclose(o->f) != 0) {
    fprintf(stderr, "valo: error: %s: cannot write: out of memory\n", path);
    rc = -1;
  } else if (valo_file_write(path, o->buf, o->len, &err)) {
    fprintf(stderr, "valo: error: %s\n", err.message);
    rc = -1;
  }
  free(o->buf);
  return rc;
}

int run_stats_write_json(const char *path, const run_report *r) {
  cli_out o;
  if (!cli_out_open(&o, path)) return -1;
  put_report(o.f, r);
  return cli_out_write(&o, path);
}
