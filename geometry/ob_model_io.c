/* ob_model_io.c — every file assimp opens for a model goes through here
 * (ob_model_internal.h, "File access").
 *
 * assimp opens more than the model: a glTF file's buffers, an OBJ file's
 * mtllib, a glTF 1 file's shaders. Through its default file system it would
 * open any of them with fopen: a FIFO blocks forever, "../../etc/passwd"
 * is read and drawn as vertices. So imports run with an aiFileIO of ours:
 * - only regular files are opened, without blocking (ob_file_open_regular:
 *   O_NONBLOCK, then fstat);
 * - a file other than the model must resolve, after symbolic links, inside
 *   the model file's folder (unless the caller allows any folder);
 * - no file is bigger than OB_MODEL_MAX_FILE_BYTES;
 * - the model itself may be served from memory, patched (ob_model_gltf.c
 *   hides glTF skins from assimp).
 * A refusal is logged naming the model and the file, and remembered: the
 * import then fails with it, whatever assimp would make of a missing file
 * (its OBJ reader goes on without the materials).
 */
#define _XOPEN_SOURCE 700
#include "ob_model_internal.h"

#include <assimp/cfileio.h>

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* One open file: a descriptor, or the patched model in memory. */
typedef struct io_file {
    int fd;                  /* -1 for memory */
    const uint8_t *memory;
    uint64_t size, at;
} io_file;

static io_file *file_of(struct aiFile *f) { return (io_file *)f->UserData; }

static size_t io_read(struct aiFile *f, char *buffer, size_t size, size_t count)
{
    io_file *h = file_of(f);
    if (!size || !count || h->at >= h->size) return 0;
    uint64_t want = (uint64_t)size * count, left = h->size - h->at;
    if (count > SIZE_MAX / size) want = left;
    if (want > left) want = left - left % size;
    if (!want) return 0;
    if (h->memory) {
        memcpy(buffer, h->memory + h->at, (size_t)want);
        h->at += want;
        return (size_t)want / size;
    }
    size_t got = 0;
    while (got < want) {
        ssize_t n = pread(h->fd, buffer + got, (size_t)(want - got), (off_t)(h->at + got));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        got += (size_t)n;
    }
    got -= got % size;
    h->at += got;
    return got / size;
}

static size_t io_write(struct aiFile *f, const char *buffer, size_t size, size_t count)
{
    (void)f, (void)buffer, (void)size, (void)count;
    return 0;   /* opened for reading only */
}

static size_t io_tell(struct aiFile *f) { return (size_t)file_of(f)->at; }
static size_t io_size(struct aiFile *f) { return (size_t)file_of(f)->size; }
static void io_flush(struct aiFile *f) { (void)f; }

static enum aiReturn io_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    io_file *h = file_of(f);
    uint64_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? h->at : h->size;
    if (origin != aiOrigin_SET && origin != aiOrigin_CUR && origin != aiOrigin_END)
        return aiReturn_FAILURE;
    uint64_t to = base + offset;   /* size_t wraps for a negative offset, as assimp passes it */
    if (origin == aiOrigin_SET) to = offset;
    if (to > h->size) return aiReturn_FAILURE;
    h->at = to;
    return aiReturn_SUCCESS;
}

static void refuse(ob_model_io *io, const char *name, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void refuse(ob_model_io *io, const char *name, const char *fmt, ...)
{
    char why[320];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    /* assimp asks for a file several times (exists? then open): the first
     * refusal is the one logged and returned. */
    if (io->refused != OB_OK) return;
    io->refused = OB_ERR_IO;
    OB_LOG_E(OB_MODEL_LOG, "%s: refused to read '%s': %s", io->model_path, name, why);
}

static bool is_model_path(const ob_model_io *io, const char *name)
{
    if (strcmp(name, io->model_path) == 0) return true;
    /* assimp may hand the path back rebuilt ("./x.gltf" for "x.gltf"). */
    char *a = realpath(name, NULL);
    bool same = a && io->model_real && strcmp(a, io->model_real) == 0;
    free(a);
    return same;
}

bool ob_model_io_inside(const ob_model_io *io, const char *path, char *why, size_t why_size)
{
    if (io->any_folder) return true;
    char *real = realpath(path, NULL);
    if (!real) {
        snprintf(why, why_size, "%s", strerror(errno));
        return false;
    }
    size_t n = io->root ? strlen(io->root) : 0;
    bool inside = n && strncmp(real, io->root, n) == 0 &&
                  (real[n] == '/' || (n == 1 && io->root[0] == '/'));
    if (!inside)
        snprintf(why, why_size, "it resolves to '%s', outside the model's folder '%s' (other "
                 "folders must be allowed explicitly)", real, io->root ? io->root : "?");
    free(real);
    return inside;
}

static struct aiFile *io_open(struct aiFileIO *fio, const char *name, const char *mode)
{
    ob_model_io *io = (ob_model_io *)fio->UserData;
    if (!name || !mode || mode[0] != 'r' || strchr(mode, '+')) {
        refuse(io, name ? name : "(null)", "assimp asked to open it for writing ('%s')", mode ? mode : "");
        return NULL;
    }
    io_file *h = ob_calloc(1, sizeof *h);
    struct aiFile *f = ob_calloc(1, sizeof *f);
    if (!h || !f) {
        ob_free(h);
        ob_free(f);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory opening '%s'", io->model_path, name);
        if (io->refused == OB_OK) io->refused = OB_ERR_OUT_OF_HOST_MEMORY;
        return NULL;
    }
    h->fd = -1;
    bool model = is_model_path(io, name);
    if (model && io->patched) {
        h->memory = io->patched;
        h->size = io->patched_size;
    } else {
        char why[512];
        if (!model && !ob_model_io_inside(io, name, why, sizeof why)) {
            /* A file that does not exist is assimp's to report (a glTF buffer
             * it needs, an optional .mtl it goes without): only files that
             * exist outside the folder are refused. */
            struct stat st;
            if (stat(name, &st) == 0) refuse(io, name, "%s", why);
            goto fail;
        }
        ob_result r;
        struct stat st;
        if (stat(name, &st) != 0) goto fail;   /* absent: assimp probes names */
        h->fd = ob_file_open_regular(name, "model file", OB_MODEL_MAX_FILE_BYTES, &h->size, why,
                                     sizeof why, &r);
        if (h->fd < 0) {
            bool first = io->refused == OB_OK;
            refuse(io, name, "%s", why);
            if (first && r == OB_ERR_LIMIT) io->refused = OB_ERR_LIMIT;
            goto fail;
        }
    }
    *f = (struct aiFile){.ReadProc = io_read, .WriteProc = io_write, .TellProc = io_tell,
                         .FileSizeProc = io_size, .SeekProc = io_seek, .FlushProc = io_flush,
                         .UserData = (aiUserData)h};
    return f;
fail:
    ob_free(h);
    ob_free(f);
    return NULL;
}

static void io_close(struct aiFileIO *fio, struct aiFile *f)
{
    (void)fio;
    if (!f) return;
    io_file *h = file_of(f);
    if (h && h->fd >= 0) close(h->fd);
    ob_free(h);
    ob_free(f);
}

ob_result ob_model_io_init(ob_model_io *io, const char *model_path, bool any_folder)
{
    memset(io, 0, sizeof *io);
    io->model_path = model_path;
    io->any_folder = any_folder;
    char *real = realpath(model_path, NULL);
    if (!real) {
        OB_LOG_E(OB_MODEL_LOG, "%s: cannot open model file: %s", model_path, strerror(errno));
        return OB_ERR_IO;
    }
    io->model_real = ob_strdup(real);
    char *slash = strrchr(real, '/');
    if (slash == real) slash[1] = '\0';   /* a model in "/" */
    else if (slash) *slash = '\0';
    io->root = ob_strdup(real);
    free(real);
    if (!io->model_real || !io->root) {
        ob_model_io_release(io);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory", model_path);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    return OB_OK;
}

void ob_model_io_release(ob_model_io *io)
{
    ob_free(io->model_real);
    ob_free(io->root);
    ob_free(io->patched);
    io->model_real = io->root = NULL;
    io->patched = NULL;
}

struct aiFileIO ob_model_io_assimp(ob_model_io *io)
{
    return (struct aiFileIO){.OpenProc = io_open, .CloseProc = io_close, .UserData = (aiUserData)io};
}
