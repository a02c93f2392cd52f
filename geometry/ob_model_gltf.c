/* ob_model_gltf.c — the glTF extension check made before assimp reads a
 * glTF file (ob_model_internal.h).
 *
 * assimp 5.2 imports a file whatever its extensionsRequired says (it refuses
 * only Draco when built without it), so a model that needs, say,
 * KHR_texture_transform or KHR_mesh_quantization would load and render
 * wrong. The glTF spec says a loader that does not support a required
 * extension must not load the asset: we read the two top-level arrays
 * ourselves. geometry may not depend on the views layer's cJSON, and only
 * two arrays of strings are needed, so this is a small scanner: it follows
 * JSON's nesting and strings (escapes included) without building anything,
 * and gives up — leaving the verdict to assimp's own parser — on anything
 * it cannot follow. Every read is bounded by the buffer.
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_model_internal.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* JSON bigger than this is not scanned (a warning says so); .gltf files
 * carrying base64 buffers reach tens of megabytes. */
#define GLTF_JSON_MAX (256u << 20)
#define GLTF_MAX_DEPTH 1024u
#define GLTF_MAX_NAMES 32u
#define GLTF_NAME_MAX 96u

/* Extensions the engine honours when a file requires them:
 * KHR_lights_punctual (ob_model_open.c reads assimp's aiLight into
 * ob_model_light), KHR_texture_transform (offset, rotation and scale per
 * texture, which assimp 5.2 reads; its texCoord override assimp drops, so
 * such a texture keeps the textureInfo's set — docs/limits.md) and
 * KHR_materials_clearcoat. The rest of the KHR_materials_* family,
 * specular-glossiness and unlit are not carried into ob_model_material, and
 * quantized or Draco-compressed geometry is not decoded. Add a name here
 * only together with the code that honours it. */
static const char *const supported_required[] = {"KHR_lights_punctual", "KHR_texture_transform",
                                                 "KHR_materials_clearcoat", NULL};

#define GLTF_NONE UINT32_MAX

typedef struct gltf_view {
    uint32_t stride, length, offset;   /* byteStride (0: none), byteLength, byteOffset */
} gltf_view;

/* Element sizes: components and bytes per component (0: unknown). */
typedef struct gltf_accessor {
    uint32_t view, components, bytes;
    uint32_t sparse_count;                         /* 0: not sparse */
    uint32_t index_view, index_offset, index_bytes, value_view, value_offset;
} gltf_accessor;

typedef struct scan {
    const char *p, *begin, *end;
    /* Offsets (from begin) of the opening quotes of the keys to hide from
     * assimp: the top-level "skins" and each node's "skin". */
    uint32_t *hide;
    uint32_t hide_count, hide_cap, skin_count;   /* skin_count: hidden keys that are skins */
    /* What the checks before assimp need of bufferViews and accessors. */
    struct gltf_view *views;
    struct gltf_accessor *accessors;
    uint32_t view_count, view_cap, accessor_count, accessor_cap;
    bool out_of_memory;
    /* What the loader does not carry of the materials, said once per
     * material (only when log_materials: ob_model_open). */
    const char *path;
    bool log_materials;
} scan;

static bool hide_key(scan *s, const char *quote)
{
    if (ob_array_reserve((void **)&s->hide, &s->hide_cap, s->hide_count + 1, sizeof *s->hide) != OB_OK) {
        s->out_of_memory = true;
        return false;
    }
    s->hide[s->hide_count++] = (uint32_t)(quote - s->begin);
    return true;
}

typedef struct name_list {
    char names[GLTF_MAX_NAMES][GLTF_NAME_MAX];
    uint32_t count;
    uint32_t dropped;   /* names past GLTF_MAX_NAMES */
} name_list;

static void skip_ws(scan *s)
{
    while (s->p < s->end && (*s->p == ' ' || *s->p == '\t' || *s->p == '\n' || *s->p == '\r'))
        s->p++;
}

/* A string starting at s->p ('"'); its text (escapes decoded, anything not
 * printable ASCII as '?', cut to out_size − 1) into out when out is not
 * NULL. False if the string is malformed or unterminated. */
static bool read_string(scan *s, char *out, size_t out_size)
{
    if (s->p >= s->end || *s->p != '"') return false;
    s->p++;
    size_t n = 0;
    while (s->p < s->end) {
        char ch = *s->p++;
        if (ch == '"') {
            if (out) out[n] = '\0';
            return true;
        }
        if ((unsigned char)ch < 0x20) return false;   /* raw control characters are not JSON */
        if (ch == '\\') {
            if (s->p >= s->end) return false;
            char e = *s->p++;
            switch (e) {
            case '"': case '\\': case '/': ch = e; break;
            case 'b': case 'f': case 'n': case 'r': case 't': ch = '?'; break;
            case 'u': {
                if (s->end - s->p < 4) return false;
                unsigned code = 0;
                for (int k = 0; k < 4; k++) {
                    unsigned char h = (unsigned char)s->p[k];
                    if (!isxdigit(h)) return false;
                    code = code * 16 + (unsigned)(isdigit(h) ? h - '0' : (tolower(h) - 'a' + 10));
                }
                s->p += 4;
                /* Decoded, so "sk\u0069ns" is seen as assimp's JSON reader sees it. */
                ch = code >= 0x20 && code < 0x7f ? (char)code : '?';
                break;
            }
            default: return false;
            }
        } else if ((unsigned char)ch >= 0x7f) {
            ch = '?';
        }
        if (out && n + 1 < out_size) out[n++] = ch;
    }
    return false;
}

/* Skips one value of any kind (object and array nesting tracked up to
 * GLTF_MAX_DEPTH; scalars are skipped up to the next delimiter, since only
 * the structure matters here). */
static bool skip_value(scan *s)
{
    char stack[GLTF_MAX_DEPTH];
    uint32_t depth = 0;
    do {
        skip_ws(s);
        if (s->p >= s->end) return false;
        char ch = *s->p;
        if (ch == '"') {
            if (!read_string(s, NULL, 0)) return false;
        } else if (ch == '{' || ch == '[') {
            if (depth == GLTF_MAX_DEPTH) return false;
            stack[depth++] = ch == '{' ? '}' : ']';
            s->p++;
            continue;
        } else if (ch == '}' || ch == ']') {
            if (depth == 0 || stack[depth - 1] != ch) return false;
            depth--;
            s->p++;
        } else if (ch == ',' || ch == ':') {
            if (depth == 0) return false;
            s->p++;
            continue;
        } else {
            const char *start = s->p;
            while (s->p < s->end && !strchr(",:]} \t\r\n\"{[", *s->p)) s->p++;
            if (s->p == start) return false;
        }
        /* Inside a container, separators and closers follow: keep going. */
        if (depth > 0) {
            skip_ws(s);
            if (s->p < s->end && (*s->p == ',' || *s->p == ':')) s->p++;
        }
    } while (depth > 0);
    return true;
}

static void list_add(name_list *l, const char *name)
{
    for (uint32_t i = 0; i < l->count; i++)
        if (strcmp(l->names[i], name) == 0) return;
    if (l->count == GLTF_MAX_NAMES) {
        l->dropped++;
        return;
    }
    snprintf(l->names[l->count++], GLTF_NAME_MAX, "%s", name);
}

/* An array of strings into l; a non-string element makes the file
 * unreadable for this scan. */
/* After a member or element: the closer (then *done) or a comma, blanks
 * around them skipped. False when neither comes. */
static bool after_item(scan *s, char close, bool *done)
{
    skip_ws(s);
    if (s->p >= s->end) return false;
    *done = *s->p == close;
    if (*done || *s->p == ',') {
        s->p++;
        return true;
    }
    return false;
}

/* The opening of an array (after white space): ARRAY_ITEMS when elements
 * follow, ARRAY_DONE when it was empty (consumed) or, with skip_other, when
 * the value there is no array (skipped), ARRAY_BAD on malformed input. */
typedef enum { ARRAY_BAD, ARRAY_DONE, ARRAY_ITEMS } array_open;

static array_open open_array(scan *s, bool skip_other)
{
    skip_ws(s);
    if (s->p >= s->end || *s->p != '[')
        return skip_other && skip_value(s) ? ARRAY_DONE : ARRAY_BAD;
    s->p++;
    skip_ws(s);
    if (s->p < s->end && *s->p == ']') {
        s->p++;
        return ARRAY_DONE;
    }
    return ARRAY_ITEMS;
}

static bool read_name_array(scan *s, name_list *l)
{
    array_open a = open_array(s, false);
    if (a != ARRAY_ITEMS) return a == ARRAY_DONE;
    for (;;) {
        skip_ws(s);
        char name[GLTF_NAME_MAX];
        if (!read_string(s, name, sizeof name)) return false;
        list_add(l, name);
        bool done;
        if (!after_item(s, ']', &done)) return false;
        if (done) return true;
    }
}

static bool hide_skin(scan *s, const char *quote)
{
    s->skin_count++;
    return hide_key(s, quote);
}

/* A non-negative integer value (anything else: skipped, *ok false). */
static bool read_uint(scan *s, uint32_t *out, bool *ok)
{
    skip_ws(s);
    const char *start = s->p;
    uint64_t v = 0;
    while (s->p < s->end && *s->p >= '0' && *s->p <= '9' && v <= UINT32_MAX)
        v = v * 10 + (uint64_t)(*s->p++ - '0');
    bool plain = s->p > start && v <= UINT32_MAX && s->p < s->end && strchr(",}] \t\r\n", *s->p);
    if (!plain) {
        s->p = start;
        *ok = false;
        return skip_value(s);
    }
    *out = (uint32_t)v;
    *ok = true;
    return true;
}

static uint32_t component_bytes(uint32_t type)
{
    switch (type) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

static uint32_t type_components(const char *type)
{
    static const struct { const char *name; uint32_t n; } types[] = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(type, types[i].name) == 0) return types[i].n;
    return 0;
}

/* One member of a buffer view or accessor object; the rest skipped. */
typedef bool (*member_fn)(scan *s, const char *key, uint32_t index);

static bool view_member(scan *s, const char *key, uint32_t index)
{
    bool ok;
    gltf_view *v = &s->views[index];
    if (strcmp(key, "byteStride") == 0) return read_uint(s, &v->stride, &ok);
    if (strcmp(key, "byteLength") == 0) return read_uint(s, &v->length, &ok);
    if (strcmp(key, "byteOffset") == 0) return read_uint(s, &v->offset, &ok);
    return skip_value(s);
}

/* The members of a JSON object: member(s, key, quote, user) for each, with
 * s->p at its value, which it must consume; quote is where the key's string
 * starts (hide_key hides it). A value that is not an object is skipped, or,
 * when strict, refused. Keys are compared cut to 31 characters (read_string). */
typedef bool (*object_member_fn)(scan *s, const char *key, const char *quote, void *user);

static bool scan_object(scan *s, bool strict, object_member_fn member, void *user)
{
    skip_ws(s);
    if (s->p >= s->end || *s->p != '{') return strict ? false : skip_value(s);
    s->p++;
    skip_ws(s);
    if (s->p < s->end && *s->p == '}') {
        s->p++;
        return true;
    }
    for (;;) {
        skip_ws(s);
        const char *quote = s->p;
        char key[32];
        if (!read_string(s, key, sizeof key)) return false;
        skip_ws(s);
        if (s->p >= s->end || *s->p++ != ':') return false;
        if (!member(s, key, quote, user)) return false;
        bool done;
        if (!after_item(s, '}', &done)) return false;
        if (done) return true;
    }
}

typedef struct named_uints {
    const char *const *keys;
    uint32_t **outs;
    uint32_t n;
} named_uints;

static bool named_uint_member(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    const named_uints *m = user;
    uint32_t k = 0;
    while (k < m->n && strcmp(key, m->keys[k]) != 0) k++;
    bool ok;
    return k < m->n ? read_uint(s, m->outs[k], &ok) : skip_value(s);
}

/* A small object's integer members by name (the rest skipped). */
static bool read_members(scan *s, const char *const *keys, uint32_t **outs, uint32_t n)
{
    named_uints m = {keys, outs, n};
    return scan_object(s, false, named_uint_member, &m);
}

/* {"count": N, "indices": {bufferView, byteOffset, componentType},
 *  "values": {bufferView, byteOffset}} */
static bool sparse_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    gltf_accessor *a = user;
    bool ok = true;
    uint32_t type = 0;
    if (strcmp(key, "count") == 0) return read_uint(s, &a->sparse_count, &ok);
    if (strcmp(key, "indices") == 0) {
        static const char *const keys[] = {"bufferView", "byteOffset", "componentType"};
        uint32_t *outs[] = {&a->index_view, &a->index_offset, &type};
        if (!read_members(s, keys, outs, 3)) return false;
        a->index_bytes = component_bytes(type);
        return true;
    }
    if (strcmp(key, "values") == 0) {
        static const char *const keys[] = {"bufferView", "byteOffset"};
        uint32_t *outs[] = {&a->value_view, &a->value_offset};
        return read_members(s, keys, outs, 2);
    }
    return skip_value(s);
}

static bool sparse_member(scan *s, gltf_accessor *a)
{
    return scan_object(s, false, sparse_field, a);
}

static bool accessor_member(scan *s, const char *key, uint32_t index)
{
    bool ok;
    uint32_t v;
    gltf_accessor *a = &s->accessors[index];
    if (strcmp(key, "bufferView") == 0) {
        if (!read_uint(s, &v, &ok)) return false;
        if (ok) a->view = v;
        return true;
    }
    if (strcmp(key, "componentType") == 0) {
        if (!read_uint(s, &v, &ok)) return false;
        a->bytes = ok ? component_bytes(v) : 0;
        return true;
    }
    if (strcmp(key, "type") == 0) {
        skip_ws(s);
        char type[8];
        if (!read_string(s, type, sizeof type)) return false;
        a->components = type_components(type);
        return true;
    }
    if (strcmp(key, "sparse") == 0) return sparse_member(s, a);
    return skip_value(s);
}

typedef struct indexed_member {
    member_fn fn;
    uint32_t index;
} indexed_member;

static bool indexed_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    const indexed_member *im = user;
    return im->fn(s, key, im->index);
}

/* An array of objects, each member handed to fn with the element's index;
 * grow(index) makes room first. */
static bool scan_objects(scan *s, bool (*grow)(scan *, uint32_t), member_fn fn)
{
    array_open a = open_array(s, true);
    if (a != ARRAY_ITEMS) return a == ARRAY_DONE;
    for (uint32_t index = 0;; index++) {
        skip_ws(s);
        if (s->p >= s->end || *s->p != '{') return false;
        if (!grow(s, index)) return false;
        indexed_member im = {fn, index};
        if (!scan_object(s, true, indexed_field, &im)) return false;
        bool done;
        if (!after_item(s, ']', &done)) return false;
        if (done) return true;
    }
}

static bool grow_views(scan *s, uint32_t index)
{
    if (ob_array_reserve((void **)&s->views, &s->view_cap, index + 1, sizeof *s->views) != OB_OK) {
        s->out_of_memory = true;
        return false;
    }
    s->views[index] = (gltf_view){0};
    s->view_count = index + 1;
    return true;
}

static bool grow_accessors(scan *s, uint32_t index)
{
    if (ob_array_reserve((void **)&s->accessors, &s->accessor_cap, index + 1, sizeof *s->accessors) != OB_OK) {
        s->out_of_memory = true;
        return false;
    }
    s->accessors[index] = (gltf_accessor){.view = GLTF_NONE, .index_view = GLTF_NONE, .value_view = GLTF_NONE};
    s->accessor_count = index + 1;
    return true;
}

/* One primitive object. Points and lines (mode 0-3) are dropped by Obelisk
 * after the import; their "indices" are hidden from assimp, which then
 * numbers the vertices in order: assimp 5.2 crashes (SIGSEGV) on a
 * LINE_LOOP whose index is past the vertex count (found by fuzz_model),
 * while it drops such triangles itself. */
typedef struct primitive_keys {
    const char *indices;        /* where its "indices" key starts, NULL without one */
    uint32_t mode;
} primitive_keys;

static bool primitive_field(scan *s, const char *key, const char *quote, void *user)
{
    primitive_keys *pk = user;
    bool ok;
    if (strcmp(key, "mode") == 0) return read_uint(s, &pk->mode, &ok);
    if (strcmp(key, "indices") == 0) pk->indices = quote;
    return skip_value(s);
}

static bool scan_primitive(scan *s)
{
    primitive_keys pk = {NULL, 4};
    if (!scan_object(s, false, primitive_field, &pk)) return false;
    if (pk.indices && pk.mode <= 3 && !hide_key(s, pk.indices)) return false;
    return true;
}

/* An array of values, each handed to fn (which must consume it). */
static bool scan_array(scan *s, bool (*fn)(scan *))
{
    array_open a = open_array(s, true);
    if (a != ARRAY_ITEMS) return a == ARRAY_DONE;
    for (;;) {
        if (!fn(s)) return false;
        bool done;
        if (!after_item(s, ']', &done)) return false;
        if (done) return true;
    }
}

static bool mesh_member(scan *s, const char *key, uint32_t index)
{
    (void)index;
    return strcmp(key, "primitives") == 0 ? scan_array(s, scan_primitive) : skip_value(s);
}

static bool grow_nothing(scan *s, uint32_t index)
{
    (void)s, (void)index;
    return true;
}

/* One node object: its "skin" member is hidden, the rest skipped. */
static bool node_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)user;
    if (strcmp(key, "skin") == 0 && !hide_skin(s, quote)) return false;
    return skip_value(s);
}

static bool scan_node(scan *s)
{
    return scan_object(s, false, node_field, NULL);
}

/* ------------------------------------------------------ material notes
 * assimp 5.2 reads KHR_texture_transform's offset, rotation and scale but
 * not its texCoord override, so such a texture is sampled with the
 * textureInfo's set: each material with one gets a warning naming it, the
 * texture and the set it asked for. */
#define GLTF_MATERIAL_DEPTH 8u

typedef struct material_note {
    char name[GLTF_NAME_MAX];
    char slot[32];          /* the textureInfo being walked ("baseColorTexture") */
    char override_slot[32]; /* the first with a texCoord override */
    uint32_t override_set;
    bool found;
    uint32_t depth;
} material_note;

static bool walk_value(scan *s, material_note *n);

static bool transform_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    material_note *n = user;
    bool ok = true;
    uint32_t set = 0;
    if (strcmp(key, "texCoord") != 0 || n->found) return skip_value(s);
    if (!read_uint(s, &set, &ok)) return false;
    if (ok) {
        n->found = true;
        n->override_set = set;
        snprintf(n->override_slot, sizeof n->override_slot, "%s", n->slot);
    }
    return true;
}

static bool walk_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    material_note *n = user;
    if (strcmp(key, "KHR_texture_transform") == 0) return scan_object(s, false, transform_field, n);
    size_t len = strlen(key);
    if (len >= 7 && strcmp(key + len - 7, "Texture") == 0) snprintf(n->slot, sizeof n->slot, "%s", key);
    return walk_value(s, n);
}

/* Any value inside a material, objects walked for the notes above (to a
 * bounded depth; deeper values are only skipped). */
static bool walk_value(scan *s, material_note *n)
{
    skip_ws(s);
    if (s->p >= s->end || *s->p != '{' || n->depth >= GLTF_MATERIAL_DEPTH) return skip_value(s);
    n->depth++;
    bool ok = scan_object(s, true, walk_field, n);
    n->depth--;
    return ok;
}

static bool material_field(scan *s, const char *key, const char *quote, void *user)
{
    (void)quote;
    material_note *n = user;
    if (strcmp(key, "name") == 0) {
        skip_ws(s);
        if (s->p < s->end && *s->p == '"') return read_string(s, n->name, sizeof n->name);
        return skip_value(s);
    }
    snprintf(n->slot, sizeof n->slot, "%s", key);
    return walk_value(s, n);
}

static bool scan_materials(scan *s)
{
    if (!s->log_materials) {
        skip_ws(s);
        return skip_value(s);
    }
    array_open a = open_array(s, true);
    if (a != ARRAY_ITEMS) return a == ARRAY_DONE;
    for (uint32_t index = 0;; index++) {
        material_note n = {.depth = 0};
        snprintf(n.name, sizeof n.name, "material %u", index);
        if (!scan_object(s, true, material_field, &n)) return false;
        if (n.found)
            OB_LOG_W(OB_MODEL_LOG, "%s: material %u '%s' %s: KHR_texture_transform's texCoord override "
                     "(TEXCOORD_%u) is not supported (assimp 5.2 drops it); the texture reads the "
                     "textureInfo's set", s->path, index, n.name, n.override_slot, n.override_set);
        bool done;
        if (!after_item(s, ']', &done)) return false;
        if (done) return true;
    }
}

/* The top-level object: extensionsRequired and extensionsUsed into the
 * lists, skins and the nodes' skin references to hide, every other member
 * skipped. */
typedef struct top_lists {
    name_list *required, *used;
} top_lists;

static bool top_field(scan *s, const char *key, const char *quote, void *user)
{
    const top_lists *t = user;
    if (strcmp(key, "extensionsRequired") == 0) return read_name_array(s, t->required);
    if (strcmp(key, "extensionsUsed") == 0) return read_name_array(s, t->used);
    if (strcmp(key, "nodes") == 0) return scan_array(s, scan_node);
    if (strcmp(key, "skins") == 0) return hide_skin(s, quote) && skip_value(s);
    if (strcmp(key, "bufferViews") == 0) return scan_objects(s, grow_views, view_member);
    if (strcmp(key, "accessors") == 0) return scan_objects(s, grow_accessors, accessor_member);
    if (strcmp(key, "meshes") == 0) return scan_objects(s, grow_nothing, mesh_member);
    if (strcmp(key, "materials") == 0) return scan_materials(s);
    return skip_value(s);
}

static bool scan_top(scan *s, name_list *required, name_list *used)
{
    skip_ws(s);
    if (s->end - s->p >= 3 && memcmp(s->p, "\xEF\xBB\xBF", 3) == 0) s->p += 3;   /* UTF-8 BOM */
    top_lists t = {required, used};
    return scan_object(s, true, top_field, &t);
}

static uint32_t read_u32le(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* The JSON text of a glTF file into *out (ob_malloc'd; *out_offset: where
 * it starts in the file) or *out NULL when the file is not glTF (nor
 * JSON), or its JSON is too big to scan. A .glb whose header or chunk
 * lengths run past the file is refused here: assimp would allocate what
 * they claim (4 GB for a 460-byte file) before noticing. */
static ob_result read_json(const char *path, char **out, size_t *out_size, size_t *out_offset)
{
    *out = NULL;
    *out_size = 0;
    *out_offset = 0;
    char why[256];
    ob_result r;
    uint64_t file_size = 0;
    int fd = ob_file_open_regular(path, "model file", OB_MODEL_MAX_FILE_BYTES, &file_size, why,
                                  sizeof why, &r);
    if (fd < 0) {
        OB_LOG_E(OB_MODEL_LOG, "%s: cannot read model file: %s", path, why);
        return r;
    }
    unsigned char head[28];
    ssize_t got = pread(fd, head, sizeof head, 0);
    if (got < 0) got = 0;
    uint64_t offset = 0, length = 0;
    if (got >= 12 && memcmp(head, "glTF", 4) == 0) {
        uint32_t version = read_u32le(head + 4), total = read_u32le(head + 8);
        const char *lie = NULL;
        uint64_t claimed = 0;
        if (total > file_size) {
            lie = "its header's total length";
            claimed = total;
        } else if (got >= 20) {
            length = read_u32le(head + 12);
            offset = 20;
            if (version == 2 && read_u32le(head + 16) != 0x4E4F534Au) {
                lie = "its first chunk (not JSON)";
                claimed = length;
                length = 0;
            } else if (20 + length > file_size) {
                lie = version == 2 ? "its JSON chunk" : "its content";
                claimed = length;
            } else if (version == 2 && 20 + length + 8 <= file_size) {
                unsigned char bin[4];
                uint64_t at = 20 + ((length + 3) & ~3ull);
                if (at + 8 <= file_size && pread(fd, bin, 4, (off_t)at) == 4 &&
                    at + 8 + read_u32le(bin) > file_size) {
                    lie = "its second (binary) chunk";
                    claimed = read_u32le(bin);
                }
            }
        } else {
            lie = "its header (shorter than 20 bytes)";
        }
        if (version != 1 && version != 2) length = 0;   /* assimp's to reject */
        if (lie) {
            close(fd);
            OB_LOG_E(OB_MODEL_LOG, "%s: not a valid binary glTF: %s claims %llu bytes, the file has "
                     "%llu", path, lie, (unsigned long long)claimed, (unsigned long long)file_size);
            return OB_ERR_BAD_MODEL;
        }
    } else {
        size_t i = 0;
        if (got >= 3 && memcmp(head, "\xEF\xBB\xBF", 3) == 0) i = 3;
        while (i < (size_t)got && isspace(head[i])) i++;
        if (i < (size_t)got && head[i] == '{') length = file_size;
    }
    if (length == 0) {
        close(fd);
        return OB_OK;
    }
    if (length > GLTF_JSON_MAX) {
        OB_LOG_W(OB_MODEL_LOG, "%s: glTF JSON of %llu bytes not scanned for required extensions "
                 "and skins (over %u MiB)", path, (unsigned long long)length, GLTF_JSON_MAX >> 20);
        close(fd);
        return OB_OK;
    }
    char *text = ob_malloc((size_t)length);
    if (!text) {
        close(fd);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory reading %llu bytes of glTF JSON", path,
                 (unsigned long long)length);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    size_t n = 0;
    while (n < length) {
        ssize_t k = pread(fd, text + n, (size_t)length - n, (off_t)(offset + n));
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;
        n += (size_t)k;
    }
    close(fd);
    if (n != length) {
        ob_free(text);
        OB_LOG_E(OB_MODEL_LOG, "%s: cannot read model file: it shrank while being read", path);
        return OB_ERR_IO;
    }
    *out = text;
    *out_size = (size_t)length;
    *out_offset = (size_t)offset;
    return OB_OK;
}

/* Checks assimp 5.2 does not make, or makes after reading out of bounds:
 * - a byteStride shorter than one element makes elements overlap, read
 *   silently wrong;
 * - a sparse accessor whose count needs more indices or values than their
 *   buffer views hold makes assimp copy past its buffer (found by
 *   fuzz_model's structure-aware glTF inputs).
 * Refused, naming the accessor, the view and the sizes. */
static ob_result check_accessors(const char *path, const scan *s)
{
    for (uint32_t i = 0; i < s->accessor_count; i++) {
        const gltf_accessor *a = &s->accessors[i];
        const uint32_t element = a->bytes * a->components;
        if (a->view < s->view_count && s->views[a->view].stride && element &&
            s->views[a->view].stride < element) {
            OB_LOG_E(OB_MODEL_LOG, "%s: accessor %u: bufferView %u has byteStride %u, smaller than one "
                     "element (%u components of %u bytes = %u bytes)", path, i, a->view,
                     s->views[a->view].stride, a->components, a->bytes, element);
            return OB_ERR_BAD_MODEL;
        }
        if (!a->sparse_count) continue;
        const struct { const char *what; uint32_t view, offset, size; } parts[2] = {
            {"indices", a->index_view, a->index_offset, a->index_bytes},
            {"values", a->value_view, a->value_offset, element}};
        for (int k = 0; k < 2; k++) {
            if (!parts[k].size) continue;
            uint64_t need = (uint64_t)parts[k].offset + (uint64_t)a->sparse_count * parts[k].size;
            uint64_t have = parts[k].view < s->view_count ? s->views[parts[k].view].length : 0;
            if (need > have) {
                OB_LOG_E(OB_MODEL_LOG, "%s: accessor %u: sparse count %u needs %llu bytes of %s, its "
                         "bufferView %u has %llu", path, i, a->sparse_count, (unsigned long long)need,
                         parts[k].what, parts[k].view, (unsigned long long)have);
                return OB_ERR_BAD_MODEL;
            }
        }
    }
    return OB_OK;
}

/* The file with every hidden key's first character replaced by '_'
 * ("skins" becomes "_kins", "skin" "_kin", a point or line primitive's
 * "indices" "_ndices"): same length, so a .glb's chunk lengths stay right,
 * and names assimp ignores. */
static ob_result hide_keys(const char *path, const scan *s, size_t json_offset, ob_model_io *io)
{
    size_t size = 0;
    ob_result r;
    char *file = ob_file_read_limited(path, "model file", OB_MODEL_MAX_FILE_BYTES, &size, NULL, 0, &r);
    if (!file) return r;
    for (uint32_t i = 0; i < s->hide_count; i++) {
        size_t at = json_offset + s->hide[i] + 1;
        if (at < size) file[at] = '_';
    }
    io->patched = (uint8_t *)file;
    io->patched_size = size;
    if (s->skin_count)
        OB_LOG_I(OB_MODEL_LOG, "%s: skins ignored (%u references): Obelisk does not animate skins, "
                 "the meshes are drawn in their bind pose", path, s->skin_count);
    return OB_OK;
}

static bool is_supported(const char *name)
{
    for (const char *const *s = supported_required; *s; s++)
        if (strcmp(*s, name) == 0) return true;
    return false;
}

/* "a, b, c" (and "(+N more)") into out. */
static void join_names(const name_list *l, const bool *pick, char *out, size_t size)
{
    size_t at = 0;
    out[0] = '\0';
    for (uint32_t i = 0; i < l->count; i++) {
        if (pick && !pick[i]) continue;
        int w = snprintf(out + at, size - at, "%s%s", at ? ", " : "", l->names[i]);
        if (w < 0 || (size_t)w >= size - at) break;
        at += (size_t)w;
    }
    if (l->dropped && at < size)
        snprintf(out + at, size - at, " (+%u more)", l->dropped);
}

ob_result ob_model_gltf_precheck(const char *path, ob_model_io *io, bool refuse_required)
{
    char *text;
    size_t size, json_offset;
    ob_result r = read_json(path, &text, &size, &json_offset);
    if (r != OB_OK || !text) return r;
    name_list *lists = ob_calloc(2, sizeof *lists);
    if (!lists) {
        ob_free(text);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory scanning glTF extensions", path);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    name_list *required = &lists[0], *used = &lists[1];
    io->gltf = true;
    scan s = {.p = text, .begin = text, .end = text + size, .path = path, .log_materials = refuse_required};
    bool scanned = scan_top(&s, required, used);
    ob_free(text);
    if (s.out_of_memory) {
        ob_free(s.views);
        ob_free(s.accessors);
        ob_free(s.hide);
        ob_free(lists);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory scanning glTF skins", path);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    if (!scanned) {
        OB_LOG_D(OB_MODEL_LOG, "%s: JSON not followed by the glTF scan; assimp decides", path);
        ob_free(s.views);
        ob_free(s.accessors);
        ob_free(s.hide);
        ob_free(lists);
        return OB_OK;
    }
    r = check_accessors(path, &s);
    if (r == OB_OK && s.hide_count) r = hide_keys(path, &s, json_offset, io);
    ob_free(s.hide);
    ob_free(s.views);
    ob_free(s.accessors);
    if (r != OB_OK) {
        ob_free(lists);
        return r;
    }

    bool unsupported[GLTF_MAX_NAMES] = {false};
    uint32_t refused = 0;
    for (uint32_t i = 0; i < required->count; i++) {
        unsupported[i] = !is_supported(required->names[i]);
        refused += unsupported[i];
    }
    char text_names[512];
    if (refuse_required && (refused || required->dropped)) {
        join_names(required, unsupported, text_names, sizeof text_names);
        OB_LOG_E(OB_MODEL_LOG, "%s: refused: the model requires the glTF extension%s %s, which "
                 "Obelisk does not support", path, refused + required->dropped > 1 ? "s" : "",
                 text_names);
        ob_free(lists);
        return OB_ERR_UNSUPPORTED;
    }
    if (!refuse_required) {
        ob_free(lists);
        return OB_OK;
    }
    /* Optional ones ignored: everything used that is neither required nor supported. */
    bool optional[GLTF_MAX_NAMES] = {false};
    uint32_t optional_count = 0;
    for (uint32_t i = 0; i < used->count; i++) {
        bool req = false;
        for (uint32_t k = 0; k < required->count && !req; k++)
            req = strcmp(required->names[k], used->names[i]) == 0;
        optional[i] = !req && !is_supported(used->names[i]);
        optional_count += optional[i];
    }
    if (optional_count || used->dropped) {
        join_names(used, optional, text_names, sizeof text_names);
        OB_LOG_I(OB_MODEL_LOG, "%s: optional glTF extension%s ignored: %s", path,
                 optional_count + used->dropped > 1 ? "s" : "", text_names);
    }
    ob_free(lists);
    return OB_OK;
}
