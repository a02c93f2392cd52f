/* ob_scene_file.h — scene description files (JSON, docs/scene-format.md):
 * parsing and validation into a plain description, with no device involved.
 *
 * The parser reads the whole document, checks every key, type, array length,
 * range and reference, fills in the documented defaults and resolves model
 * paths against the scene file's directory. Anything wrong stops it with one
 * error naming the file and the JSON path of the offending value, e.g.
 *   scene.json: entities[3].transform.scale: expected a number or 3 numbers
 * and, for a JSON syntax error, the line and column:
 *   scene.json:12:7: invalid JSON near '}, "camera"...'
 * Unknown keys are errors (with a suggestion when one is close), so a typo is
 * never silently ignored. Nothing here touches the GPU: ob_scene_load.h
 * turns a description into a scene (materials, geometry, nodes, lights,
 * camera, particles), reporting a model that fails to load and going on
 * with the rest.
 *
 * Lifecycle: ob_scene_file_parse / ob_scene_file_load fill a caller-provided
 * ob_scene_file → read it → ob_scene_file_release. A zeroed ob_scene_file is
 * empty and may be released.
 * Thread rule: [any thread]; a description is plain data, written by one
 * thread at a time. Parses may run concurrently (cJSON's global error pointer
 * is never used). cJSON's allocation hooks are left as the program has them
 * unless it calls ob_scene_file_hook_cjson.
 */
#ifndef OB_SCENE_FILE_H
#define OB_SCENE_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ob_core.h"
#include "ob_material.h"
#include "ob_scene.h"
#include "ob_views.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OB_SCENE_FILE_NONE UINT32_MAX   /* "no index": no parent, default material */
#define OB_SCENE_FILE_MAX_PARTICLES (1u << 20)
/* Input bounds (docs/limits.md), checked before memory is committed: a
 * scene file's bytes (from the file's size, before reading it) and its
 * entities (from the array's length, before any is parsed). */
#define OB_SCENE_FILE_MAX_BYTES (64u << 20)
#define OB_SCENE_FILE_MAX_ENTITIES (1u << 18)

/* One range per setting, the same in a scene file's "settings" and on a
 * program's command line (obelisk-view, obelisk-mirror): a value outside
 * it is refused, naming it (docs/limits.md). */
#define OB_SETTING_SIZE_MAX 8192u
#define OB_SETTING_ENV_MAP_MIN 8u
#define OB_SETTING_ENV_MAP_MAX 4096u
#define OB_SETTING_SHADOW_MAP_MIN 16u
#define OB_SETTING_SHADOW_MAP_MAX 8192u
/* A linear scale before the tone map: past 1e6 (20 stops) a lit colour
 * overflows half-float targets and single-precision tone mapping, and the
 * image turns black or white without saying why. */
#define OB_SETTING_EXPOSURE_MIN 1e-6
#define OB_SETTING_EXPOSURE_MAX 1e6

/* The error of a failed parse or load (ob_scene_load.h uses it too). */
typedef struct ob_scene_file_error {
    char message[1024];      /* "FILE: PATH: what was expected" (or "FILE:LINE:COL: ..." for syntax) */
    char json_path[320];     /* "entities[3].transform.scale"; "" for syntax errors and the top level */
    uint32_t line, column;   /* 1-based position of a syntax error; 0 otherwise */
} ob_scene_file_error;

/* "settings": each value overrides the program's default (a program may let
 * its own command line override the file, as obelisk-view does).
 * ob_scene_load_settings puts them where they belong. */
typedef struct ob_scene_file_settings {
    bool has_size;
    uint32_t width, height;       /* 1..OB_SETTING_SIZE_MAX */
    uint32_t env_map_size;        /* 0 = not given; else OB_SETTING_ENV_MAP_MIN..MAX */
    uint32_t shadow_map_size;     /* 0 = not given; else OB_SETTING_SHADOW_MAP_MIN..MAX */
    uint32_t shadow_cascades;     /* 0 = not given; else 1..OB_SHADOW_MAX_CASCADES */
    float shadow_distance;        /* 0 = not given; else > 0 */
    float shadow_split_lambda;    /* 0 = not given; else (0, 1] */
    bool has_threads;
    int threads;                  /* 0 = single-threaded, N workers, -1 = "auto" */
    bool has_clear_color;
    float clear_color[4];         /* rgba (alpha 1 when 3 numbers were given) */
    bool has_ambient;
    float ambient[4];             /* rgb, w = intensity > 0 (0 0 0 1 for "none") */
    float exposure;               /* the composite's exposure; 0 = not given, else > 0 */
    bool has_env_map_kind;
    ob_env_map_kind env_map_kind; /* "env_map": "paraboloid" or "cube" */
    bool has_sky_color;
    float sky_color[4];           /* what env maps clear to (linear; alpha 1) */
} ob_scene_file_settings;

/* "camera": without one the program frames the whole scene (ob_scene_load
 * does when asked to). */
typedef struct ob_scene_file_camera {
    bool present;
    double position[3], target[3], up[3];
    float fov_degrees;            /* vertical, 1..170 */
    float znear;                  /* > 0 */
} ob_scene_file_camera;

typedef struct ob_scene_file_light {
    ob_light_desc desc;           /* type, color, intensity (>= 0), range, casts_shadows */
    char *name;                   /* "lights[i]" when not given */
    double position[3];
    /* Where the light points (directional: its direction; point: unused).
     * From "direction", or target - position. Never zero. */
    double direction[3];
} ob_scene_file_light;

typedef struct ob_scene_file_material {
    char *name;                   /* the key in "materials", or "entities[i].material" */
    bool inline_material;         /* written inside an entity */
    /* Every field explicit (no zero-means-default left): reflectivity is
     * meaningful only for OB_MATERIAL_REFLECTIVE and may be 0. desc.name
     * points at name. */
    ob_material_desc desc;
} ob_scene_file_material;

typedef enum ob_scene_file_geometry_kind {
    OB_SCENE_GEOMETRY_NONE = 0,   /* a transform-only entity (a pivot, a parent) */
    OB_SCENE_GEOMETRY_BOX,
    OB_SCENE_GEOMETRY_SPHERE,
    OB_SCENE_GEOMETRY_PLANE,
    OB_SCENE_GEOMETRY_CONE,
    OB_SCENE_GEOMETRY_TORUS,
    OB_SCENE_GEOMETRY_MODEL,
} ob_scene_file_geometry_kind;

/* A generator's parameters (defaults filled in) or a resolved model path.
 * Two entities whose geometry descriptions compare equal
 * (ob_scene_file_geometry_equal) can share one uploaded geometry. */
/* Coarser levels of detail a generator may ask for ("lods"): all a geometry
 * holds besides level 0 (OB_GEOMETRY_MAX_LODS - 1, checked by the loader). */
#define OB_SCENE_FILE_MAX_LODS 7u

typedef struct ob_scene_file_geometry {
    ob_scene_file_geometry_kind kind;
    float size[3];                /* box: full extents */
    float radius;                 /* sphere, cone */
    float height;                 /* cone */
    float width, depth;           /* plane */
    float major_radius, minor_radius;  /* torus */
    uint32_t segments[2];         /* sphere: slices, stacks; cone: slices, 0;
                                     plane: subdivisions, 0; torus: major, minor */
    uint32_t lods;                /* sphere, cone, torus, model: coarser levels of detail */
    char *model;                  /* MODEL: the path as the loader gets it */
    bool model_relative;          /* MODEL: the file gave a relative path (joined to its folder) */
} ob_scene_file_geometry;

typedef enum ob_scene_file_rotation_kind {
    OB_SCENE_ROTATION_NONE = 0,
    OB_SCENE_ROTATION_EULER,      /* value = pitch, yaw, roll in degrees */
    OB_SCENE_ROTATION_QUATERNION, /* value = x, y, z, w (non-zero; not normalized) */
} ob_scene_file_rotation_kind;

typedef enum ob_scene_file_controller_kind {
    OB_SCENE_CONTROLLER_ROTATE = 0,
    OB_SCENE_CONTROLLER_ORBIT,
} ob_scene_file_controller_kind;

typedef struct ob_scene_file_controller {
    ob_scene_file_controller_kind kind;
    float axis[3];                /* non-zero */
    float speed_degrees;          /* degrees per second, may be negative */
    double center[3];             /* orbit: in the parent's space */
    double radius;                /* orbit: >= 0 */
    float phase_degrees;          /* orbit */
} ob_scene_file_controller;

typedef struct ob_scene_file_entity {
    char *name;                   /* "entities[i]" when not given; names are unique */
    uint32_t index;               /* position in "entities" */
    ob_scene_file_geometry geometry;
    double position[3];
    ob_scene_file_rotation_kind rotation_kind;
    double rotation[4];
    float scale[3];
    uint32_t material;            /* index into materials, or OB_SCENE_FILE_NONE (default) */
    uint32_t parent;              /* index of an earlier entity, or OB_SCENE_FILE_NONE */
    bool hidden;
    ob_scene_file_controller *controllers;
    uint32_t controller_count;
} ob_scene_file_entity;

typedef struct ob_scene_file_particles {
    /* desc.name points at name; desc.seed is 0 (the program picks one). */
    ob_particle_desc desc;
    char *name;                   /* "particles[i]" when not given */
    uint32_t parent;              /* entity index or OB_SCENE_FILE_NONE (the root) */
} ob_scene_file_particles;

typedef struct ob_scene_file {
    char *path;                   /* the file as named to the parser */
    char *description;            /* "description", or NULL */
    bool has_lights;              /* "lights" was given (an empty list means none) */
    ob_scene_file_settings settings;
    ob_scene_file_camera camera;
    ob_scene_file_light *lights;
    uint32_t light_count;
    ob_scene_file_material *materials;
    uint32_t material_count;
    ob_scene_file_entity *entities;
    uint32_t entity_count;
    ob_scene_file_particles *particles;
    uint32_t particle_count;
} ob_scene_file;

/* Parses `size` bytes of JSON text (need not be NUL-terminated; a NUL byte
 * inside is an error). `path` names the file in messages and is the base for
 * relative model paths (NULL → "scene", relative to the working directory).
 * On success *out holds the description (release it) and *out_error is
 * cleared. On failure *out is left empty and *out_error (may be NULL) says
 * what and where: OB_ERR_PARSE (JSON syntax, wrong type, length, unknown key,
 * bad reference, out-of-range or non-finite value), OB_ERR_OUT_OF_HOST_MEMORY.
 * Nothing is logged: the caller shows out_error->message. */
ob_result ob_scene_file_parse(const char *text, size_t size, const char *path,
                              ob_scene_file *out, ob_scene_file_error *out_error);

/* Reads the file at `path` and parses it. Only a regular file of at most
 * OB_SCENE_FILE_MAX_BYTES is read, checked before reading (a FIFO never
 * blocks, /dev/zero is never read). Also OB_ERR_IO (message names the file
 * and the OS error, or what the path is: "not a regular file (a FIFO)") and
 * OB_ERR_LIMIT (the file's size against the bound). */
ob_result ob_scene_file_load(const char *path, ob_scene_file *out, ob_scene_file_error *out_error);

/* Frees everything the description owns and zeroes it. NULL is a no-op. */
void ob_scene_file_release(ob_scene_file *sf);

/* Routes cJSON's allocations through ob_malloc/ob_free, so that
 * fault injection (ob_fault_*) reaches the parser's and ob_heap_stats_now
 * counts them. cJSON's hooks are process-wide: this changes cJSON for
 * every user of it in the process, which is why the library never does it
 * by itself (a program with its own cJSON hooks keeps them). Call it once,
 * before anything in the process uses cJSON (blocks cJSON allocated before
 * would be freed through ob_free); later calls do nothing. Obelisk's tests
 * and demos call it. Cannot fail. [any thread] */
void ob_scene_file_hook_cjson(void);

/* Same generator and parameters, or the same model path. */
bool ob_scene_file_geometry_equal(const ob_scene_file_geometry *a, const ob_scene_file_geometry *b);

/* Stable lower-case names: "none", "box", ..., "model". */
const char *ob_scene_file_geometry_kind_name(ob_scene_file_geometry_kind kind);

#ifdef __cplusplus
}
#endif
#endif /* OB_SCENE_FILE_H */
