#define _DEFAULT_SOURCE
#include "ob_test.h"

/* Apart from ob_test.c so that only tests that copy shaders pull the
 * shader folder's code into their link. */

#include <dirent.h>
#include <stdio.h>

#include "ob_shader_source.h"   /* ob_shader_dir_default: where the copy comes from */

static void copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    assert_non_null(in);
    assert_non_null(out);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0) assert_int_equal(fwrite(buf, 1, n, out), n);
    fclose(in);
    assert_int_equal(fclose(out), 0);
}

uint32_t ob_test_copy_shader_folder(const char *to)
{
    char *from = ob_shader_dir_default();
    assert_non_null(from);
    DIR *d = opendir(from);
    assert_non_null(d);
    uint32_t count = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        char a[1024], b[1024];
        snprintf(a, sizeof a, "%s/%s", from, e->d_name);
        snprintf(b, sizeof b, "%s/%s", to, e->d_name);
        copy_file(a, b);
        count++;
    }
    closedir(d);
    ob_free(from);
    return count;
}
