/* options.h — owns the one declared table of render options: each option's command-line
 * flag, its key in a JSON scene file, the field it sets (valo_options, valo_load_options
 * or valo_output_options), its type, default, range or names, and its help. The command
 * line (through valo_option_at / valo_option_set), the JSON loader, option resolution and
 * validation (src/api/options.c), --help and the docs test all read this table, so an
 * option is added in one place. It sits in core/ because both the loaders and the API
 * read it, and neither may include the other. */
#ifndef VALO_CORE_OPTIONS_H
#define VALO_CORE_OPTIONS_H
#include "valo/valo.h"
#include <stddef.h>

typedef enum opt_target { OPT_RENDER, OPT_LOAD, OPT_OUTPUT } opt_target;
typedef enum opt_type {
  OPT_INT,     /* int */
  OPT_INT64,   /* int64_t */
  OPT_REAL,    /* double */
  OPT_FLOAT,   /* float */
  OPT_NAME,    /* char[size]: one of `names` (or, with names NULL, any text) */
  OPT_CHOICE,  /* int: index of the value in `names`, plus choice_base */
  OPT_FLAG,    /* int set to `hi` by the flag alone (no value) */
  OPT_SIZE,    /* "WxH" into width and height (two ints from offset) */
  OPT_RECT,    /* "X,Y,W,H" into four ints from offset */
  OPT_PARAMS   /* char[size]: "name=value" entries, appended */
} opt_type;

typedef struct option_decl {
  valo_option_info info;  /* flag, metavar, JSON key, help (the public view) */
  opt_target target;
  opt_type type;
  size_t offset, size;    /* the field in the target struct; size of text fields */
  double lo, hi;          /* numbers: the range (OPT_FLAG: the value it sets) */
  double def;             /* the default when neither file nor caller set it */
  const char *def_text;   /* OPT_NAME: the default name */
  int keep_unset;         /* 1: no default; unset means "the scene's" or "none" */
  double unset;           /* numbers: the "not given" value (VALO_UNSET, or
                             VALO_DEPTH_UNSET for max_depth) */
  const char *names;      /* OPT_NAME / OPT_CHOICE: "a|b|c" */
  int choice_base;        /* OPT_CHOICE: the value of the first name */
  const char *range_text; /* what a valid value is, for messages ("a whole number from 1 to 1048576") */
} option_decl;

/* The table, ended by an entry with a NULL flag and NULL JSON key. */
extern const option_decl option_table[];
/* The entry with this flag ("--spp") or JSON key ("render.spp"), or NULL. */
const option_decl *option_find_flag(const char *flag);
const option_decl *option_find_json(const char *key);
/* Sets option d from text into the struct of its target (the others may be NULL).
 * Errors name what a valid value is; the caller prefixes the flag or the file and key. */
valo_status option_set(const option_decl *d, const char *value, valo_options *ro, valo_load_options *lo, valo_output_options *oo,
                       valo_error *err);
/* Whether option d is set in o (a render option), and its value as a double (numbers). */
int option_is_set(const option_decl *d, const valo_options *o);
/* Copies option d from src to dst (render options; OPT_PARAMS appends). */
void option_copy(const option_decl *d, valo_options *dst, const valo_options *src);
/* Every option of target in o (a valo_options, valo_load_options or valo_output_options)
 * to its "not given" value, names and text empty (init), or to its default (default: the
 * load and output options, which have no file to come from). */
void options_init_target(opt_target target, void *o);
void options_default_target(opt_target target, void *o);
/* Sets option d in o to its default (when it has one). */
void option_default(const option_decl *d, valo_options *o);
/* Checks a set render option against its range or names: VALO_OK or an error naming it. */
valo_status option_check(const option_decl *d, const valo_options *o, valo_error *err);
#endif
