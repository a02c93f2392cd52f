#define _POSIX_C_SOURCE 200809L
#include "ob_shader_source.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Deeper nesting than this is almost certainly an unguarded include loop
 * through different paths; glslang's own limit is similar. */
#define INCLUDE_DEPTH_MAX 64

/* ----------------------------------------------------------- text buffer */

typedef struct text_buf {
    char *data;
    size_t length, cap;
    bool oom;
} text_buf;

static void buf_append(text_buf *b, const char *s, size_t n)
{
    if (b->oom) return;
    if (b->length + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->length + n + 1) cap *= 2;
        char *p = ob_realloc(b->data, cap);
        if (!p) {
            b->oom = true;
            return;
        }
        b->data = p;
        b->cap = cap;
    }
    memcpy(b->data + b->length, s, n);
    b->length += n;
    b->data[b->length] = '\0';
}

static void buf_str(text_buf *b, const char *s) { buf_append(b, s, strlen(s)); }

__attribute__((format(printf, 2, 3)))
static void buf_printf(text_buf *b, const char *fmt, ...)
{
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n < 0) return;
    buf_append(b, tmp, OB_MIN((size_t)n, sizeof tmp - 1));
}

char *ob_shader_path_join(const char *dir, const char *name)
{
    if (name[0] == '/' || !dir || !dir[0]) return ob_strdup(name);
    size_t d = strlen(dir), n = strlen(name);
    while (d > 1 && dir[d - 1] == '/') d--;
    char *p = ob_malloc(d + 1 + n + 1);
    if (!p) return NULL;
    memcpy(p, dir, d);
    p[d] = '/';
    memcpy(p + d + 1, name, n + 1);
    return p;
}

/* The folder of path ("." when it has none); ob_malloc'ed. */
static char *path_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return ob_strdup(".");
    size_t n = slash == path ? 1 : (size_t)(slash - path);
    char *d = ob_malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, path, n);
    d[n] = '\0';
    return d;
}

/* Reads a regular file without logging: a miss is normal while searching
 * include folders. OB_ERR_NOT_FOUND when absent, OB_ERR_IO otherwise. */
static ob_result read_file_quiet(const char *path, char **out_text, size_t *out_len,
                                 struct stat *out_st, int *out_errno)
{
    *out_text = NULL;
    *out_errno = 0;
    if (stat(path, out_st) != 0) {
        *out_errno = errno;
        return (errno == ENOENT || errno == ENOTDIR) ? OB_ERR_NOT_FOUND : OB_ERR_IO;
    }
    if (!S_ISREG(out_st->st_mode)) {
        *out_errno = EISDIR;
        return OB_ERR_IO;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        *out_errno = errno;
        return OB_ERR_IO;
    }
    ob_result r = OB_OK;
    size_t size = (size_t)out_st->st_size;
    char *text = ob_malloc(size + 1);
    if (!text) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
    } else if (fread(text, 1, size, f) != size) {
        *out_errno = ferror(f) ? errno : EIO;
        r = OB_ERR_IO;
        ob_free(text);
        text = NULL;
    } else {
        text[size] = '\0';
        *out_text = text;
        *out_len = size;
    }
    fclose(f);
    return r;
}

/* ---------------------------------------------------------- file table */

static ob_result add_file(ob_shader_source *src, const char *display, const struct stat *st,
                          uint32_t *out_index)
{
    if (st) {
        for (uint32_t i = 0; i < src->file_count; i++) {
            const ob_shader_source_file *f = &src->files[i];
            if (f->has_id && f->dev == (uint64_t)st->st_dev && f->ino == (uint64_t)st->st_ino) {
                *out_index = i;
                return OB_OK;
            }
        }
    }
    ob_result r = ob_array_reserve((void **)&src->files, &src->file_cap, src->file_count + 1,
                                   sizeof *src->files);
    if (r != OB_OK) return r;
    char *name = ob_strdup(display);
    if (!name) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_shader_source_file *f = &src->files[src->file_count];
    memset(f, 0, sizeof *f);
    f->display = name;
    if (st) {
        f->has_id = true;
        f->dev = (uint64_t)st->st_dev;
        f->ino = (uint64_t)st->st_ino;
    }
    *out_index = src->file_count++;
    return OB_OK;
}

__attribute__((format(printf, 4, 5)))
static ob_result add_note(ob_shader_source *src, uint32_t file, uint32_t line, const char *fmt, ...)
{
    ob_result r = ob_array_reserve((void **)&src->notes, &src->note_cap, src->note_count + 1,
                                   sizeof *src->notes);
    if (r != OB_OK) return r;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    char *copy = ob_strdup(msg);
    if (!copy) return OB_ERR_OUT_OF_HOST_MEMORY;
    src->notes[src->note_count++] = (ob_shader_source_note){file, line, copy};
    return OB_OK;
}

/* ------------------------------------------------------------ scanning */

typedef enum include_kind { LINE_PLAIN, LINE_INCLUDE, LINE_BAD_INCLUDE, LINE_PRAGMA_ONCE } include_kind;

static const char *skip_blanks(const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t')) p++;
    return p;
}

static bool word_at(const char *p, const char *end, const char *word)
{
    size_t n = strlen(word);
    return (size_t)(end - p) >= n && memcmp(p, word, n) == 0 &&
           (p + n == end || p[n] == ' ' || p[n] == '\t' || p[n] == '"' || p[n] == '<' || p[n] == '/');
}

/* True when [p, end) holds only blanks and comments; updates the block-comment state. */
static bool rest_is_blank(const char *p, const char *end, bool *in_comment)
{
    bool blank = true;
    while (p < end) {
        if (*in_comment) {
            if (p + 1 < end && p[0] == '*' && p[1] == '/') {
                *in_comment = false;
                p += 2;
            } else {
                p++;
            }
        } else if (p + 1 < end && p[0] == '/' && p[1] == '/') {
            break;
        } else if (p + 1 < end && p[0] == '/' && p[1] == '*') {
            *in_comment = true;
            p += 2;
        } else {
            if (*p != ' ' && *p != '\t' && *p != '\r') blank = false;
            p++;
        }
    }
    return blank;
}

/* Classifies one line (without its newline). A directive only counts when
 * the line does not start inside a block comment. */
static include_kind scan_line(const char *line, const char *end, bool *in_comment,
                              const char **name, size_t *name_len, bool *system)
{
    bool started_in_comment = *in_comment;
    const char *p = skip_blanks(line, end);
    if (!started_in_comment && p < end && *p == '#') {
        p = skip_blanks(p + 1, end);
        if (word_at(p, end, "include")) {
            p = skip_blanks(p + 7, end);
            char close = p < end && *p == '"' ? '"' : p < end && *p == '<' ? '>' : 0;
            if (!close) {
                rest_is_blank(p, end, in_comment);
                return LINE_BAD_INCLUDE;
            }
            const char *start = p + 1, *q = start;
            while (q < end && *q != close) q++;
            if (q == end || q == start) {
                rest_is_blank(p, end, in_comment);
                return LINE_BAD_INCLUDE;
            }
            *name = start;
            *name_len = (size_t)(q - start);
            *system = close == '>';
            return rest_is_blank(q + 1, end, in_comment) ? LINE_INCLUDE : LINE_BAD_INCLUDE;
        }
        if (word_at(p, end, "pragma")) {
            const char *q = skip_blanks(p + 6, end);
            if (word_at(q, end, "once") && rest_is_blank(q + 4, end, in_comment))
                return LINE_PRAGMA_ONCE;
        }
    }
    rest_is_blank(line, end, in_comment);
    return LINE_PLAIN;
}

/* ------------------------------------------------------------ inlining */

typedef struct expand_ctx {
    ob_shader_source *src;
    const char *shader_dir;
    text_buf out;
    uint32_t stack[INCLUDE_DEPTH_MAX];  /* file indices being inlined */
    uint32_t depth;
} expand_ctx;

static ob_result expand_text(expand_ctx *x, uint32_t file, const char *dir, const char *text,
                             size_t length);

static bool on_stack(const expand_ctx *x, uint32_t file)
{
    for (uint32_t i = 0; i < x->depth; i++)
        if (x->stack[i] == file) return true;
    return false;
}

/* Replaces an include directive at (file, line) with an #error the
 * preprocessor reaches only in an active branch, and keeps our message. */
static ob_result include_problem(expand_ctx *x, uint32_t file, uint32_t line, const char *message)
{
    ob_result r = add_note(x->src, file, line, "%s", message);
    buf_str(&x->out, "#error include problem\n");
    return r;
}

static ob_result expand_include(expand_ctx *x, uint32_t file, uint32_t line, const char *dir,
                                const char *name, bool system)
{
    ob_result r = OB_OK;
    char *found_text = NULL, *found_path = NULL;
    size_t found_len = 0;
    struct stat st;
    /* "x": the including file's folder, then shader_dir; <x>: shader_dir only. */
    const char *dirs[2] = {system ? x->shader_dir : dir, system ? NULL : x->shader_dir};
    for (int i = 0; i < 2 && !found_text; i++) {
        if (!dirs[i] || (i == 1 && strcmp(dirs[0], dirs[1]) == 0)) continue;
        char *path = ob_shader_path_join(dirs[i], name);
        if (!path) return OB_ERR_OUT_OF_HOST_MEMORY;
        int err = 0;
        r = read_file_quiet(path, &found_text, &found_len, &st, &err);
        if (r == OB_OK) {
            found_path = path;
        } else {
            ob_free(path);
            if (r == OB_ERR_OUT_OF_HOST_MEMORY) return r;
            if (r == OB_ERR_IO) {
                char msg[1024];
                snprintf(msg, sizeof msg, "cannot read include \"%s\": %s", name, strerror(err));
                return include_problem(x, file, line, msg);
            }
            if (name[0] == '/') break;
        }
    }
    if (!found_text) {
        char msg[1024];
        if (name[0] == '/')
            snprintf(msg, sizeof msg, "cannot find include \"%s\"", name);
        else if (system || strcmp(dir, x->shader_dir) == 0)
            snprintf(msg, sizeof msg, "cannot find include \"%s\" (searched %s)", name, x->shader_dir);
        else
            snprintf(msg, sizeof msg, "cannot find include \"%s\" (searched %s, %s)", name, dir,
                     x->shader_dir);
        return include_problem(x, file, line, msg);
    }

    uint32_t index = 0;
    char *inc_dir = NULL;
    r = add_file(x->src, found_path, &st, &index);
    if (r != OB_OK) goto done;
    const ob_shader_source_file *f = &x->src->files[index];
    if (f->once || on_stack(x, index)) {
        /* Already inlined under #pragma once, or a cycle: what an include
         * guard would produce. Keep the line count. */
        buf_str(&x->out, "\n");
        goto done;
    }
    if (x->depth >= INCLUDE_DEPTH_MAX) {
        char msg[256];
        snprintf(msg, sizeof msg, "includes nested deeper than %d at \"%s\"", INCLUDE_DEPTH_MAX, name);
        r = include_problem(x, file, line, msg);
        goto done;
    }
    inc_dir = path_dir(found_path);
    if (!inc_dir) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    buf_printf(&x->out, "#line 1 %u\n", index);
    r = expand_text(x, index, inc_dir, found_text, found_len);
    if (r != OB_OK) goto done;
    if (found_len > 0 && found_text[found_len - 1] != '\n') buf_str(&x->out, "\n");
    buf_printf(&x->out, "#line %u %u\n", line + 1, file);
done:
    ob_free(inc_dir);
    ob_free(found_path);
    ob_free(found_text);
    return r;
}

static ob_result expand_text(expand_ctx *x, uint32_t file, const char *dir, const char *text,
                             size_t length)
{
    x->stack[x->depth++] = file;
    ob_result r = OB_OK;
    bool in_comment = false;
    const char *p = text, *end = text + length;
    for (uint32_t line = 1; p < end && r == OB_OK && !x->out.oom; line++) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *line_end = eol ? eol : end;
        const char *next = eol ? eol + 1 : end;
        const char *name = NULL;
        size_t name_len = 0;
        bool system = false;
        switch (scan_line(p, line_end, &in_comment, &name, &name_len, &system)) {
        case LINE_PLAIN:
            buf_append(&x->out, p, (size_t)(next - p));
            break;
        case LINE_PRAGMA_ONCE:
            x->src->files[file].once = true;
            buf_str(&x->out, "\n");
            break;
        case LINE_BAD_INCLUDE:
            r = include_problem(x, file, line, "malformed #include: expected \"file\" or <file>");
            break;
        case LINE_INCLUDE: {
            char *inc = ob_malloc(name_len + 1);
            if (!inc) {
                r = OB_ERR_OUT_OF_HOST_MEMORY;
                break;
            }
            memcpy(inc, name, name_len);
            inc[name_len] = '\0';
            r = expand_include(x, file, line, dir, inc, system);
            ob_free(inc);
            break;
        }
        }
        p = next;
    }
    x->depth--;
    if (r == OB_OK && x->out.oom) r = OB_ERR_OUT_OF_HOST_MEMORY;
    return r;
}

ob_result ob_shader_source_load(const char *shader_dir, const char *path, const char *source,
                                ob_shader_source *out)
{
    memset(out, 0, sizeof *out);
    ob_result r = OB_OK;
    char *full = ob_shader_path_join(shader_dir, path);
    char *text = NULL, *dir = NULL;
    size_t length = 0;
    struct stat st;
    bool on_disk = false;
    if (!full) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    if (source) {
        length = strlen(source);
    } else {
        int err = 0;
        r = read_file_quiet(full, &text, &length, &st, &err);
        if (r == OB_ERR_NOT_FOUND || r == OB_ERR_IO) {
            OB_LOG_E("shader", "cannot read shader '%s' (%s): %s", path, full, strerror(err));
            r = OB_ERR_IO;
        }
        if (r != OB_OK) goto done;
        on_disk = true;
    }
    dir = path_dir(full);
    if (!dir) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    uint32_t index;
    r = add_file(out, on_disk ? full : path, on_disk ? &st : NULL, &index);
    if (r != OB_OK) goto done;

    expand_ctx x = {.src = out, .shader_dir = shader_dir};
    r = expand_text(&x, 0, dir, source ? source : text, length);
    if (r == OB_OK && !x.out.data) buf_str(&x.out, "");
    if (r == OB_OK && x.out.oom) r = OB_ERR_OUT_OF_HOST_MEMORY;
    if (r == OB_OK) {
        out->text = x.out.data;
        out->length = x.out.length;
    } else {
        ob_free(x.out.data);
    }
done:
    ob_free(dir);
    ob_free(text);
    ob_free(full);
    if (r != OB_OK) ob_shader_source_release(out);
    return r;
}

void ob_shader_source_release(ob_shader_source *src)
{
    if (!src) return;
    for (uint32_t i = 0; i < src->file_count; i++) ob_free(src->files[i].display);
    for (uint32_t i = 0; i < src->note_count; i++) ob_free(src->notes[i].message);
    ob_free(src->files);
    ob_free(src->notes);
    ob_free(src->text);
    memset(src, 0, sizeof *src);
}

/* ------------------------------------------------------------ messages */

static bool parse_location(const char *p, uint32_t *file, uint32_t *line, const char **rest)
{
    char *e1, *e2;
    unsigned long f = strtoul(p, &e1, 10);
    if (e1 == p || *e1 != ':') return false;
    unsigned long l = strtoul(e1 + 1, &e2, 10);
    if (e2 == e1 + 1 || *e2 != ':') return false;
    *file = (uint32_t)f;
    *line = (uint32_t)l;
    *rest = e2 + 1;
    while (**rest == ' ') (*rest)++;
    return true;
}

uint32_t ob_shader_source_log(const ob_shader_source *src, const char *variant_name,
                              const char *info_log)
{
    uint32_t errors = 0;
    bool note_logged = false;
    const char *p = info_log ? info_log : "";
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t n = eol ? (size_t)(eol - p) : strlen(p);
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)OB_MIN(n, sizeof line - 1), p);
        p += n + (eol ? 1 : 0);
        size_t len = strlen(line);
        while (len > 0 && (line[len - 1] == ' ' || line[len - 1] == '\r')) line[--len] = '\0';

        bool is_error = strncmp(line, "ERROR: ", 7) == 0;
        bool is_warning = strncmp(line, "WARNING: ", 9) == 0;
        if (!is_error && !is_warning) continue;
        const char *body = line + (is_error ? 7 : 9);
        /* glslang's follow-ups of a real error carry no information. */
        if (strstr(body, "compilation terminated") || strstr(body, "compilation errors.")) continue;
        /* Our #error stops the preprocessor inside its #if: the missing
         * #endif it then reports is an artefact of the include problem. */
        if (note_logged && strstr(body, "missing #endif")) continue;

        uint32_t file, at;
        const char *text;
        ob_log_level level = is_error ? OB_LOG_ERROR : OB_LOG_WARN;
        if (parse_location(body, &file, &at, &text) && file < src->file_count) {
            for (uint32_t i = 0; i < src->note_count; i++) {
                if (src->notes[i].file == file && src->notes[i].line == at &&
                    strstr(text, "#error")) {
                    text = src->notes[i].message;
                    note_logged = true;
                    break;
                }
            }
            ob_log_write(level, "shader", __FILE__, __LINE__, "%s:%u: %s",
                         src->files[file].display, at, text);
        } else {
            ob_log_write(level, "shader", __FILE__, __LINE__, "%s: %s", variant_name, body);
        }
        errors += is_error;
    }
    return errors;
}

/* --------------------------------------------------------------- defines */

static bool is_identifier(const char *s)
{
    if (!s || !(*s == '_' || (*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z'))) return false;
    for (; *s; s++)
        if (!(*s == '_' || (*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
              (*s >= '0' && *s <= '9')))
            return false;
    return true;
}

static int compare_defines(const void *a, const void *b)
{
    const ob_shader_define *const *da = a, *const *db = b;
    return strcmp((*da)->name, (*db)->name);
}

ob_result ob_shader_variant_describe(const ob_shader_desc *desc, char **out_name,
                                     char **out_preamble)
{
    *out_name = NULL;
    *out_preamble = NULL;
    uint32_t count = desc->define_count;
    if (count && !desc->defines) {
        OB_LOG_E("shader", "'%s': define_count is %u but defines is NULL", desc->path, count);
        return OB_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t i = 0; i < count; i++) {
        const ob_shader_define *d = &desc->defines[i];
        if (!is_identifier(d->name)) {
            OB_LOG_E("shader", "'%s': define %u has an invalid name '%s'", desc->path, i,
                     d->name ? d->name : "(null)");
            return OB_ERR_INVALID_ARGUMENT;
        }
        size_t vlen = d->value ? strlen(d->value) : 0;
        if (d->value && (strpbrk(d->value, "\r\n") || (vlen && d->value[vlen - 1] == '\\'))) {
            OB_LOG_E("shader", "'%s': the value of define %s must be one line", desc->path, d->name);
            return OB_ERR_INVALID_ARGUMENT;
        }
    }
    const ob_shader_define **sorted = ob_malloc((count ? count : 1) * sizeof *sorted);
    if (!sorted) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < count; i++) sorted[i] = &desc->defines[i];
    qsort(sorted, count, sizeof *sorted, compare_defines);

    ob_result r = OB_OK;
    text_buf name = {0}, pre = {0};
    buf_str(&name, desc->path);
    buf_str(&pre, "");
    for (uint32_t i = 0; i < count; i++) {
        const char *value = sorted[i]->value ? sorted[i]->value : "1";
        if (i > 0 && strcmp(sorted[i]->name, sorted[i - 1]->name) == 0) {
            OB_LOG_E("shader", "'%s': define %s is given twice", desc->path, sorted[i]->name);
            r = OB_ERR_INVALID_ARGUMENT;
            goto fail_free_text;
        }
        buf_str(&name, i == 0 ? " [" : ", ");
        buf_str(&name, sorted[i]->name);
        buf_str(&name, "=");
        buf_str(&name, value);
        buf_str(&pre, "#define ");
        buf_str(&pre, sorted[i]->name);
        buf_str(&pre, " ");
        buf_str(&pre, value);
        buf_str(&pre, "\n");
    }
    if (count) buf_str(&name, "]");
    if (name.oom || pre.oom) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_text;
    }
    ob_free(sorted);
    *out_name = name.data;
    *out_preamble = pre.data;
    return OB_OK;
fail_free_text:
    ob_free(sorted);
    ob_free(name.data);
    ob_free(pre.data);
    return r;
}
