/* ob_golden.c — compares a rendered PNG with its golden image (tests/golden).
 *
 *   ob_golden IMAGE GOLDEN [--tolerance T] [--max-pixels N] [--diff OUT.png] [--report]
 *
 * A pixel differs when any of its channels (R, G, B, A) differs from the
 * golden's by more than T (0..255, default 2). The comparison passes when at
 * most N pixels differ (default: 0.1% of the pixels, rounded up). Either way
 * it prints one line: the number of differing pixels, the largest channel
 * difference and where it is. On failure, and whenever --diff is given and
 * the images are not identical, a diff image is written (default
 * IMAGE-without-.png + ".diff.png"): the golden in dim grey, pixels that
 * differ beyond the tolerance in red, pixels that differ within it in yellow.
 *
 * --report (used when regenerating goldens) never fails on a difference: it
 * prints "unchanged", "new" (GOLDEN does not exist) or "changed: N pixels
 * differ by more than T, largest difference D" and exits 0.
 *
 * Exit status: 0 pass (or --report), 1 the images differ beyond the limits or
 * their sizes differ, 2 bad usage or an image that cannot be read or written.
 * Single-threaded program; no state besides its arguments.
 */
#include "ob_core.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>
#include <stb_image_write.h>

typedef struct ob_golden_diff {
    long differing;        /* pixels with a channel beyond the tolerance */
    long within;           /* pixels that differ, but within the tolerance */
    int largest;           /* largest channel difference, 0..255 */
    int largest_x, largest_y, largest_channel;
} ob_golden_diff;

static void usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s IMAGE GOLDEN [--tolerance T] [--max-pixels N] [--diff OUT.png] [--report]\n"
            "  T: per-channel tolerance, 0..255 (default 2)\n"
            "  N: most pixels allowed to differ by more than T (default 0.1%% of the pixels)\n",
            argv0);
}

static int parse_count(const char *text, long max, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < 0 || v > max) return 0;
    *out = v;
    return 1;
}

static void compare(const unsigned char *img, const unsigned char *gold, int w, int h, int tolerance,
                    ob_golden_diff *out)
{
    memset(out, 0, sizeof *out);
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            const unsigned char *a = img + ((size_t)y * w + x) * 4;
            const unsigned char *b = gold + ((size_t)y * w + x) * 4;
            int worst = 0, worst_c = 0;
            for (int c = 0; c < 4; c++) {
                int d = abs((int)a[c] - (int)b[c]);
                if (d > worst) worst = d, worst_c = c;
            }
            if (worst > tolerance) out->differing++;
            else if (worst > 0) out->within++;
            if (worst > out->largest) {
                out->largest = worst;
                out->largest_x = x, out->largest_y = y, out->largest_channel = worst_c;
            }
        }
    }
}

/* The golden dimmed to grey, differing pixels highlighted (see the top). */
static int write_diff(const char *path, const unsigned char *img, const unsigned char *gold, int w, int h,
                      int tolerance)
{
    unsigned char *out = ob_malloc((size_t)w * h * 3);
    if (!out) {
        fprintf(stderr, "ob_golden: out of memory for the diff image\n");
        return 0;
    }
    for (size_t i = 0; i < (size_t)w * h; i++) {
        const unsigned char *a = img + i * 4, *b = gold + i * 4;
        int worst = 0;
        for (int c = 0; c < 4; c++) {
            int d = abs((int)a[c] - (int)b[c]);
            if (d > worst) worst = d;
        }
        unsigned char *o = out + i * 3;
        if (worst > tolerance) {
            o[0] = 255, o[1] = 0, o[2] = 0;
        } else if (worst > 0) {
            o[0] = 255, o[1] = 255, o[2] = 0;
        } else {
            unsigned char grey = (unsigned char)((b[0] * 77 + b[1] * 150 + b[2] * 29) / 256 / 3);
            o[0] = o[1] = o[2] = grey;
        }
    }
    int ok = stbi_write_png(path, w, h, 3, out, w * 3);
    ob_free(out);
    if (!ok) fprintf(stderr, "ob_golden: could not write the diff image %s\n", path);
    return ok;
}

static const char *channel_name(int c)
{
    return (const char *[]){"R", "G", "B", "A"}[c & 3];
}

int main(int argc, char **argv)
{
    const char *image_path = NULL, *golden_path = NULL, *diff_path = NULL;
    long tolerance = 2, max_pixels = -1;
    int report = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "--tolerance") && i + 1 < argc) {
            if (!parse_count(argv[++i], 255, &tolerance)) {
                fprintf(stderr, "ob_golden: --tolerance takes 0..255, not '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(arg, "--max-pixels") && i + 1 < argc) {
            if (!parse_count(argv[++i], 1L << 40, &max_pixels)) {
                fprintf(stderr, "ob_golden: --max-pixels takes a count, not '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(arg, "--diff") && i + 1 < argc) {
            diff_path = argv[++i];
        } else if (!strcmp(arg, "--report")) {
            report = 1;
        } else if (arg[0] == '-' && arg[1]) {
            usage(argv[0]);
            return 2;
        } else if (!image_path) {
            image_path = arg;
        } else if (!golden_path) {
            golden_path = arg;
        } else {
            usage(argv[0]);
            return 2;
        }
    }
    if (!image_path || !golden_path) {
        usage(argv[0]);
        return 2;
    }

    int w = 0, h = 0, gw = 0, gh = 0, channels = 0;
    unsigned char *img = stbi_load(image_path, &w, &h, &channels, 4);
    if (!img) {
        fprintf(stderr, "ob_golden: cannot read %s: %s\n", image_path, stbi_failure_reason());
        return 2;
    }
    FILE *probe = fopen(golden_path, "rb");
    if (!probe) {
        stbi_image_free(img);
        if (report) {
            printf("new\n");
            return 0;
        }
        fprintf(stderr, "ob_golden: no golden image %s (create it with ./setup.sh golden and review it)\n",
                golden_path);
        return 1;
    }
    fclose(probe);
    unsigned char *gold = stbi_load(golden_path, &gw, &gh, &channels, 4);
    if (!gold) {
        fprintf(stderr, "ob_golden: cannot read %s: %s\n", golden_path, stbi_failure_reason());
        stbi_image_free(img);
        return 2;
    }
    int rc = 0;
    if (w != gw || h != gh) {
        if (report) printf("changed: size %dx%d, was %dx%d\n", w, h, gw, gh);
        else fprintf(stderr, "ob_golden: %s is %dx%d but the golden %s is %dx%d\n", image_path, w, h,
                     golden_path, gw, gh);
        rc = report ? 0 : 1;
        goto done;
    }
    if (max_pixels < 0) max_pixels = ((long)w * h + 999) / 1000;

    ob_golden_diff d;
    compare(img, gold, w, h, (int)tolerance, &d);
    if (report) {
        if (d.differing == 0 && d.within == 0) printf("unchanged\n");
        else printf("changed: %ld pixels differ by more than %ld (%ld within it), largest difference %d\n",
                    d.differing, tolerance, d.within, d.largest);
        goto done;
    }
    int pass = d.differing <= max_pixels;
    printf("%s: %ld of %d pixels differ from %s by more than %ld (at most %ld allowed), %ld within it; "
           "largest difference %d (%s at %d,%d)\n",
           pass ? "match" : "MISMATCH", d.differing, w * h, golden_path, tolerance, max_pixels, d.within,
           d.largest, channel_name(d.largest_channel), d.largest_x, d.largest_y);
    char fallback[4096];
    if (!pass && !diff_path) {
        size_t n = strlen(image_path);
        if (n > 4 && !strcmp(image_path + n - 4, ".png")) n -= 4;
        if (n + sizeof ".diff.png" > sizeof fallback) n = sizeof fallback - sizeof ".diff.png";
        memcpy(fallback, image_path, n);
        memcpy(fallback + n, ".diff.png", sizeof ".diff.png");
        diff_path = fallback;
    }
    if (diff_path && (d.differing || d.within)) {
        if (write_diff(diff_path, img, gold, w, h, (int)tolerance))
            printf("diff image: %s (red: beyond the tolerance, yellow: within it)\n", diff_path);
        else if (pass) rc = 2;
    }
    if (!pass) rc = 1;
done:
    stbi_image_free(gold);
    stbi_image_free(img);
    return rc;
}
