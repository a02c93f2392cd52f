/* ob_model_internal.h — geometry-private pieces of model loading. Not API:
 * only geometry/ob_model*.c include it. */
#ifndef OB_MODEL_INTERNAL_H
#define OB_MODEL_INTERNAL_H

#include "ob_mesh.h"

#include <stdarg.h>

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

struct aiScene;
struct aiVector3D;

#define OB_MODEL_LOG "model"
#define OB_MODEL_MAX_NODE_DEPTH 256u
/* Problems logged per file before only a count is kept. */
#define OB_MODEL_LOG_MAX 4u

/* Bytes of any one file a model reads (the model, a glTF buffer, an
 * .mtl): checked from the file's size before it is opened for assimp. */
#define OB_MODEL_MAX_FILE_BYTES (1ull << 30)

/* ------------------------------------------------------------ file access
 * (ob_model_io.c) Every file assimp opens for one import: regular files
 * only, opened without blocking; anything but the model itself must
 * resolve, after symbolic links, inside the model's folder (root) unless
 * any_folder; none over OB_MODEL_MAX_FILE_BYTES. patched, when set, is
 * served instead of the model file's bytes. refused is the first refusal's
 * result (OB_OK: none); each is logged naming the model and the file. */
typedef struct ob_model_io {
    const char *model_path;      /* as given */
    char *model_real;            /* realpath of the model */
    char *root;                  /* realpath of the model's folder */
    bool any_folder;
    uint8_t *patched;            /* ob_malloc'd, owned */
    size_t patched_size;
    bool gltf;                   /* the glTF scan saw glTF JSON (for assimp's messages) */
    ob_result refused;
} ob_model_io;

ob_result ob_model_io_init(ob_model_io *io, const char *model_path, bool any_folder);
void ob_model_io_release(ob_model_io *io);
struct aiFileIO ob_model_io_assimp(ob_model_io *io);
/* True when path resolves inside io->root (or any folder is allowed);
 * otherwise why says where it resolves. */
bool ob_model_io_inside(const ob_model_io *io, const char *path, char *why, size_t why_size);

/* Problem bookkeeping of one load: the first OB_MODEL_LOG_MAX problems are
 * logged prefixed with the path, the rest only counted. io is the load's
 * file access (NULL before the import starts). */
typedef struct ob_model_check {
    const char *path;
    uint32_t problems;
    ob_model_io *io;
} ob_model_check;

void ob_model_bad(ob_model_check *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void ob_model_vbad(ob_model_check *c, const char *fmt, va_list ap);
/* "N more problems not shown" when more than were logged. */
void ob_model_report_more(const ob_model_check *c);

/* A model whose triangles all have zero area draws nothing: callers reject
 * it rather than hand out a mesh that passes every other check. */
bool ob_model_mesh_has_area(const ob_mesh *m);
bool ob_model_v3_finite(const struct aiVector3D *v);
/* Replaces, in place, each byte of a control character (C0, DEL, C1) or of
 * invalid UTF-8 in the first length bytes of s with '?': names from a file
 * are printed, and a terminal would interpret escapes. */
void ob_model_sanitize_text(char *s, size_t length);

/* OB_ERR_IO (logged) unless path names a readable regular file. */
ob_result ob_model_check_readable(const char *path);

/* aiImportFileEx(path, 0, io's file system) under the lock that guards
 * assimp's process-wide error string; on NULL, err holds assimp's message. */
const struct aiScene *ob_model_parse(const char *path, ob_model_io *io, char *err, size_t err_size);

/* The raw scene before any post-processing: meshes present, face indices in
 * range, finite positions / normals / uv, at least one polygon, nodes
 * referring to existing meshes, depth bounded. Sets each mesh's
 * mPrimitiveTypes to what its faces are (see ob_model.c). */
ob_result ob_model_check_raw_scene(ob_model_check *c, const struct aiScene *s);

/* The front both loaders share, in the order ob_model.c explains: the file
 * is readable, the PLY precheck, the glTF extension scan (when asked: only
 * ob_model_open refuses required extensions), assimp's parse with no
 * post-processing, the raw checks, then triangulation, sorting by primitive
 * type, missing normals (smooth), vertex joining and, with flip_uv, v → 1 − v.
 * *out_scene is released with aiReleaseImport; NULL on failure, which is
 * logged (the file and the problem): OB_ERR_IO, OB_ERR_PARSE,
 * OB_ERR_BAD_MODEL, OB_ERR_UNSUPPORTED, OB_ERR_OUT_OF_HOST_MEMORY. */
/* c->io must point at the caller's ob_model_io, which the import
 * initializes (desc->allow_any_folder) and the caller releases after it is
 * done with the scene, whatever the result. Refused files (ob_model_io)
 * fail the import with that refusal. refuse_required: the glTF scan refuses
 * unsupported required extensions (only ob_model_open does). */
ob_result ob_model_import(ob_model_check *c, const ob_model_desc *desc, bool refuse_required,
                          const struct aiScene **out_scene);

/* glTF files (.gltf JSON, .glb by its magic) are scanned before assimp
 * reads them:
 * - extensionsRequired / extensionsUsed: OB_ERR_UNSUPPORTED naming the file
 *   and an unsupported required extension; optional ones get an info line;
 * - a .glb's header and chunk lengths against the file's size
 *   (OB_ERR_BAD_MODEL naming the chunk: assimp would allocate what a
 *   lying header claims);
 * - a bufferView's byteStride shorter than the element of an accessor
 *   reading through it (OB_ERR_BAD_MODEL naming both: assimp reads
 *   overlapping elements silently), and a sparse accessor whose count
 *   needs more indices or values than their views hold (assimp copies past
 *   its buffer);
 * - skins: Obelisk does not animate them, and assimp 5.2 crashes or reads
 *   out of bounds on skins the spec allows (no inverseBindMatrices) or that
 *   lie (joint indices, weights, too few matrices). The top-level "skins"
 *   and every node's "skin" are renamed in a copy of the file (io->patched,
 *   served to assimp instead of the file), so assimp never sees a skin;
 *   one info line says so;
 * - materials (ob_model_open only): a KHR_texture_transform texCoord
 *   override, which assimp drops, is warned about once per material,
 *   naming it, the texture and the set;
 * - point and line primitives (mode 0-3), which Obelisk drops after the
 *   import: their "indices" are hidden the same way (assimp 5.2 crashes on
 *   a LINE_LOOP index past the vertex count).
 * With refuse_required false, required extensions are only reported.
 * OK for other files. OB_ERR_IO if the file cannot be read. JSON the scan
 * cannot follow is left to assimp to reject. [any thread] */
ob_result ob_model_gltf_precheck(const char *path, ob_model_io *io, bool refuse_required);

/* model->materials (at least one: a file without materials gets one
 * default) and model->images from the scene (ob_model_material.c);
 * flip_uv says the meshes' uv convention, for KHR_texture_transform. On
 * failure (logged) what was read so far stays in model, counted, for
 * ob_model_close to free. [any thread] */
struct ob_model;
ob_result ob_model_read_materials(ob_model_check *c, const struct aiScene *s, bool flip_uv,
                                  struct ob_model *model);

/* Checks a file that assimp would read as a PLY (a .ply extension, or
 * content starting with "ply") before assimp reads it: the first line must
 * be "ply", the header must be well formed and end with end_header,
 * and the data must hold every element the header declares (binary: every
 * record walked, list lengths included; ASCII: at least two bytes per
 * value). assimp 5.2's PLY reader loops forever on a truncated header and
 * reads past its buffer when the header or the data lie; see
 * fuzz/corpus/model-assimp-known. Other files: OB_OK without reading them.
 * Failure: OB_ERR_BAD_MODEL naming the path and the line or element,
 * OB_ERR_IO or OB_ERR_OUT_OF_HOST_MEMORY; logged. [any thread] */
ob_result ob_model_ply_precheck(const char *path);

#pragma GCC visibility pop

#endif /* OB_MODEL_INTERNAL_H */
