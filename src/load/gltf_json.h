/* gltf_json.h — owns the strict JSON reader that gltf_check.c reads glTF with: RFC 8259
 * syntax only (no comments, trailing commas, NaN or numbers past a double's range; a
 * lone surrogate escape is an error), nested at most JSON_MAX_DEPTH deep, the text ending
 * at its first NUL byte as Assimp's parser ends it. Unlike cJSON it keeps whether a number
 * was written as an integer (no fraction or exponent), which is how Assimp's parser decides
 * that a value can be an index. Errors give the line. */
#ifndef VALO_GLTF_JSON_H
#define VALO_GLTF_JSON_H
#include <stddef.h>
#include <stdint.h>

#define JSON_MAX_DEPTH 512 /* glTF nests about 8 deep; this bounds valo's recursion */
typedef enum { J_NULL, J_FALSE, J_TRUE, J_NUM, J_STR, J_ARR, J_OBJ } jtype;
typedef struct jnode {
  jtype t;
  int is_int;        /* a number written as an integer */
  double num;
  const char *key;   /* the member's name (unescaped), in an object; else NULL */
  const char *key_at; /* where that name's opening quote is in the text parsed */
  const char *str;   /* a string's value (unescaped; \u0000 is refused) */
  uint32_t child, next, n; /* node indices (0: none); n: the members or elements */
} jnode;
typedef struct jdoc { jnode *nodes; uint32_t count, cap; char *strs; size_t nstrs; } jdoc;

/* Parses text (len bytes; it ends at a NUL before that). Returns 0 with the root at node
 * 1, or -1 with *line and a message in msg (msg_size bytes). Free with json_free. */
int json_parse(jdoc *d, const char *text, size_t len, size_t *line, char *msg, size_t msg_size);
void json_free(jdoc *d);
/* The first member of object o called key, or 0. */
uint32_t json_get(const jdoc *d, uint32_t o, const char *key);
#endif
