/* ob_shader_source.h — INTERNAL to the shader compiler (not API): assembles
 * the GLSL text glslang compiles and maps glslang's messages back to files.
 *
 * glslang 12's C interface has no include callbacks, so includes are inlined
 * here: each file gets a source-string number, and `#line <n> <number>`
 * directives around every inlined file make glslang report "<number>:<line>"
 * for errors, which ob_shader_source_log rewrites as "<file>:<line>". A
 * missing or malformed include becomes an `#error` line at the include's
 * position, so the preprocessor reports it only when that branch is active;
 * the message logged for it is ours (it names the include and the folders
 * searched).
 *
 * Thread rule: no shared state; [any thread] on separate objects.
 */
#ifndef OB_SHADER_SOURCE_H
#define OB_SHADER_SOURCE_H

#include "ob_shader.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

typedef struct ob_shader_source_note {
    uint32_t file;        /* source-string number */
    uint32_t line;        /* 1-based line in that file */
    char *message;        /* logged instead of glslang's "#error" text */
} ob_shader_source_note;

typedef struct ob_shader_source_file {
    char *display;        /* the path opened (or the name given for in-memory source) */
    bool has_id;          /* dev/ino known (file on disk) */
    uint64_t dev, ino;
    bool once;            /* saw `#pragma once` */
} ob_shader_source_file;

typedef struct ob_shader_source {
    char *text;           /* the main file with includes inlined; NUL-terminated */
    size_t length;
    uint32_t file_count;  /* files[0] is the main file */
    uint32_t file_cap;
    ob_shader_source_file *files;
    uint32_t note_count;
    uint32_t note_cap;
    ob_shader_source_note *notes;
} ob_shader_source;

/* Loads desc->path (relative to shader_dir unless absolute) or takes
 * desc->source, and inlines every include. Failure: OB_ERR_IO (main file
 * unreadable; logged with the path), OB_ERR_OUT_OF_HOST_MEMORY; *out is
 * empty then. Include problems are not failures here (see above). */
ob_result ob_shader_source_load(const char *shader_dir, const char *path, const char *source,
                                ob_shader_source *out);
void ob_shader_source_release(ob_shader_source *src);

/* Logs every ERROR / WARNING line of a glslang info log as
 * "<file>:<line>: <text>" (module "shader"); lines without a location are
 * prefixed with the variant name. Returns the number of errors logged. */
uint32_t ob_shader_source_log(const ob_shader_source *src, const char *variant_name,
                              const char *info_log);

/* Validates and sorts the defines, then builds the variant name
 * ("pbr.frag [A=1, B=2]") and the preamble ("#define A 1\n#define B 2\n").
 * Both are ob_malloc'ed. Failure: OB_ERR_INVALID_ARGUMENT (logged, naming
 * the define), OB_ERR_OUT_OF_HOST_MEMORY. */
ob_result ob_shader_variant_describe(const ob_shader_desc *desc, char **out_name,
                                     char **out_preamble);

/* dir + '/' + name (name alone when absolute or dir is empty); ob_malloc'ed,
 * NULL when out of memory. */
char *ob_shader_path_join(const char *dir, const char *name);

/* The shader folder when neither the desc nor $OB_SHADER_DIR names one:
 * share/obelisk/shaders found relative to the binary holding the engine
 * (materials/ob_shader_dir.c). ob_malloc'ed; NULL when out of memory. A
 * missing folder is logged (warning) and the configured install path returned. */
char *ob_shader_dir_default(void);

#pragma GCC visibility pop

#endif /* OB_SHADER_SOURCE_H */
