#define _POSIX_C_SOURCE 200809L
#include "ob_json_read.h"

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* ------------------------------------------------------------ errors */

void ob_json_reader_init(ob_json_reader *rd, const char *file, ob_json_error *err)
{
    memset(rd, 0, sizeof *rd);
    rd->file = file ? file : "document";
    rd->err = err ? err : &rd->own_err;
    memset(rd->err, 0, sizeof *rd->err);
}

bool ob_json_fail(ob_json_reader *rd, const char *fmt, ...)
{
    if (rd->result != OB_OK) return false;   /* the first error is the one reported */
    rd->result = OB_ERR_PARSE;
    char what[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    ob_json_error *e = rd->err;
    snprintf(e->json_path, sizeof e->json_path, "%s", rd->path);
    if (rd->len) snprintf(e->message, sizeof e->message, "%s: %s: %s", rd->file, rd->path, what);
    else snprintf(e->message, sizeof e->message, "%s: %s", rd->file, what);
    return false;
}

bool ob_json_out_of_memory(ob_json_reader *rd)
{
    if (rd->result != OB_OK) return false;
    rd->result = OB_ERR_OUT_OF_HOST_MEMORY;
    snprintf(rd->err->message, sizeof rd->err->message, "%s: out of memory while reading it", rd->file);
    return false;
}

/* ------------------------------------------------------------ paths */

static bool is_identifier(const char *s)
{
    if (!isalpha((unsigned char)*s) && *s != '_') return false;
    for (s++; *s; s++)
        if (!isalnum((unsigned char)*s) && *s != '_') return false;
    return true;
}

size_t ob_json_push_key(ob_json_reader *rd, const char *key)
{
    size_t mark = rd->len, room = sizeof rd->path - rd->len;
    if (is_identifier(key) && strlen(key) <= 40) {
        snprintf(rd->path + rd->len, room, "%s%s", rd->len ? "." : "", key);
    } else {
        char shown[48];
        size_t n = 0;
        for (const char *s = key; *s && n < 40; s++)
            shown[n++] = (*s >= 0x20 && *s < 0x7f && *s != '"' && *s != '\\') ? *s : '?';
        shown[n] = '\0';
        snprintf(rd->path + rd->len, room, "[\"%s%s\"]", shown, strlen(key) > 40 ? "..." : "");
    }
    rd->len += strlen(rd->path + rd->len);
    return mark;
}

size_t ob_json_push_index(ob_json_reader *rd, uint32_t index)
{
    size_t mark = rd->len;
    snprintf(rd->path + rd->len, sizeof rd->path - rd->len, "[%u]", index);
    rd->len += strlen(rd->path + rd->len);
    return mark;
}

void ob_json_pop(ob_json_reader *rd, size_t mark)
{
    rd->len = mark;
    rd->path[mark] = '\0';
}

const char *ob_json_type_name(const cJSON *j)
{
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an invalid value";
}

/* ------------------------------------------------------------ parsing */

static void *hook_malloc(size_t size) { return ob_malloc(size); }
static void hook_free(void *p) { ob_free(p); }

/* Process-wide (cJSON keeps one set of hooks), so only on the program's
 * request: see ob_scene_file_hook_cjson. */
static ob_result install_hooks(void)
{
    cJSON_Hooks hooks = {.malloc_fn = hook_malloc, .free_fn = hook_free};
    cJSON_InitHooks(&hooks);
    return OB_OK;
}
static ob_once hooks_once = OB_ONCE_INIT("cJSON hooks", install_hooks);

void ob_json_hook_allocations(void) { ob_once_run(&hooks_once); }

static bool syntax_error(ob_json_reader *rd, const char *text, size_t size, size_t pos, const char *what)
{
    uint32_t line = 1, col = 1;
    for (size_t i = 0; i < pos && i < size; i++) {
        if (text[i] == '\n') line++, col = 1;
        else col++;
    }
    char near[32];
    size_t n = 0;
    for (size_t i = pos; i < size && n < 24 && text[i] != '\n'; i++)
        near[n++] = text[i] >= 0x20 && text[i] < 0x7f ? text[i] : '?';
    near[n] = '\0';
    rd->result = OB_ERR_PARSE;
    rd->err->line = line;
    rd->err->column = col;
    if (what)
        snprintf(rd->err->message, sizeof rd->err->message, "%s:%u:%u: invalid JSON: %s", rd->file,
                 line, col, what);
    else if (pos >= size)
        snprintf(rd->err->message, sizeof rd->err->message,
                 "%s:%u:%u: invalid JSON: unexpected end of file", rd->file, line, col);
    else
        snprintf(rd->err->message, sizeof rd->err->message, "%s:%u:%u: invalid JSON near '%s'",
                 rd->file, line, col, near);
    return false;
}

/* What cJSON would report only as "invalid JSON near ...", or not at all,
 * found first and named: nesting past cJSON's limit (CJSON_NESTING_LIMIT),
 * and a \u0000 escape, which cJSON decodes into a NUL that silently cuts
 * the string short (a path "a.obj\u0000.png" would name "a.obj"). */
static bool scan_structure(ob_json_reader *rd, const char *text, size_t size)
{
    size_t depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < size; i++) {
        char ch = text[i];
        if (in_string) {
            if (ch == '"') {
                in_string = false;
            } else if (ch == '\\' && i + 1 < size) {
                if (text[i + 1] == 'u' && i + 5 < size && strncmp(text + i + 2, "0000", 4) == 0)
                    return syntax_error(rd, text, size, i,
                                        "a \\u0000 (NUL) escape in a string, which would cut it short");
                i++;
            }
        } else if (ch == '"') {
            in_string = true;
        } else if (ch == '[' || ch == '{') {
            if (++depth > CJSON_NESTING_LIMIT) {
                char what[96];
                snprintf(what, sizeof what, "arrays and objects nested deeper than %d levels",
                         CJSON_NESTING_LIMIT);
                return syntax_error(rd, text, size, i, what);
            }
        } else if ((ch == ']' || ch == '}') && depth) {
            depth--;
        }
    }
    return true;
}

/* Text shown to a user (names, descriptions, paths) must be valid UTF-8
 * without control characters: terminal escapes would be printed raw. The
 * byte offset of the first bad character, or -1. */
static long bad_text_at(const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    for (size_t i = 0; p[i];) {
        unsigned c = p[i];
        uint32_t cp;
        size_t n;
        if (c < 0x80) cp = c, n = 1;
        else if ((c & 0xE0) == 0xC0) cp = c & 0x1F, n = 2;
        else if ((c & 0xF0) == 0xE0) cp = c & 0x0F, n = 3;
        else if ((c & 0xF8) == 0xF0) cp = c & 0x07, n = 4;
        else return (long)i;
        for (size_t k = 1; k < n; k++) {
            if ((p[i + k] & 0xC0) != 0x80) return (long)i;
            cp = cp << 6 | (p[i + k] & 0x3F);
        }
        static const uint32_t min_cp[5] = {0, 0, 0x80, 0x800, 0x10000};
        if (cp < min_cp[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return (long)i;
        if (cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)) return (long)i;
        i += n;
    }
    return -1;
}

bool ob_json_check_text(ob_json_reader *rd, const char *s, const char *what)
{
    long at = bad_text_at(s);
    if (at < 0) return true;
    return ob_json_fail(rd, "expected %s of printable UTF-8 text, got a control character or "
                        "invalid UTF-8 at byte %ld", what, at);
}

cJSON *ob_json_parse(ob_json_reader *rd, const char *text, size_t size)
{
    if (!text) {
        ob_json_fail(rd, "no text to parse");
        return NULL;
    }
    const char *nul = memchr(text, '\0', size);
    if (nul) {
        syntax_error(rd, text, size, (size_t)(nul - text), "a NUL byte in the text");
        return NULL;
    }
    if (!scan_structure(rd, text, size)) return NULL;
    size_t blank = 0;
    while (blank < size && isspace((unsigned char)text[blank])) blank++;
    if (blank == size) {
        ob_json_fail(rd, "the file is empty (expected a JSON object)");
        return NULL;
    }
    /* cJSON wants the terminating NUL inside the length to reject trailing
     * text, and a terminated copy keeps any over-read inside the buffer. */
    char *copy = ob_malloc(size + 1);
    if (!copy) {
        ob_json_out_of_memory(rd);
        return NULL;
    }
    memcpy(copy, text, size);
    copy[size] = '\0';
    const char *end = NULL;
    bool fault_before = ob_fault_hit(OB_FAULT_HOST_ALLOC);
    cJSON *root = cJSON_ParseWithLengthOpts(copy, size + 1, &end, true);
    if (!root) {
        /* cJSON reports a failed allocation as a syntax error; fault-injection
         * runs must see it as what it was. */
        if (!fault_before && ob_fault_hit(OB_FAULT_HOST_ALLOC))
            ob_json_out_of_memory(rd);
        else
            syntax_error(rd, copy, size, end && end >= copy ? (size_t)(end - copy) : size, NULL);
    }
    ob_free(copy);
    return root;
}

/* ------------------------------------------------------------ keys */

static bool unknown_key(ob_json_reader *rd, const char *key, const char *const *keys, uint32_t n)
{
    char list[400] = "";
    for (uint32_t i = 0; i < n; i++) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", keys[i]);
    }
    const char *close = ob_closest_name(key, keys, n, 2);
    /* "speed" for "speed_degrees", "fov" for "fov_degrees": a shortened name. */
    size_t kl = strlen(key);
    for (uint32_t i = 0; i < n && !close && kl >= 3; i++) {
        size_t nl = strlen(keys[i]);
        if (strncmp(key, keys[i], OB_MIN(kl, nl)) == 0) close = keys[i];
    }
    if (close) return ob_json_fail(rd, "unknown key (did you mean '%s'? expected one of: %s)", close, list);
    return ob_json_fail(rd, "unknown key (expected one of: %s)", list);
}

bool ob_json_check_object(ob_json_reader *rd, const cJSON *j, const char *what,
                          const char *const *keys, uint32_t n)
{
    if (!cJSON_IsObject(j)) return ob_json_fail(rd, "expected %s, got %s", what, ob_json_type_name(j));
    uint32_t seen = 0;
    for (const cJSON *it = j->child; it; it = it->next) {
        uint32_t k = 0;
        while (k < n && strcmp(it->string, keys[k]) != 0) k++;
        size_t mark = ob_json_push_key(rd, it->string);
        if (k == n) return unknown_key(rd, it->string, keys, n);
        if (seen & (1u << k)) return ob_json_fail(rd, "duplicate key");
        seen |= 1u << k;
        ob_json_pop(rd, mark);
    }
    return true;
}

const cJSON *ob_json_member(const cJSON *obj, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(obj, key);
}

bool ob_json_missing(ob_json_reader *rd, const char *key, const char *what)
{
    ob_json_push_key(rd, key);
    return ob_json_fail(rd, "missing (expected %s)", what);
}

/* ------------------------------------------------------------ values */

/* " > 0", " from 1 to 8192", "" */
static void rule_suffix(const ob_json_rule *r, char *dst, size_t size)
{
    switch (r->kind) {
    case OB_JSON_NUM_ANY: snprintf(dst, size, "%s", ""); break;
    case OB_JSON_NUM_POSITIVE: snprintf(dst, size, " > 0"); break;
    case OB_JSON_NUM_NON_NEGATIVE: snprintf(dst, size, " >= 0"); break;
    case OB_JSON_NUM_RANGE: snprintf(dst, size, " from %g to %g", r->lo, r->hi); break;
    case OB_JSON_NUM_INT: snprintf(dst, size, " from %.0f to %.0f", r->lo, r->hi); break;
    }
}

static void describe_rule(const ob_json_rule *r, char *dst, size_t size)
{
    char suffix[48];
    rule_suffix(r, suffix, sizeof suffix);
    snprintf(dst, size, "%s%s", r->kind == OB_JSON_NUM_INT ? "an integer" : "a number", suffix);
}

bool ob_json_number(ob_json_reader *rd, const cJSON *j, ob_json_rule rule, bool float32, double *out)
{
    char expected[96];
    describe_rule(&rule, expected, sizeof expected);
    if (!cJSON_IsNumber(j)) return ob_json_fail(rd, "expected %s, got %s", expected, ob_json_type_name(j));
    double v = j->valuedouble;
    if (!isfinite(v)) return ob_json_fail(rd, "expected %s, got a number too large to represent", expected);
    bool ok = true;
    switch (rule.kind) {
    case OB_JSON_NUM_ANY: break;
    case OB_JSON_NUM_POSITIVE: ok = v > 0.0; break;
    case OB_JSON_NUM_NON_NEGATIVE: ok = v >= 0.0; break;
    case OB_JSON_NUM_RANGE: ok = v >= rule.lo && v <= rule.hi; break;
    case OB_JSON_NUM_INT: ok = v >= rule.lo && v <= rule.hi && v == floor(v); break;
    }
    if (!ok) return ob_json_fail(rd, "expected %s, got %.17g", expected, v);
    if (float32 && fabs(v) > FLT_MAX)
        return ob_json_fail(rd, "expected %s within single precision, got %g", expected, v);
    if (float32 && rule.kind == OB_JSON_NUM_POSITIVE && v < FLT_MIN)
        return ob_json_fail(rd, "expected %s, got %g (too small for single precision)", expected, v);
    *out = v;
    return true;
}

const char *ob_json_string(ob_json_reader *rd, const cJSON *j, const char *what)
{
    if (!cJSON_IsString(j) || !j->valuestring) {
        ob_json_fail(rd, "expected %s, got %s", what, ob_json_type_name(j));
        return NULL;
    }
    if (!j->valuestring[0]) {
        ob_json_fail(rd, "expected %s, got an empty string", what);
        return NULL;
    }
    if (!ob_json_check_text(rd, j->valuestring, what)) return NULL;
    return j->valuestring;
}

/* "3 numbers", "3 or 4 numbers >= 0", "2 integers from 1 to 8192". */
static void describe_vector(uint32_t min_n, uint32_t max_n, const ob_json_rule *rule, char *dst,
                            size_t size)
{
    char suffix[48];
    rule_suffix(rule, suffix, sizeof suffix);
    const char *noun = rule->kind == OB_JSON_NUM_INT ? "integers" : "numbers";
    if (min_n == max_n) snprintf(dst, size, "%u %s%s", min_n, noun, suffix);
    else snprintf(dst, size, "%u or %u %s%s", min_n, max_n, noun, suffix);
}

bool ob_json_vector(ob_json_reader *rd, const cJSON *j, uint32_t min_n, uint32_t max_n,
                    ob_json_rule rule, bool float32, double *out, uint32_t *out_n)
{
    char expected[96];
    describe_vector(min_n, max_n, &rule, expected, sizeof expected);
    if (!cJSON_IsArray(j)) return ob_json_fail(rd, "expected %s, got %s", expected, ob_json_type_name(j));
    int n = cJSON_GetArraySize(j);
    if (n < (int)min_n || n > (int)max_n)
        return ob_json_fail(rd, "expected %s, got %d", expected, n);
    uint32_t i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        size_t mark = ob_json_push_index(rd, i);
        if (!ob_json_number(rd, e, rule, float32, &out[i])) return false;
        ob_json_pop(rd, mark);
    }
    if (out_n) *out_n = i;
    return true;
}

/* ------------------------------------------------------------ optional members */

bool ob_json_opt_double(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                        double *out)
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    size_t mark = ob_json_push_key(rd, key);
    if (!ob_json_number(rd, j, rule, false, out)) return false;
    ob_json_pop(rd, mark);
    return true;
}

bool ob_json_opt_float(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       float *out)
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    size_t mark = ob_json_push_key(rd, key);
    double v;
    if (!ob_json_number(rd, j, rule, true, &v)) return false;
    *out = (float)v;
    ob_json_pop(rd, mark);
    return true;
}

bool ob_json_opt_u32(ob_json_reader *rd, const cJSON *obj, const char *key, uint32_t lo, uint32_t hi,
                     uint32_t *out)
{
    double v = *out;
    if (!ob_json_opt_double(rd, obj, key, OB_JSON_INT(lo, hi), &v)) return false;
    *out = (uint32_t)v;
    return true;
}

bool ob_json_opt_bool(ob_json_reader *rd, const cJSON *obj, const char *key, bool *out)
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    if (!cJSON_IsBool(j)) {
        ob_json_push_key(rd, key);
        return ob_json_fail(rd, "expected true or false, got %s", ob_json_type_name(j));
    }
    *out = cJSON_IsTrue(j);
    return true;
}

static bool opt_vec(ob_json_reader *rd, const cJSON *obj, const char *key, uint32_t min_n,
                    uint32_t max_n, ob_json_rule rule, bool float32, double *out)
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    size_t mark = ob_json_push_key(rd, key);
    double v[4];
    uint32_t n = 0;
    if (!ob_json_vector(rd, j, min_n, max_n, rule, float32, v, &n)) return false;
    memcpy(out, v, sizeof *v * n);
    ob_json_pop(rd, mark);
    return true;
}

bool ob_json_opt_vec3d(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       double out[3])
{
    return opt_vec(rd, obj, key, 3, 3, rule, false, out);
}

bool ob_json_opt_vec3f(ob_json_reader *rd, const cJSON *obj, const char *key, ob_json_rule rule,
                       float out[3])
{
    double v[3] = {out[0], out[1], out[2]};
    if (!opt_vec(rd, obj, key, 3, 3, rule, true, v)) return false;
    for (int i = 0; i < 3; i++) out[i] = (float)v[i];
    return true;
}

bool ob_json_opt_color(ob_json_reader *rd, const cJSON *obj, const char *key, float w, float out[4])
{
    double v[4] = {out[0], out[1], out[2], w};
    if (!ob_json_member(obj, key)) return true;
    if (!opt_vec(rd, obj, key, 3, 4, OB_JSON_NON_NEGATIVE, true, v)) return false;
    for (int i = 0; i < 4; i++) out[i] = (float)v[i];
    return true;
}

bool ob_json_opt_number_or_vec3(ob_json_reader *rd, const cJSON *obj, const char *key,
                                ob_json_rule rule, float out[3])
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    size_t mark = ob_json_push_key(rd, key);
    double v[3];
    if (cJSON_IsNumber(j)) {
        if (!ob_json_number(rd, j, rule, true, &v[0])) return false;
        v[1] = v[2] = v[0];
    } else if (cJSON_IsArray(j) && cJSON_GetArraySize(j) == 3) {
        if (!ob_json_vector(rd, j, 3, 3, rule, true, v, NULL)) return false;
    } else {
        char each[64];
        rule_suffix(&rule, each, sizeof each);
        if (cJSON_IsArray(j))
            return ob_json_fail(rd, "expected a number or 3 numbers%s, got an array of %d", each,
                                cJSON_GetArraySize(j));
        return ob_json_fail(rd, "expected a number or 3 numbers%s, got %s", each, ob_json_type_name(j));
    }
    for (int i = 0; i < 3; i++) out[i] = (float)v[i];
    ob_json_pop(rd, mark);
    return true;
}

/* ------------------------------------------------------------ vectors and names */

bool ob_json_normalize(double *v, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
    if (!(m > 0.0) || !isfinite(m)) return false;
    double len2 = 0.0;
    for (int i = 0; i < n; i++) len2 += (v[i] / m) * (v[i] / m);
    double len = m * sqrt(len2);
    for (int i = 0; i < n; i++) v[i] /= len;
    return true;
}

bool ob_json_opt_direction(ob_json_reader *rd, const cJSON *obj, const char *key, double out[3])
{
    const cJSON *j = ob_json_member(obj, key);
    if (!j) return true;
    size_t mark = ob_json_push_key(rd, key);
    double v[3];
    if (!ob_json_vector(rd, j, 3, 3, OB_JSON_ANY, true, v, NULL)) return false;
    if (!ob_json_normalize(v, 3)) return ob_json_fail(rd, "expected a non-zero vector");
    memcpy(out, v, sizeof v);
    ob_json_pop(rd, mark);
    return true;
}

bool ob_json_names_init(ob_json_reader *rd, ob_json_names *m, uint32_t n)
{
    uint64_t cap = 8;
    while (cap < 2ull * n + 1) cap *= 2;
    if (cap > UINT32_MAX) return ob_json_out_of_memory(rd);
    m->keys = ob_calloc((size_t)cap, sizeof *m->keys);
    m->values = ob_calloc((size_t)cap, sizeof *m->values);
    m->cap = (uint32_t)cap;
    if (!m->keys || !m->values) return ob_json_out_of_memory(rd);
    return true;
}

void ob_json_names_release(ob_json_names *m)
{
    ob_free(m->keys);
    ob_free(m->values);
    memset(m, 0, sizeof *m);
}

/* The slot of key: where it is, or the empty slot where it would go. */
static uint32_t names_slot(const ob_json_names *m, const char *key)
{
    uint32_t i = (uint32_t)ob_hash_str(OB_HASH_SEED, key) & (m->cap - 1);
    while (m->keys[i] && strcmp(m->keys[i], key) != 0) i = (i + 1) & (m->cap - 1);
    return i;
}

uint32_t ob_json_names_find(const ob_json_names *m, const char *key)
{
    if (!m->cap) return UINT32_MAX;
    uint32_t i = names_slot(m, key);
    return m->keys[i] ? m->values[i] : UINT32_MAX;
}

void ob_json_names_put(ob_json_names *m, const char *key, uint32_t value)
{
    uint32_t i = names_slot(m, key);
    m->keys[i] = key;
    m->values[i] = value;
}
