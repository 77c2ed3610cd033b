/* load_mitsuba_doc.c — owns a Mitsuba scene document's structure before its elements are
 * read (load_mitsuba.c): 0.6's camelCase names, <include> (files spliced in, their
 * elements marked with the file they came from), <path> (folders to find files in), <default> values with the command
 * line's --define, $name substitution, and the check that every <ref> names an element. */
#include "load/load_json_internal.h"
#include "load/mitsuba_internal.h"
#include "core/error.h"
#include "core/grow.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Mitsuba 0.6 names: camelCase becomes snake_case ("toWorld" -> "to_world", "intIOR" -> "int_ior").
 * A <default>'s name is the file's own parameter ($photonCount), not a property: kept. */
static void upgrade_names(xml_node *n) {
  for (; n; n = n->next) {
    for (int i = 0; i < n->nattrs && strcmp(n->name, "default"); i++) {
      if (strcmp(n->attrs[i].name, "name")) continue;
      const char *v = n->attrs[i].value;
      char *o = malloc(2 * strlen(v) + 1), *q = o;
      if (!o) continue;
      for (const char *p = v; *p; p++) {
        if (isupper((unsigned char)*p) && p > v && (islower((unsigned char)p[-1]) || isdigit((unsigned char)p[-1]))) *q++ = '_';
        *q++ = (char)tolower((unsigned char)*p);
      }
      *q = 0;
      free(n->attrs[i].value);
      n->attrs[i].value = o;
    }
    if (!strcmp(n->name, "lookAt")) { free(n->name); n->name = strdup("lookat"); }
    upgrade_names(n->child);
  }
}

/* Marks every element of the tree at n (n's siblings too) as read from file. */
static void set_file(xml_node *n, const char *file) {
  for (; n; n = n->next) {
    n->file = file;
    set_file(n->child, file);
  }
}

/* Mitsuba's <include filename="..."/>, at any depth: the element is replaced by the
 * file's content, its root's children when the root is <scene>, else the root itself
 * (each file's names upgraded by its own version). As Mitsuba's file resolver does, a
 * relative name is found from the main file's folder, in every included file too (so
 * are the meshes and textures they name); at most MI_INCLUDE_DEPTH levels deep and
 * MI_INCLUDE_FILES inclusions in all (Mitsuba has only the first bound; the second keeps
 * a file that includes the next one twice, fifteen times over, from growing without end). */
/* Mitsuba's <path value="folder"/>, a child of a file's <scene>: relative file names read
 * after it are looked for in that folder first (mi_resolve). A relative folder is found
 * from the folder of the file that names it, else as a file name is. */
static valo_status read_path(mctx *c, const xml_node *parent, const xml_node *n) {
  if (strcmp(parent->name, "scene") || parent->parent) return mi_bad(c, n, "a <path> must be a child of <scene>");
  const char *v = xml_attr_get(n, "value");
  if (!v || !*v) return mi_bad(c, n, "needs a value (a folder)");
  if (strchr(v, '$')) return mi_bad(c, n, "a $parameter in a <path> is not read");
  char *cand = mi_beside(mi_file(c, n), v), **k;
  struct stat sb;
  if (cand && v[0] != '/' && stat(cand, &sb)) { free(cand); cand = mi_resolve(c, v); }
  if (!cand) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  char *abs = realpath(cand, NULL);
  if (!abs || stat(abs, &sb) || !S_ISDIR(sb.st_mode)) {
    valo_status st = mi_bad(c, n, "%s is not a folder", cand);
    free(cand);
    free(abs);
    return st;
  }
  free(cand);
  if (!(k = grow_for(c->search, (size_t)c->nsearch, sizeof *k))) { free(abs); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
  c->search = k;
  c->search[c->nsearch++] = abs;
  return VALO_OK;
}

#define MI_INCLUDE_DEPTH 15
#define MI_INCLUDE_FILES 4096
static valo_status expand_includes(mctx *c, xml_node *parent, int depth) {
  for (xml_node **pp = &parent->child; *pp;) {
    xml_node *n = *pp;
    if (!strcmp(n->name, "path")) { /* read here, in document order, so that the <include>s after it see it */
      TRY(read_path(c, parent, n));
      *pp = n->next;
      n->next = NULL;
      xml_free(n);
      continue;
    }
    if (strcmp(n->name, "include")) {
      TRY(expand_includes(c, n, depth));
      pp = &n->next;
      continue;
    }
    const char *f = xml_attr_get(n, "filename");
    if (!f || !*f) return mi_bad(c, n, "needs a filename");
    if (strchr(f, '$')) return mi_bad(c, n, "a $parameter in an included file's name is not read");
    if (depth >= MI_INCLUDE_DEPTH) return mi_bad(c, n, "includes nested more than %d deep (does a file include itself?)", MI_INCLUDE_DEPTH);
    if (c->nincluded >= MI_INCLUDE_FILES) return mi_bad(c, n, "more than %d files included", MI_INCLUDE_FILES);
    char *path = mi_resolve(c, f), **inc = grow_for(c->included, (size_t)c->nincluded, sizeof *inc);
    if (inc) c->included = inc;
    if (!path || !inc) { free(path); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
    c->included[c->nincluded++] = path;
    struct stat sb;
    if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode)) return mi_bad(c, n, "%s is not a file", path);
    char *text;
    size_t tl;
    xml_node *r = NULL;
    valo_status st = scene_text_read(path, &text, &tl, c->err);
    if (!st && (c->included_bytes += tl) > MI_INCLUDE_BYTES) {
      free(text);
      return mi_bad(c, n, "the files included come to more than %u MiB in all (at %s, included %d times so far)", MI_INCLUDE_BYTES >> 20, path,
                    c->nincluded);
    }
    if (!st) {
      st = xml_parse(path, text, tl, &r, c->err);
      free(text);
    }
    if (st) {
      size_t ml = strlen(c->err->message);
      snprintf(c->err->message + ml, sizeof c->err->message - ml, " (the <include> at %s:%d)", mi_file(c, n), n->line);
      return st;
    }
    set_file(r, path);
    const char *ver = xml_attr_get(r, "version");
    int whole = !strcmp(r->name, "scene");
    if (ver && atoi(ver) < 2) upgrade_names(whole ? r->child : r);
    if (whole) {
      st = expand_includes(c, r, depth + 1);
    } else {
      /* the root as the only child of a stand-in, so that it can be replaced in turn */
      xml_node hold = {.name = "", .child = r};
      r->parent = &hold;
      st = expand_includes(c, &hold, depth + 1);
      r = hold.child;
    }
    if (st) { xml_free(r); return st; }
    xml_node *first = whole ? r->child : r, *last = NULL;
    if (whole) { r->child = NULL; xml_free(r); }
    for (xml_node *k = first; k; k = k->next) { k->parent = parent; last = k; }
    *pp = first ? first : n->next;
    if (last) last->next = n->next;
    n->next = NULL;
    xml_free(n);
    if (last) pp = &last->next;
  }
  return VALO_OK;
}

/* The command line's NAME=VALUE for name (length n), or NULL: *len gets the value's length. */
static const char *define_of(const char *defines, const char *name, size_t n, size_t *len) {
  for (const char *p = defines; p && *p;) {
    while (*p == ' ') p++;
    const char *eq = strchr(p, '='), *end = strchr(p, ' ');
    if (!end) end = p + strlen(p);
    if (eq && eq < end && (size_t)(eq - p) == n && !strncmp(p, name, n)) { *len = (size_t)(end - eq - 1); return eq + 1; }
    p = end;
  }
  return NULL;
}

typedef struct { const char *name, *value; } mdef;

/* Replaces $name in every attribute of n and of the elements inside it (not its next
 * siblings) with its <default>'s value. */
static valo_status substitute(mctx *c, xml_node *n, const mdef *d, int nd) {
  for (int i = 0; i < n->nattrs; i++) {
    char *v = n->attrs[i].value;
    if (!strchr(v, '$')) continue;
    size_t cap = strlen(v) + 1, len = 0;
    char *o = malloc(cap);
    if (!o) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    for (const char *p = v; *p;) {
      const char *add = p;
      size_t alen = 1;
      int made = *p == '$'; /* text made by substitution, counted against MI_SUBST_BYTES */
      if (made) {
        const char *e = p + 1;
        while (isalnum((unsigned char)*e) || *e == '_') e++;
        int k;
        for (k = 0; k < nd; k++)
          if (strlen(d[k].name) == (size_t)(e - p - 1) && !strncmp(d[k].name, p + 1, (size_t)(e - p - 1))) break;
        if (k < nd) {
          add = d[k].value;
          alen = strlen(add);
        } else if (!(add = define_of(c->defines, p + 1, (size_t)(e - p - 1), &alen))) {
          free(o);
          int nl = (int)(e - p - 1 > 60 ? 60 : e - p - 1);
          return mi_bad(c, n, "$%.*s has no <default name=\"%.*s\"> (or --define %.*s=VALUE)", nl, p + 1, nl, p + 1, nl, p + 1);
        }
        p = e;
      } else {
        p++;
      }
      if (made && (c->substituted_bytes += alen) > MI_SUBST_BYTES) {
        free(o);
        return mi_bad(c, n, "$name substitution makes more than %u MiB of attribute text in all", MI_SUBST_BYTES >> 20);
      }
      if (len + alen + 1 > cap) {
        cap = 2 * (len + alen + 1);
        if (cap > (1u << 20)) { free(o); return mi_bad(c, n, "an attribute grows past 1 MiB by substitution"); }
        char *t = realloc(o, cap);
        if (!t) { free(o); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
        o = t;
      }
      memcpy(o + len, add, alen);
      len += alen;
    }
    o[len] = 0;
    free(v);
    n->attrs[i].value = o;
  }
  for (xml_node *k = n->child; k; k = k->next) TRY(substitute(c, k, d, nd));
  return VALO_OK;
}

/* Every <ref> names an element that exists. */
static valo_status check_refs(mctx *c, xml_node *n) {
  for (; n; n = n->next) {
    if (!strcmp(n->name, "ref")) {
      const char *id = xml_attr_get(n, "id");
      if (!id) return mi_bad(c, n, "needs an id");
      if (!mi_find_id(c, id)) return mi_bad(c, n, "refers to an id that no element has");
    }
    TRY(check_refs(c, n->child));
  }
  return VALO_OK;
}

valo_status mi_document_prepare(mctx *c) {
  xml_node *r = c->root;
  if (strcmp(r->name, "scene")) return mi_bad(c, r, "the root element of a Mitsuba scene is <scene>");
  const char *ver = xml_attr_get(r, "version");
  if (ver && atoi(ver) < 2) upgrade_names(r->child);
  TRY(expand_includes(c, r, 0));
  mdef defs[256];
  int nd = 0;
  for (xml_node *k = r->child; k; k = k->next) {
    if (strcmp(k->name, "default")) continue;
    const char *nm = xml_attr_get(k, "name"), *v = xml_attr_get(k, "value");
    if (!nm || !v) return mi_bad(c, k, "needs name and value");
    if (nd == 256) return mi_bad(c, k, "more than 256 defaults");
    size_t dl;
    const char *dv = define_of(c->defines, nm, strlen(nm), &dl);
    if (dv) {
      /* the command line's value replaces the file's (kept in the node, freed with it) */
      char *cp = malloc(dl + 1);
      if (!cp) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
      memcpy(cp, dv, dl);
      cp[dl] = 0;
      for (int i = 0; i < k->nattrs; i++)
        if (!strcmp(k->attrs[i].name, "value")) { free(k->attrs[i].value); k->attrs[i].value = cp; v = cp; }
    }
    defs[nd].name = nm; defs[nd].value = v;
    nd++;
    k->used = 1;
  }
  /* The values point into <default> nodes, which substitution does not rewrite ($ in a
   * default's own value is not expanded, as in Mitsuba). */
  for (xml_node *k = r->child; k; k = k->next)
    if (strcmp(k->name, "default")) TRY(substitute(c, k, defs, nd));
  TRY(mi_index_ids(c));
  TRY(check_refs(c, r->child));
  return VALO_OK;
}
