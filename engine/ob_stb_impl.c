/* ob_stb_impl.c — the one translation unit that compiles stb_image,
 * stb_image_write and stb_image_resize (textures above the device limit). Everyone else includes the headers without the
 * IMPLEMENTATION defines and links against these definitions.
 *
 * Their allocations go through ob_malloc & co., so fault injection reaches
 * them too; memory they return (stbi_load*) is freed with stbi_image_free.
 */
#include "ob_core.h"

#define STBI_MALLOC(sz) ob_malloc(sz)
#define STBI_REALLOC(p, newsz) ob_realloc(p, newsz)
#define STBI_FREE(p) ob_free(p)
#define STBIW_MALLOC(sz) ob_malloc(sz)
#define STBIW_REALLOC(p, newsz) ob_realloc(p, newsz)
#define STBIW_FREE(p) ob_free(p)
#define STBIR_MALLOC(sz, ctx) ((void)(ctx), ob_malloc(sz))
#define STBIR_FREE(p, ctx) ((void)(ctx), ob_free(p))

/* Third-party code: its warnings are not ours to fix. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
#define STB_IMAGE_RESIZE_IMPLEMENTATION
#include <stb_image_resize.h>
#pragma GCC diagnostic pop
