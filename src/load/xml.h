/* xml.h — owns a small XML reader for scene files: elements with attributes and
 * children, each with its line; comments, the prolog and whitespace are skipped, the five
 * named entities and numeric character references are decoded. Not a general XML
 * parser: no DTDs, CDATA or processing instructions inside the document (errors that
 * name the line). */
#ifndef VALO_XML_H
#define VALO_XML_H
#include "valo/valo.h"
#include <stddef.h>

typedef struct xml_attr { char *name, *value; } xml_attr;

typedef struct xml_node {
  char *name;
  xml_attr *attrs;
  int nattrs;
  struct xml_node *child, *next, *parent; /* children in document order */
  int line, col; /* where its start tag opens */
  int used; /* set by a reader that took this node's meaning (unused ones are warned about) */
  const char *file; /* the file it was read from, when a reader spliced it in from another
                       (Mitsuba's <include>); NULL: the document's own */
} xml_node;

/* Parses text (len bytes, NUL-terminated) into a tree whose root is the document's one
 * element; errors name path and line:column. Free with xml_free. */
valo_status xml_parse(const char *path, const char *text, size_t len, xml_node **root, valo_error *err);
void xml_free(xml_node *n);
/* The attribute's value, or NULL. */
const char *xml_attr_get(const xml_node *n, const char *name);
#endif
