/* Where the standard shaders are when neither the application
 * (ob_shader_compiler_desc.shader_dir) nor $OB_SHADER_DIR says: beside the
 * binary that holds this code, as installed — <its folder>/OB_SHADER_REL_DIR
 * (lib/ → ../share/obelisk/shaders) — so a moved prefix keeps working and
 * nothing points into the source tree. The binary is libobelisk.so, or the
 * executable when the engine is linked statically (the build tree has
 * build/share/obelisk/shaders for build/bin and build/tests). Last, the
 * configured install folder: a static program living outside the prefix. */
#define _GNU_SOURCE
#include "ob_shader_source.h"

#include <dlfcn.h>
#include <link.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef OB_SHADER_REL_DIR
#define OB_SHADER_REL_DIR "../share/obelisk/shaders"
#endif
#ifndef OB_SHADER_INSTALL_DIR
#define OB_SHADER_INSTALL_DIR "/usr/local/share/obelisk/shaders"
#endif

/* Any object of this file: its address names the binary it was linked into. */
static const char shader_dir_anchor = 0;

static bool is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* Folder of the shared object or executable holding this code, ob_malloc'ed
 * into *out_dir (NULL when the system cannot tell). OB_ERR_OUT_OF_HOST_MEMORY
 * only when the copy fails. */
static ob_result binary_dir(char **out_dir)
{
    *out_dir = NULL;
    Dl_info info;
    struct link_map *map = NULL;
    const char *file = "/proc/self/exe";
    /* The main program's link map has an empty name (dladdr would give argv[0]). */
    if (dladdr1(&shader_dir_anchor, &info, (void **)&map, RTLD_DL_LINKMAP) && map &&
        map->l_name && map->l_name[0])
        file = map->l_name;
    char *real = realpath(file, NULL);
    if (!real) return OB_OK;
    char *slash = strrchr(real, '/');
    if (slash) *slash = '\0';
    *out_dir = ob_strdup(real[0] ? real : "/");
    free(real);   /* realpath's buffer comes from malloc */
    return *out_dir ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
}

char *ob_shader_dir_default(void)
{
    char *bin;
    if (binary_dir(&bin) != OB_OK) return NULL;
    const char *rel[] = {OB_SHADER_REL_DIR, "../share/obelisk/shaders"};
    for (size_t i = 0; bin && i < OB_ARRAY_COUNT(rel); i++) {
        char *dir = ob_shader_path_join(bin, rel[i]);
        if (!dir || is_dir(dir)) {
            if (dir) OB_LOG_I("shader", "shaders from %s", dir);
            ob_free(bin);
            return dir;
        }
        ob_free(dir);
    }
    if (!is_dir(OB_SHADER_INSTALL_DIR))
        OB_LOG_W("shader", "no shader folder at %s/%s nor at %s: set $OB_SHADER_DIR",
                 bin ? bin : "(unknown program folder)", OB_SHADER_REL_DIR, OB_SHADER_INSTALL_DIR);
    ob_free(bin);
    return ob_strdup(OB_SHADER_INSTALL_DIR);
}
