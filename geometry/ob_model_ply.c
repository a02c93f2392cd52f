/* ob_model_ply.c — a PLY file is checked against its own header before
 * assimp parses it (see ob_model_internal.h for why). */
#define _POSIX_C_SOURCE 200809L
#include "ob_model_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PLY_LOG "model"
#define PLY_MAX_HEADER (1u << 20)   /* bytes; real headers are a few hundred */
#define PLY_MAX_ELEMENTS 64u
#define PLY_MAX_PROPERTIES 1024u

typedef enum ply_format { PLY_NONE, PLY_ASCII, PLY_BINARY_LE, PLY_BINARY_BE } ply_format;

typedef struct ply_property {
    uint8_t size;        /* bytes of a value (of a list's items for a list) */
    uint8_t count_size;  /* bytes of a list's length, 0 for a scalar */
} ply_property;

typedef struct ply_element {
    char name[32];
    uint64_t count;
    uint32_t first, props;   /* its properties in the property array */
} ply_element;

typedef struct ply_header {
    ply_format format;
    ply_element elements[PLY_MAX_ELEMENTS];
    uint32_t element_count;
    ply_property properties[PLY_MAX_PROPERTIES];
    uint32_t property_count;
    size_t data_offset;      /* first byte after end_header's line break */
} ply_header;

/* Size of a PLY scalar type name, 0 if unknown. */
static uint8_t type_size(const char *t)
{
    static const struct { const char *name; uint8_t size; } types[] = {
        {"char", 1}, {"uchar", 1}, {"int8", 1}, {"uint8", 1},
        {"short", 2}, {"ushort", 2}, {"int16", 2}, {"uint16", 2},
        {"int", 4}, {"uint", 4}, {"int32", 4}, {"uint32", 4},
        {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8},
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(t, types[i].name) == 0) return types[i].size;
    return 0;
}

static bool is_integer_type(const char *t)
{
    return type_size(t) && strcmp(t, "float") && strcmp(t, "float32") && strcmp(t, "double") &&
           strcmp(t, "float64");
}

/* Splits line (NUL-terminated, modified) into at most max tokens. */
static uint32_t tokens(char *line, char **out, uint32_t max)
{
    uint32_t n = 0;
    for (char *save = NULL, *t = strtok_r(line, " \t\r", &save); t && n < max;
         t = strtok_r(NULL, " \t\r", &save))
        out[n++] = t;
    return n;
}

static bool parse_count(const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (!*s || *end || errno || s[0] == '-' || v > UINT32_MAX) return false;
    *out = v;
    return true;
}

/* One header line (without its line break). Returns false after logging. */
static bool header_line(const char *path, uint32_t line_no, char *line, ply_header *h, bool *out_end)
{
    char *t[6];
    uint32_t n = tokens(line, t, 6);
    *out_end = false;
    if (n == 0) return true;   /* blank lines are tolerated */
    const char *what = NULL;
    if (!strcmp(t[0], "comment") || !strcmp(t[0], "obj_info")) return true;
    if (!strcmp(t[0], "end_header") && n == 1) {
        *out_end = true;
        return true;
    }
    if (!strcmp(t[0], "format")) {
        if (h->format != PLY_NONE) what = "a second format line";
        else if (n != 3) what = "a format line that is not 'format <format> <version>'";
        else if (!strcmp(t[1], "ascii")) h->format = PLY_ASCII;
        else if (!strcmp(t[1], "binary_little_endian")) h->format = PLY_BINARY_LE;
        else if (!strcmp(t[1], "binary_big_endian")) h->format = PLY_BINARY_BE;
        else what = "an unknown format";
    } else if (!strcmp(t[0], "element")) {
        uint64_t count;
        if (h->format == PLY_NONE) what = "an element before the format line";
        else if (n != 3 || !parse_count(t[2], &count)) what = "an element line that is not 'element <name> <count>'";
        else if (h->element_count >= PLY_MAX_ELEMENTS) what = "too many elements";
        else {
            ply_element *e = &h->elements[h->element_count++];
            snprintf(e->name, sizeof e->name, "%s", t[1]);
            e->count = count;
            e->first = h->property_count;
            e->props = 0;
        }
    } else if (!strcmp(t[0], "property")) {
        ply_property p = {0};
        if (h->element_count == 0) what = "a property before any element";
        else if (h->property_count >= PLY_MAX_PROPERTIES) what = "too many properties";
        else if (n == 3 && (p.size = type_size(t[1])) != 0) {
            /* scalar */
        } else if (n == 5 && !strcmp(t[1], "list") && is_integer_type(t[2]) &&
                   (p.size = type_size(t[3])) != 0) {
            p.count_size = type_size(t[2]);
        } else {
            what = "a property line with an unknown type or shape";
        }
        if (!what) {
            h->properties[h->property_count++] = p;
            h->elements[h->element_count - 1].props++;
        }
    }
    /* Any other line is ignored, as assimp does (exporters write free text
     * without 'comment', e.g. Blender's "Created by Blender3D ..."). */
    if (what) OB_LOG_E(PLY_LOG, "%s: PLY header line %u: %s", path, line_no, what);
    return what == NULL;
}

static ob_result parse_header(const char *path, const char *data, size_t size, ply_header *h)
{
    size_t limit = size < PLY_MAX_HEADER ? size : PLY_MAX_HEADER;
    size_t pos = 0;
    uint32_t line_no = 0;
    char line[512];
    while (pos < limit) {
        const char *nl = memchr(data + pos, '\n', limit - pos);
        if (!nl) break;
        size_t len = (size_t)(nl - (data + pos));
        line_no++;
        bool text = len < sizeof line;
        for (size_t i = 0; text && i < len; i++) {
            unsigned char ch = (unsigned char)data[pos + i];
            text = ch >= 0x20 || ch == '\t' || ch == '\r';
        }
        if (!text) {
            OB_LOG_E(PLY_LOG, "%s: PLY header line %u is not a line of text (binary data in the "
                     "header: a damaged or truncated file?)", path, line_no);
            return OB_ERR_BAD_MODEL;
        }
        memcpy(line, data + pos, len);
        line[len] = '\0';
        pos += len + 1;
        if (line_no == 1) {
            if (strcmp(line, "ply") && strcmp(line, "ply\r")) {
                OB_LOG_E(PLY_LOG, "%s: PLY file does not start with a 'ply' line", path);
                return OB_ERR_BAD_MODEL;
            }
            continue;
        }
        bool end;
        if (!header_line(path, line_no, line, h, &end)) return OB_ERR_BAD_MODEL;
        if (end) {
            if (h->format == PLY_NONE) {
                OB_LOG_E(PLY_LOG, "%s: PLY header has no format line", path);
                return OB_ERR_BAD_MODEL;
            }
            h->data_offset = pos;
            return OB_OK;
        }
    }
    OB_LOG_E(PLY_LOG, "%s: PLY header does not end with an end_header line (truncated file?)", path);
    return OB_ERR_BAD_MODEL;
}

static uint64_t read_count(const unsigned char *p, uint8_t size, bool big_endian)
{
    uint64_t v = 0;
    for (uint8_t i = 0; i < size; i++) v |= (uint64_t)p[big_endian ? size - 1 - i : i] << (8 * i);
    return v;
}

/* Walks every record; a signed list length is read as unsigned, so a
 * negative one is a huge one and fails the size check. */
static ob_result check_binary(const char *path, const unsigned char *data, size_t size,
                              const ply_header *h)
{
    bool big = h->format == PLY_BINARY_BE;
    uint64_t pos = h->data_offset;
    for (uint32_t ei = 0; ei < h->element_count; ei++) {
        const ply_element *e = &h->elements[ei];
        if (e->props == 0) continue;   /* empty records take no bytes */
        for (uint64_t r = 0; r < e->count; r++) {
            for (uint32_t k = 0; k < e->props; k++) {
                const ply_property *p = &h->properties[e->first + k];
                if (!p->count_size) {
                    pos += p->size;
                } else {
                    if (pos + p->count_size > size) goto short_data;
                    uint64_t n = read_count(data + pos, p->count_size, big);
                    pos += p->count_size + n * p->size;
                }
                if (pos > size) goto short_data;
            }
        }
        continue;
    short_data:
        OB_LOG_E(PLY_LOG, "%s: PLY data ends inside element '%s' (%llu declared): the file has "
                 "%zu bytes", path, e->name, (unsigned long long)e->count, size);
        return OB_ERR_BAD_MODEL;
    }
    return OB_OK;
}

static ob_result check_ascii(const char *path, size_t size, const ply_header *h)
{
    /* Every value is at least one character and one separator. */
    uint64_t values = 0;
    for (uint32_t ei = 0; ei < h->element_count; ei++)
        values += h->elements[ei].count * h->elements[ei].props;
    uint64_t avail = size - h->data_offset;
    if (values > (avail + 1) / 2) {
        OB_LOG_E(PLY_LOG, "%s: PLY header declares %llu values but only %llu bytes of text follow",
                 path, (unsigned long long)values, (unsigned long long)avail);
        return OB_ERR_BAD_MODEL;
    }
    return OB_OK;
}

/* True if path ends in ".ply", in any case. */
static bool has_ply_extension(const char *path)
{
    size_t n = strlen(path);
    if (n < 4 || path[n - 4] != '.') return false;
    for (int i = 0; i < 3; i++)
        if ((path[n - 3 + i] | 0x20) != "ply"[i]) return false;
    return true;
}

ob_result ob_model_ply_precheck(const char *path)
{
    char head[3] = {0};
    FILE *f = fopen(path, "rb");
    if (!f) {
        OB_LOG_E(PLY_LOG, "%s: cannot open model file: %s", path, strerror(errno));
        return OB_ERR_IO;
    }
    size_t got = fread(head, 1, 3, f);
    fclose(f);
    /* assimp hands a file to its PLY reader for its extension, or for "ply"
     * at the start of its content (whatever follows: "plyU" too, and then
     * it never returns). Either way the first line must be exactly "ply". */
    if (got == 0) return OB_OK;   /* assimp says it is empty */
    if (!has_ply_extension(path) && (got < 3 || memcmp(head, "ply", 3))) return OB_OK;

    size_t size = 0;
    ob_result r;
    char *data = ob_file_read(path, &size, &r);
    if (!data) return r;
    ply_header *h = ob_calloc(1, sizeof *h);
    if (!h) {
        OB_LOG_E(PLY_LOG, "%s: no memory to check the PLY header", path);
        ob_free(data);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    r = parse_header(path, data, size, h);
    if (r == OB_OK)
        r = h->format == PLY_ASCII ? check_ascii(path, size, h)
                                   : check_binary(path, (const unsigned char *)data, size, h);
    ob_free(h);
    ob_free(data);
    return r;
}
