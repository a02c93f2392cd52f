/* ob_json_read.h — reading a JSON document (cJSON) against a schema, with
 * errors that say where: the file, the JSON path of the offending value and
 * what was expected, e.g.
 *   scene.json: entities[3].transform.scale: expected a number or 3 numbers
 * or, for a syntax error, the line and column:
 *   scene.json:12:7: invalid JSON near '}, "camera": {'
 *
 * A reader tracks the path of the value being read (push a key or an index,
 * read it, pop) and keeps the first error: every function returns false (or
 * NULL) once something is wrong, and later failures never overwrite the
 * first message. Optional members (ob_json_opt_*) leave *out untouched when
 * the key is absent, so the caller presets the default.
 *
 * Lifecycle: ob_json_reader_init → ob_json_parse → check and read →
 * cJSON_Delete(root). Internal to the views layer (the scene-file parser
 * uses it); not installed, so cJSON never reaches a program's include path.
 * Thread rule: [any thread], one reader per thread; cJSON's global error
 * pointer is never used, and its allocation hooks are changed only through
 * ob_json_hook_allocations (the program's choice: ob_scene_file_hook_cjson).
 */
#ifndef OB_JSON_READ_H
#define OB_JSON_READ_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ob_core.h"
#include "ob_scene_file.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

/* The error report is the scene file's public one (ob_scene_file.h): this
 * reader is internal to the views layer and not installed, so the struct a
 * program reads must live in the installed header. */
typedef ob_scene_file_error ob_json_error;

typedef struct ob_json_reader {
    const char *file;        /* names the document in messages; not copied */
    ob_json_error *err;      /* where the first error goes; never NULL after init */
    ob_result result;        /* OB_OK until the first error */
    char path[sizeof ((ob_json_error *)0)->json_path];
    size_t len;
    ob_json_error own_err;   /* used when the caller gives no error struct */
} ob_json_reader;

typedef enum ob_json_num_kind {
    OB_JSON_NUM_ANY,
    OB_JSON_NUM_POSITIVE,      /* > 0 */
    OB_JSON_NUM_NON_NEGATIVE,  /* >= 0 */
    OB_JSON_NUM_RANGE,         /* lo..hi inclusive */
    OB_JSON_NUM_INT,           /* an integer in lo..hi */
} ob_json_num_kind;

/* What a number must be (it must always be finite: 1e400 parses as Inf). */
typedef struct ob_json_rule {
    ob_json_num_kind kind;
    double lo, hi;
} ob_json_rule;

#define OB_JSON_ANY ((ob_json_rule){OB_JSON_NUM_ANY, 0, 0})
#define OB_JSON_POSITIVE ((ob_json_rule){OB_JSON_NUM_POSITIVE, 0, 0})
#define OB_JSON_NON_NEGATIVE ((ob_json_rule){OB_JSON_NUM_NON_NEGATIVE, 0, 0})
#define OB_JSON_RANGE(lo, hi) ((ob_json_rule){OB_JSON_NUM_RANGE, (lo), (hi)})
#define OB_JSON_INT(lo, hi) ((ob_json_rule){OB_JSON_NUM_INT, (lo), (hi)})

/* file: the document's name in messages (NULL → "document"); err may be NULL. */
void ob_json_reader_init(ob_json_reader *rd, const char *file, ob_json_error *err);

/* Parses `size` bytes (need not be NUL-terminated). A NUL byte inside, an
 * empty (all blank) text, trailing text after the value and any syntax error
 * fail with the line and column. Returns the root (cJSON_Delete it) or NULL
 * with the error set (OB_ERR_PARSE, or OB_ERR_OUT_OF_HOST_MEMORY). */
cJSON *ob_json_parse(ob_json_reader *rd, const char *text, size_t size);

/* cJSON_InitHooks with ob_malloc/ob_free, once per process (the ob_once
 * "cJSON hooks" listed in ob_core.h). [any thread] */
void ob_json_hook_allocations(void);

/* Records an error at the current path (the first one only); returns false. */
bool ob_json_fail(ob_json_reader *rd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
bool ob_json_out_of_memory(ob_json_reader *rd);

/* Path steps: push returns a mark for ob_json_pop. Keys that are not plain
 * identifiers show as ["key"] (escaped, shortened). */
size_t ob_json_push_key(ob_json_reader *rd, const char *key);
size_t ob_json_push_index(ob_json_reader *rd, uint32_t index);
void ob_json_pop(ob_json_reader *rd, size_t mark);

/* "a number", "an object", ... for messages. */
const char *ob_json_type_name(const cJSON *j);

/* j must be an object (else "expected <what>, got <type>") whose keys are
 * all among keys[0..n) (n <= 32), each at most once. An unknown key fails
 * at its own path, naming the expected keys and the closest one. */
bool ob_json_check_object(ob_json_reader *rd, const cJSON *j, const char *what,
                          const char *const *keys, uint32_t n);
/* Records "KEY: missing (expected <what>)"; returns false. */
bool ob_json_missing(ob_json_reader *rd, const char *key, const char *what);
/* The member (case-sensitive) or NULL. */
const cJSON *ob_json_member(const cJSON *obj, const char *key);

/* Values at the current path. float32 also requires single-precision range. */
bool ob_json_number(ob_json_reader *rd, const cJSON *j, ob_json_rule rule, bool float32, double *out);
/* A non-empty string of printable UTF-8 ("expected <what>" otherwise: a
 * control character such as a terminal escape, or invalid UTF-8, is
 * refused); NULL on error. */
const char *ob_json_string(ob_json_reader *rd, const cJSON *j, const char *what);
/* False (recorded) unless s is printable UTF-8: no C0/C1 control character,
 * no invalid or overlong sequence. */
bool ob_json_check_text(ob_json_reader *rd, const char *s, const char *what);
/* An array of min_n..max_n numbers, each per rule, into out[0..n). */
bool ob_json_vector(ob_json_reader *rd, const cJSON *j, uint32_t min_n, uint32_t max_n,
                    ob_json_rule rule, bool float32, double *out, uint32_t *out_n);

/* Optional members of obj; absent keys leave *out as it was. */
bool ob_json_opt_double(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                        double *out);
bool ob_json_opt_float(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       float *out);
bool ob_json_opt_u32(ob_json_reader *rd, const cJSON *obj, const char *key, uint32_t lo, uint32_t hi,
                     uint32_t *out);
bool ob_json_opt_bool(ob_json_reader *rd, const cJSON *obj, const char *key, bool *out);
bool ob_json_opt_vec3d(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       double out[3]);
bool ob_json_opt_vec3f(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       float out[3]);
/* A number (copied to all three) or 3 numbers. */
bool ob_json_opt_number_or_vec3(ob_json_reader *rd, const cJSON *obj, const char *key,
                                ob_json_rule rule, float out[3]);
/* 3 or 4 numbers >= 0; a missing fourth is `w`. */
bool ob_json_opt_color(ob_json_reader *rd, const cJSON *obj, const char *key, float w, float out[4]);

/* Scales a vector of n doubles to unit length without overflowing; false
 * (v unchanged) if it is zero or not finite. */
bool ob_json_normalize(double *v, int n);
/* 3 numbers, not all zero, stored at unit length. */
bool ob_json_opt_direction(ob_json_reader *rd, const cJSON *obj, const char *key, double out[3]);

/* Names → indices, for values that refer to others by name (hashed, so a
 * document with many names stays linear). Keys are not copied: they must
 * outlive the map (strings of the parsed document do). */
typedef struct ob_json_names {
    const char **keys;
    uint32_t *values;
    uint32_t cap;   /* power of two; 0 before init */
} ob_json_names;

/* Room for n names; false (out of memory recorded in rd) on failure. Release
 * even after a failed init. */
bool ob_json_names_init(ob_json_reader *rd, ob_json_names *m, uint32_t n);
void ob_json_names_release(ob_json_names *m);
/* The value of key, or UINT32_MAX if absent (also before init). */
uint32_t ob_json_names_find(const ob_json_names *m, const char *key);
/* Adds key (not present yet; at most the n given to init). */
void ob_json_names_put(ob_json_names *m, const char *key, uint32_t value);

#pragma GCC visibility pop

#endif /* OB_JSON_READ_H */
