#define _POSIX_C_SOURCE 200809L
#include "ob_demo.h"
#include "ob_scene_file.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

/* ------------------------------------------------------------ options */

static void usage(FILE *f, const char *prog, const char *extra, bool takes_input)
{
    fprintf(f,
            "usage: %s [options]%s\n"
            "  --frames F        frames to render (default 60; with --window, until it closes)\n"
            "  --threads T       0 = single-threaded, N = N workers, auto = decide per frame\n"
            "  --toggle K        switch single/multi-threaded every K frames\n"
            "  --size WxH        image size (default 640x480; each side 1 to 8192)\n"
            "  --out FILE.png    write the final image (through a symbolic link; never over a\n"
            "                    FIFO, device or directory)\n"
            "  --stats-json FILE write one object of stats per frame (the last also holds the\n"
            "                    lean report, as \"lean\")\n"
            "  --seed S          scene seed\n"
            "  --env-size N      environment map size (paraboloid half or cube face; 8 to 4096)\n"
            "  --env-map KIND    environment maps: paraboloid (default) or cube\n"
            "  --shadow-size N   shadow map size (16 to 8192)\n"
            "  --msaa N          samples per pixel of the main view: 1, 2, 4 or 8 (default 1;\n"
            "                    lowered to what the device offers, said in the log)\n"
            "  --exposure F      linear scale of the scene colour before the tone map\n"
            "                    (default 1; 2 = one stop brighter; 1e-6 to 1e6)\n"
            "  --overlay         draw the text overlay (on by default with --window)\n"
            "  --no-overlay      no text overlay, also with --window\n"
            "  --window          show the scene live (keys below; resizable)\n"
            "  --window-resize F:WxH  ask for a WxH window before frame F (tests a resize)\n"
            "  --quiet           no per-frame lines\n"
            "  --no-instancing   one draw per entity instead of one per run of a material\n"
            "                    and mesh (for comparison; the image is the same)\n"
            "  --malloc-threshold KIB  fix glibc's mmap and trim thresholds (steady RSS on\n"
            "                    long runs, slower frames on lavapipe; docs/soak.md)\n"
            "  --input SCRIPT    scripted input, as if typed in the window, also headless:\n"
            "                    'FRAME:key W; FRAME:drag left DX DY; FRAME:wheel N' (frames\n"
            "                    from 0; drag buttons left, middle, right, shift+left;\n"
            "                    keys A-Z 0-9 F1-F12 Escape); @FILE reads it from FILE\n"
            "  --screenshot-prefix P  where the S key writes: P0001.png, P0002.png, ...\n"
            "                    (default obelisk-shot-)\n"
            "%s" OB_DEMO_KEYS_HELP,
            prog, takes_input ? " FILE" : "", extra ? extra : "");
}

static bool parse_u32(const char *s, uint32_t *out)
{
    char *end;
    if (!s || *s < '0' || *s > '9') return false;   /* no sign, no blank: strtoul takes "-1" */
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end || errno == ERANGE || v > UINT32_MAX) return false;
    *out = (uint32_t)v;
    return true;
}

/* "WxH", each a decimal from 1 to OB_SETTING_SIZE_MAX and nothing else:
 * sscanf's "%ux%u" wrapped 4294967297 to 1 and ignored "x56". */
static bool parse_size(const char *s, uint32_t *w, uint32_t *h)
{
    const char *x = s ? strchr(s, 'x') : NULL;
    if (!x || x == s || (size_t)(x - s) > 10) return false;
    char first[12];
    memcpy(first, s, (size_t)(x - s));
    first[x - s] = '\0';
    return parse_u32(first, w) && parse_u32(x + 1, h) && *w >= 1 && *h >= 1 &&
           *w <= OB_SETTING_SIZE_MAX && *h <= OB_SETTING_SIZE_MAX;
}

/* Options that take a value: a missing value is said as such only for these. */
static bool takes_value(const char *a)
{
    static const char *const with_value[] = {"--frames", "--threads", "--toggle", "--size", "--out",
                                             "--stats-json", "--seed", "--objects", "--env-size",
                                             "--malloc-threshold", "--window-resize", "--msaa",
                                             "--exposure", "--shadow-size", "--input",
                                             "--screenshot-prefix", "--env-map"};
    for (size_t i = 0; i < OB_ARRAY_COUNT(with_value); i++)
        if (!strcmp(a, with_value[i])) return true;
    return false;
}

ob_threading ob_demo_options_threading(const ob_demo_options *o)
{
    return o->threads == 0 ? OB_THREADING_SINGLE : o->threads < 0 ? OB_THREADING_AUTO : OB_THREADING_MULTI;
}

/* Every option the parser knows, for the "did you mean" of a typo. */
static const char *const known_options[] = {
    "--help", "--overlay", "--no-overlay", "--window", "--quiet", "--no-instancing",
    "--allow-missing", "--allow-any-folder", "--frames", "--threads", "--toggle", "--size", "--out",
    "--stats-json", "--seed", "--objects", "--env-size", "--malloc-threshold", "--window-resize",
    "--msaa", "--exposure", "--shadow-size", "--input", "--screenshot-prefix"};

/* An argument the parser does not know, with the nearest option when a typo
 * explains it ("--frmaes": did you mean --frames?). */
static void unknown_argument(const char *prog, const char *a)
{
    const char *near = a[0] == '-' ? ob_closest_name(a, known_options,
                                                     OB_ARRAY_COUNT(known_options), 0) : NULL;
    if (near) fprintf(stderr, "%s: unknown argument '%s' (did you mean %s?)\n", prog, a, near);
    else fprintf(stderr, "%s: unknown argument '%s'\n", prog, a);
}

bool ob_demo_options_parse(int argc, char **argv, const char *usage_extra, bool takes_input,
                           ob_demo_options *o, int *out_exit)
{
    *o = (ob_demo_options){.frames = 60, .threads = 0, .width = 640, .height = 480,
                           .seed = 1, .objects = 200};
    bool overlay_set = false;
    *out_exit = 2;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = true;
        const char *range = NULL;   /* what a bad value should have been */
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout, argv[0], usage_extra, takes_input);
            *out_exit = 0;
            return false;
        } else if (!strcmp(a, "--overlay")) {
            o->overlay = overlay_set = true;
        } else if (!strcmp(a, "--no-overlay")) {
            o->overlay = false;
            overlay_set = true;
        } else if (!strcmp(a, "--window")) {
            o->window = true;
        } else if (!strcmp(a, "--quiet")) {
            o->quiet = true;
        } else if (!strcmp(a, "--no-instancing")) {
            o->no_instancing = true;
        } else if (!strcmp(a, "--allow-missing")) {
            o->allow_missing = true;
        } else if (!strcmp(a, "--allow-any-folder")) {
            o->allow_any_folder = true;
        } else if (takes_value(a) && !v) {
            fprintf(stderr, "%s: option %s needs a value\n", argv[0], a);
            return false;
        } else if (!strcmp(a, "--frames")) {
            ok = parse_u32(v, &o->frames) && o->frames > 0;
            range = "a positive integer";
            i++;
            o->frames_given = true;
        } else if (!strcmp(a, "--threads")) {
            uint32_t t;
            if (!strcmp(v, "auto")) o->threads = -1;
            else if ((ok = parse_u32(v, &t) && t <= OB_MAX_WORKERS)) o->threads = (int)t;
            range = "0 (single-threaded), a worker count or auto";
            i++;
            o->threads_given = true;
        } else if (!strcmp(a, "--toggle")) {
            ok = parse_u32(v, &o->toggle);
            i++;
        } else if (!strcmp(a, "--size")) {
            ok = parse_size(v, &o->width, &o->height);
            range = "WxH, each side from 1 to 8192";
            i++;
            o->size_given = true;
        } else if (!strcmp(a, "--out")) {
            o->out = v;
            i++;
        } else if (!strcmp(a, "--stats-json")) {
            o->stats_json = v;
            i++;
        } else if (!strcmp(a, "--seed")) {
            ok = parse_u32(v, &o->seed);
            i++;
        } else if (!strcmp(a, "--objects")) {
            ok = parse_u32(v, &o->objects) && o->objects <= 100000;
            i++;
        } else if (!strcmp(a, "--env-size")) {
            ok = parse_u32(v, &o->env_size) && o->env_size >= OB_SETTING_ENV_MAP_MIN &&
                 o->env_size <= OB_SETTING_ENV_MAP_MAX;
            range = "an integer from 8 to 4096";
            i++;
        } else if (!strcmp(a, "--env-map")) {
            ok = v && (!strcmp(v, "paraboloid") || !strcmp(v, "cube"));
            if (ok) o->env_map_kind = !strcmp(v, "cube") ? OB_ENV_MAP_CUBE : OB_ENV_MAP_PARABOLOID;
            o->env_map_given = ok;
            range = "paraboloid or cube";
            i++;
        } else if (!strcmp(a, "--malloc-threshold")) {
            ok = parse_u32(v, &o->malloc_threshold_kib) && o->malloc_threshold_kib >= 1 &&
                 o->malloc_threshold_kib <= 32 * 1024;
            i++;
        } else if (!strcmp(a, "--window-resize")) {
            const char *colon = strchr(v, ':');
            char frame[12] = "";
            if (colon && colon > v && (size_t)(colon - v) < sizeof frame)
                memcpy(frame, v, (size_t)(colon - v));
            ok = colon && parse_u32(frame, &o->resize_frame) &&
                 parse_size(colon + 1, &o->resize_width, &o->resize_height);
            range = "F:WxH, each side from 1 to 8192";
            i++;
        } else if (!strcmp(a, "--msaa")) {
            ok = parse_u32(v, &o->msaa) && (o->msaa == 1 || o->msaa == 2 || o->msaa == 4 ||
                                            o->msaa == 8);
            range = "1, 2, 4 or 8";
            i++;
        } else if (!strcmp(a, "--exposure")) {
            char *end;
            double e = strtod(v, &end);
            ok = *v && !*end && isfinite(e) && e >= OB_SETTING_EXPOSURE_MIN && e <= OB_SETTING_EXPOSURE_MAX;
            o->exposure = (float)e;
            range = "a number from 1e-06 to 1e+06";
            o->exposure_given = true;
            i++;
        } else if (!strcmp(a, "--shadow-size")) {
            ok = parse_u32(v, &o->shadow_size) && o->shadow_size >= OB_SETTING_SHADOW_MAP_MIN &&
                 o->shadow_size <= OB_SETTING_SHADOW_MAP_MAX;
            range = "an integer from 16 to 8192";
            i++;
        } else if (!strcmp(a, "--input")) {
            o->input_script = v;
            i++;
            /* A script in the argument is checked now (exit 2 like any bad
             * value); @FILE when it is read, at init. */
            ob_input_script check;   /* 12 KiB, on the stack for the check only */
            char why[200];
            if (v[0] != '@' && !ob_input_script_parse(v, &check, why, sizeof why)) {
                fprintf(stderr, "%s: --input: %s\n", argv[0], why);
                return false;
            }
        } else if (!strcmp(a, "--screenshot-prefix")) {
            ok = v[0] != '\0';
            o->screenshot_prefix = v;
            range = "a path prefix";
            i++;
        } else if (a[0] != '-' && takes_input && !o->input) {
            o->input = a;
        } else {
            unknown_argument(argv[0], a);
            usage(stderr, argv[0], usage_extra, takes_input);
            return false;
        }
        if (!ok) {
            fprintf(stderr, "%s: bad value '%s' for %s%s%s\n", argv[0], v, a, range ? ": expected " : "",
                    range ? range : "");
            return false;
        }
    }
    if (takes_input && !o->input) {
        usage(stderr, argv[0], usage_extra, takes_input);
        return false;
    }
    if (!overlay_set) o->overlay = o->window;
    *out_exit = 0;
    return true;
}

/* ------------------------------------------------------------ set-up */

ob_demo_memory ob_demo_memory_now(void)
{
    ob_demo_memory m = {0, 0, 0, 0};
    FILE *f = fopen("/proc/self/status", "r");
    if (f) {
        char line[128];
        while (fgets(line, sizeof line, f)) {
            unsigned long long v;
            if (sscanf(line, "VmRSS: %llu kB", &v) == 1) m.rss_kb = v;
            else if (sscanf(line, "VmHWM: %llu kB", &v) == 1) m.peak_rss_kb = v;
        }
        fclose(f);
    }
    m.obelisk_heap_kb = ob_heap_stats_now().live_bytes / 1024;
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
    struct mallinfo2 mi = mallinfo2();
    m.heap_in_use_kb = (unsigned long long)(mi.uordblks + mi.hblkhd) / 1024;
#endif
    return m;
}

static void lean_note_view(ob_demo_lean *l, const char *name, ob_skip_reason reason)
{
    for (uint32_t i = 0; i < l->view_count; i++) {
        if (l->views[i].reason != reason || strcmp(l->views[i].name, name)) continue;
        l->views[i].frames++;
        return;
    }
    if (l->view_count == OB_DEMO_LEAN_VIEWS) {
        l->views_more++;   /* an upper bound: the same one may come again */
        return;
    }
    snprintf(l->views[l->view_count].name, sizeof l->views[0].name, "%s", name);
    l->views[l->view_count].reason = reason;
    l->views[l->view_count++].frames = 1;
}

static void lean_note_frame(ob_demo_lean *l, const ob_frame_stats *st)
{
    for (uint32_t i = 0; i < st->skipped_count; i++)
        lean_note_view(l, st->skipped[i].name, st->skipped[i].reason);
    for (uint32_t i = 0; i < st->view_count; i++)
        if (st->views[i].skipped != OB_SKIP_NONE)
            lean_note_view(l, st->views[i].name, st->views[i].skipped);
    l->drawn_count = l->drawn_more = 0;
    for (uint32_t i = 0; i < st->view_count; i++) {
        if (st->views[i].skipped != OB_SKIP_NONE) continue;
        if (l->drawn_count == OB_DEMO_LEAN_VIEWS) {
            l->drawn_more++;
            continue;
        }
        snprintf(l->drawn[l->drawn_count].name, sizeof l->drawn[0].name, "%s", st->views[i].name);
        l->drawn[l->drawn_count].type = st->views[i].type;
        l->drawn[l->drawn_count++].draws = st->views[i].draws;
    }
    l->pipelines_created += st->pipelines_created;
    l->variants_created += st->variants_created;
    l->draws = st->draws;
    l->draw_calls = st->pm.draw_calls;
    l->instances = st->pm.instances;
    l->longest_run = st->pm.longest_run;
    l->multi_draw_runs = st->pm.multi_draw_runs;
}

static void on_stats(void *user, const ob_frame_stats *st)
{
    ob_demo *d = user;
    lean_note_frame(&d->lean, st);
    if (ob_array_reserve((void **)&d->history, &d->history_cap, d->history_count + 1,
                         sizeof *d->history) == OB_OK)
        d->history[d->history_count++] = (ob_demo_frame_times){
            st->workers, st->update_ns, st->pre_render_ns, st->record_ns, st->assemble_ns,
            st->submit_ns, st->frame_ns, st->gpu_ms, ob_frame_stats_cpu_work_ns(st),
            ob_frame_stats_wait_ns(st)};
    if (!d->opt.quiet) {
        /* The stats of a frame come once the GPU is done with it, frames in
         * flight after it was recorded: said once, with the first line. */
        if (d->history_count == 1)
            printf("(a frame's line comes when the GPU has finished it, at the start of the frame "
                   "%u later; cpu = the engine's work, wait = for the GPU, an image and the "
                   "present)\n", ob_device_frames_in_flight(ob_renderer_device(d->world.r)));
        printf("frame %4llu %-3s workers %u  cpu %7.3f ms (update %.3f pre-render %.3f record %.3f "
               "assemble %.3f submit %.3f)  wait %7.3f ms (gpu %.3f image %.3f present %.3f)  "
               "frame %7.3f ms  gpu %7.3f ms  views %u draws %u culled %u  hash %016llx\n",
               (unsigned long long)st->frame, st->workers ? "MT" : "ST", st->workers,
               (double)ob_frame_stats_cpu_work_ns(st) * 1e-6, (double)st->update_ns * 1e-6,
               (double)st->pre_render_ns * 1e-6, (double)st->record_ns * 1e-6,
               (double)st->assemble_ns * 1e-6, (double)st->submit_ns * 1e-6,
               (double)ob_frame_stats_wait_ns(st) * 1e-6, (double)st->gpu_wait_ns * 1e-6,
               (double)st->acquire_ns * 1e-6, (double)st->present_ns * 1e-6,
               (double)st->frame_ns * 1e-6, st->gpu_ms, st->view_count, st->draws, st->culled,
               (unsigned long long)st->frame_hash);
    }
    if (d->json) {
        if (d->history_count > 1) fputs(",\n", d->json);
        /* The process's memory after this frame: the soak (tests/soak)
         * tells the allocator's kept pages (rss) from live memory (heap). */
        ob_demo_memory mem = ob_demo_memory_now();
        ob_demo_write_stats_json(d->json, st, &mem);
    }
}

/* --stats-json's file, opened for writing: through a symbolic link, but
 * never a FIFO (opening one would block until a reader comes; O_NONBLOCK
 * fails at once instead), a device (/dev/full) or a directory. Truncated
 * only once it is known to be a regular file. NULL with a message. */
static FILE *open_stats_json(const char *path)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_NONBLOCK | O_CLOEXEC | O_NOCTTY, 0666);
    struct stat st;
    const char *why = NULL;
    if (fd < 0) why = errno == ENXIO ? "a FIFO, not a regular file" : strerror(errno);
    else if (fstat(fd, &st) != 0) why = strerror(errno);
    else if (!S_ISREG(st.st_mode))
        why = S_ISFIFO(st.st_mode) ? "a FIFO, not a regular file"
              : S_ISDIR(st.st_mode) ? "a directory, not a regular file" : "a device, not a regular file";
    FILE *f = NULL;
    if (!why) {
        int flags = fcntl(fd, F_GETFL);
        if (ftruncate(fd, 0) != 0 || flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0 ||
            !(f = fdopen(fd, "w")))
            why = strerror(errno);
    }
    if (why) {
        if (fd >= 0) close(fd);
        fprintf(stderr, "cannot write the stats file '%s': %s\n", path, why);
        return NULL;
    }
    if (fputs("[\n", f) == EOF) {
        fclose(f);
        fprintf(stderr, "cannot write the stats file '%s': %s\n", path, strerror(errno));
        return NULL;
    }
    return f;
}

/* Headless runs render --frames frames; windowed runs until the window
 * closes, or for --frames when it was given. */
static bool frames_bound_run(const ob_demo_options *o) { return !o->window || o->frames_given; }

/* --malloc-threshold: glibc's allocator policy, for long runs (glibc only).
 *
 * glibc's default mmap threshold is dynamic: freeing a large mmap'd block
 * raises it (up to 32 MiB), after which blocks of that size come from the
 * arenas, and the trim threshold follows it (twice the mmap threshold). The
 * driver allocates and frees many blocks of hundreds of kB to a few MB per
 * frame (lavapipe's binned scenes and command buffers), so after each new
 * high-water mark an arena keeps more free pages resident: over the 10,000
 * frames of the soak (docs/soak.md) RSS rose 220.3 -> 225.1 MB in steps
 * until frame ~6,000, while the live heap stayed flat and the arenas held
 * ~22 MB free. Fixed thresholds end that: blocks of the threshold and more
 * are mmap'd and unmapped when freed, and an arena gives its top back once
 * that much is free there (with 128 KiB the same soak held RSS at 192 MB,
 * +0.219% from frame 1,000 to 10,000). The price is a page fault per fresh
 * page of every such block, paid by the driver each frame: on lavapipe a
 * frame of the soak's scene took 659-692 ms with 128 KiB against 511-602 ms
 * with the default (medians of 100 frames, docs/soak.md). So it is an
 * option, not the default; a GPU driver's per-frame host allocations are
 * small, and there it should cost little. */
static void set_allocator_policy(uint32_t threshold_kib)
{
    if (!threshold_kib) return;
#if defined(__GLIBC__)
    int bytes = (int)(threshold_kib * 1024u);
    /* A replaced allocator (ASan's, or one preloaded) refuses: the run goes
     * on under its policy, and the warning says the option had no effect. */
    if (!mallopt(M_MMAP_THRESHOLD, bytes) || !mallopt(M_TRIM_THRESHOLD, bytes))
        OB_LOG_W("demo", "--malloc-threshold: the allocator ignores mallopt (not glibc's?)");
#else
    OB_LOG_W("demo", "--malloc-threshold: only glibc's allocator has these thresholds");
#endif
}

/* ------------------------------------------------------------ input */

/* --input: the script in the argument, or in the file after '@'. */
static ob_result load_script(ob_demo *d, const char *arg)
{
    ob_result r = OB_OK;
    char *text = NULL;
    if (arg[0] == '@') {
        char why[200] = "";
        text = ob_file_read_limited(arg + 1, "input script", 1u << 20, NULL, why, sizeof why, &r);
        if (!text) {
            fprintf(stderr, "--input: cannot read '%s': %s\n", arg + 1, why);
            return r;
        }
    }
    if (!(d->script = ob_malloc(sizeof *d->script))) {
        ob_free(text);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    char why[200];
    if (!ob_input_script_parse(text ? text : arg, d->script, why, sizeof why)) {
        fprintf(stderr, "--input: %s%s%s\n", text ? arg + 1 : "", text ? ": " : "", why);
        r = OB_ERR_PARSE;
    }
    ob_free(text);
    return r;
}

static void toggle_wireframe(ob_demo *d)
{
    ob_view *main = ob_perspective_view_base(d->world.main);
    ob_result r = ob_view_set_wireframe(main, ob_renderer_device(d->world.r), !d->wireframe);
    if (r == OB_OK) {
        d->wireframe = !d->wireframe;
        printf("input: W: wireframe %s\n", d->wireframe ? "on" : "off");
    } else {
        printf("input: W: no wireframe on this device (%s: it lacks fillModeNonSolid)\n",
               ob_device_name(ob_renderer_device(d->world.r)));
    }
}

/* The runner's keys, then the program's listener. */
static void on_key(void *user, int key, bool shift)
{
    ob_demo *d = user;
    if (key == OB_KEY_F1) {
        d->flipped = !d->flipped;
        printf("input: F1: single/multi-threaded recording flipped\n");
    } else if (key == 'S' && !shift) {
        d->screenshot_pending = true;
    } else if (key == 'W' && !shift) {
        toggle_wireframe(d);
    } else if (key == 'O' && !shift) {
        if (!d->world.overlay) {
            printf("input: O: no overlay in this run (--no-overlay, or headless without --overlay)\n");
        } else {
            d->overlay_detail = (d->overlay_detail + 1) % 2;
            printf("input: O: overlay %s\n", d->overlay_detail ? "detailed" : "summary");
        }
    } else if (key == OB_KEY_ESCAPE) {
        d->stop = true;
    }
    if (d->app_input.key) d->app_input.key(d->app_input.user, key, shift);
}

static void on_button(void *user, ob_mouse_button b, bool down, bool shift)
{
    ob_demo *d = user;
    if (d->app_input.button) d->app_input.button(d->app_input.user, b, down, shift);
}

static void on_cursor(void *user, double x, double y)
{
    ob_demo *d = user;
    if (d->app_input.cursor) d->app_input.cursor(d->app_input.user, x, y);
}

static void on_scroll(void *user, double steps)
{
    ob_demo *d = user;
    if (d->app_input.scroll) d->app_input.scroll(d->app_input.user, steps);
}

void ob_demo_set_input(ob_demo *d, const ob_input_handler *h)
{
    if (h) d->app_input = *h;
    else memset(&d->app_input, 0, sizeof d->app_input);
}

/* S: the final image as the next numbered PNG, once the frame is done. */
static ob_result take_screenshot(ob_demo *d)
{
    d->screenshot_pending = false;
    ob_result r = ob_renderer_wait_idle(d->world.r);
    if (r != OB_OK) return r;
    char path[1024];
    const char *prefix = d->opt.screenshot_prefix ? d->opt.screenshot_prefix : "obelisk-shot-";
    snprintf(path, sizeof path, "%s%04u.png", prefix, d->screenshots + 1);
    ob_image target = ob_composite_view_target(d->world.composite);
    r = ob_image_write_png(ob_renderer_device(d->world.r), target, path);
    if (r != OB_OK) {
        /* A screenshot that cannot be written is said; the run goes on. */
        printf("input: S: cannot write screenshot '%s': %s\n", path, ob_result_name(r));
        return OB_OK;
    }
    d->screenshots++;
    ob_image_info info = {0};
    ob_image_get_info(ob_renderer_device(d->world.r), target, &info);
    printf("screenshot: wrote %s (%ux%u)\n", path, info.width, info.height);
    return OB_OK;
}

ob_result ob_demo_init(ob_demo *d, const ob_demo_options *o)
{
    set_allocator_policy(o->malloc_threshold_kib);
    memset(d, 0, sizeof *d);
    d->opt = *o;
    ob_result r;
    const char *const *exts = NULL;
    uint32_t ext_count = 0;
    if (o->resize_width && !o->window) {
        fprintf(stderr, "--window-resize needs --window\n");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (o->window) {
        d->window = ob_window_open(o->width, o->height, "Obelisk", &exts, &ext_count);
        if (!d->window) return OB_ERR_UNSUPPORTED;
    }
    ob_stack_desc sd = {
        .renderer = {
            /* --malloc-threshold is the allocator's policy for this run:
             * the device must not replace its trim threshold. */
            .device = {.app_name = "obelisk-demo", .instance_extensions = exts,
                       .instance_extension_count = ext_count, .swapchain = o->window,
                       .driver_heap = o->malloc_threshold_kib ? -1 : 0},
            .worker_count = o->threads > 0 ? (uint32_t)o->threads : 0,
            .threading = ob_demo_options_threading(o),
            .gpu_timing = o->gpu_timing,
        },
        .width = o->width, .height = o->height,
        .camera = {.fovy = 1.0f, .znear = 0.05f},
        .env_map_size = o->env_size, .shadow_map_size = o->shadow_size,
        .env_map_kind = o->env_map_kind,
        .overlay = o->overlay,
        .msaa = o->msaa,
        .exposure = o->exposure,
    };
    memcpy(sd.clear_color, o->clear_color, sizeof sd.clear_color);
    memcpy(sd.sky_color, o->sky_color, sizeof sd.sky_color);
    memcpy(sd.ambient, o->ambient, sizeof sd.ambient);
    if ((r = ob_world_create(&d->world, &(ob_world_desc){.stack = sd})) != OB_OK) return r;
    if (o->no_instancing) ob_material_library_set_instancing(d->world.lib, false);
    ob_renderer_set_stats_callback(d->world.r, on_stats, d);
    if (d->window && (r = ob_window_attach(d->window, d->world.r)) != OB_OK) return r;
    /* The renderer presents the composite's target; main follows the window's size. */
    if (d->window) ob_composite_view_set_presenting(d->world.composite, true);
    if (o->stats_json && !(d->json = open_stats_json(o->stats_json))) return OB_ERR_IO;
    if (o->input_script && (r = load_script(d, o->input_script)) != OB_OK) return r;
    if (d->window) ob_window_set_input(d->window, &(ob_input_handler){on_key, on_button, on_cursor, on_scroll, d});
    /* The summary's 64 bytes per frame, taken once: a headless run's memory
     * then does not grow with its frames (what the soak measures). */
    if (frames_bound_run(o) &&
        (r = ob_array_reserve((void **)&d->history, &d->history_cap, o->frames,
                              sizeof *d->history)) != OB_OK)
        return r;
    return OB_OK;
}

void ob_demo_shutdown(ob_demo *d)
{
    if (d->world.r) ob_renderer_wait_idle(d->world.r);
    for (uint32_t i = 0; i < d->system_count; i++) ob_particle_system_destroy(d->world.views, d->systems[i]);
    /* The swapchain goes before the device it lives on. */
    ob_window_close(d->window);
    ob_world_destroy(&d->world);
    if (d->json) {   /* a run that stopped early: close the array, best effort */
        fputs("\n]\n", d->json);
        fclose(d->json);
    }
    ob_free(d->systems);
    ob_free(d->history);
    ob_free(d->script);
    memset(d, 0, sizeof *d);
}

ob_geometry *ob_demo_geometry(ob_demo *d, const ob_mesh *mesh, const char *name)
{
    return ob_stack_add_geometry(d->world.stack, mesh, name, NULL);
}

ob_node *ob_demo_entity(ob_demo *d, ob_node *parent, const char *name, ob_geometry *g,
                        ob_material *m)
{
    return ob_stack_add_entity(d->world.stack, parent, name, g, m, NULL);
}

ob_particle_system *ob_demo_particles(ob_demo *d, ob_node *parent, const ob_particle_desc *desc,
                                      ob_result *out_result)
{
    ob_result r = ob_array_reserve((void **)&d->systems, &d->system_cap, d->system_count + 1,
                                   sizeof *d->systems);
    ob_particle_system *ps = NULL;
    if (r != OB_OK)
        OB_LOG_E("demo", "particle system '%s': out of memory for the demo's list",
                 desc && desc->name ? desc->name : "(unnamed)");
    else if ((ps = ob_particle_system_create(d->world.views, d->world.scene, parent, desc, &r)))
        d->systems[d->system_count++] = ps;
    if (out_result) *out_result = ps ? OB_OK : r;
    return ps;
}

/* ------------------------------------------------------------ stats */

/* mode: 0 = single-threaded frames, 1 = multi-threaded frames, -1 = all. */
double ob_demo_median_ms(const ob_demo *d, int mode, size_t phase_offset)
{
    double *v = ob_malloc(sizeof *v * (d->history_count + 1));
    uint32_t n = 0;
    if (!v) return NAN;
    for (uint32_t i = 0; i < d->history_count; i++) {
        const ob_demo_frame_times *st = &d->history[i];
        if (mode >= 0 && (st->workers > 0) != (mode == 1)) continue;
        if (phase_offset == offsetof(ob_demo_frame_times, gpu_ms)) {
            if (st->gpu_ms < 0) continue;
            v[n++] = st->gpu_ms;
        } else {
            uint64_t ns;
            memcpy(&ns, (const char *)st + phase_offset, sizeof ns);
            v[n++] = (double)ns * 1e-6;
        }
    }
    double m = ob_median(v, n);
    ob_free(v);
    return m;
}

void ob_demo_write_stats_json(FILE *f, const ob_frame_stats *st, const ob_demo_memory *mem)
{
    fprintf(f,
            "{\"frame\":%llu,\"mode\":\"%s\",\"workers\":%u,\"update_ms\":%.4f,"
            "\"pre_render_ms\":%.4f,\"record_ms\":%.4f,\"assemble_ms\":%.4f,\"submit_ms\":%.4f,"
            "\"wait_ms\":%.4f,\"frame_ms\":%.4f,\"gpu_ms\":%.4f,\"draws\":%u,\"culled\":%u,"
            "\"pipeline_binds\":[%u,%u],\"descriptor_binds\":[%u,%u],\"push_descriptors\":[%u,%u],"
            "\"push_constants\":[%u,%u],\"vertex_binds\":[%u,%u],\"index_binds\":[%u,%u],"
            "\"uniform_bytes\":%llu,\"blocks_packed\":%u,\"blocks_reused\":%u,"
            "\"pipelines_created\":%u,\"variants_created\":%u,\"frame_hash\":\"%016llx\","
            "\"draw_calls\":%u,\"instances\":%u,\"lod_items\":%u,\"vertices\":%llu,\"descriptor_sets_allocated\":%u,"
            "\"descriptor_sets_held\":%u,\"threading\":\"%s\",\"cpu_work_ms\":%.4f,"
            "\"waiting_ms\":%.4f,\"gpu_wait_ms\":%.4f,\"acquire_ms\":%.4f,\"present_ms\":%.4f,"
            "\"views\":[",
            (unsigned long long)st->frame, st->workers ? "MT" : "ST", st->workers,
            st->update_ns * 1e-6, st->pre_render_ns * 1e-6, st->record_ns * 1e-6,
            st->assemble_ns * 1e-6, st->submit_ns * 1e-6, st->wait_ns * 1e-6, st->frame_ns * 1e-6,
            st->gpu_ms, st->draws, st->culled, st->pm.pipeline_binds_requested,
            st->pm.pipeline_binds_issued, st->pm.descriptor_binds_requested,
            st->pm.descriptor_binds_issued, st->pm.push_descriptor_requested,
            st->pm.push_descriptor_issued, st->pm.push_constant_requested,
            st->pm.push_constant_issued, st->pm.vertex_binds_requested, st->pm.vertex_binds_issued,
            st->pm.index_binds_requested, st->pm.index_binds_issued,
            (unsigned long long)st->pm.uniform_bytes, st->pm.blocks_packed, st->pm.blocks_reused,
            st->pipelines_created, st->variants_created, (unsigned long long)st->frame_hash,
            st->pm.draw_calls, st->pm.instances, st->lod_items,
            (unsigned long long)st->pm.vertices, st->pm.descriptor_sets_allocated,
            st->pm.descriptor_sets_held, ob_threading_name(st->mode),
            ob_frame_stats_cpu_work_ns(st) * 1e-6, ob_frame_stats_wait_ns(st) * 1e-6,
            st->gpu_wait_ns * 1e-6, st->acquire_ns * 1e-6, st->present_ns * 1e-6);
    for (uint32_t i = 0; i < st->view_count; i++) {
        const ob_view_stats *v = &st->views[i];
        fprintf(f,
                "%s{\"name\":\"%s\",\"type\":\"%s\",\"items\":%u,\"draws\":%u,\"culled\":%u,"
                "\"chunks\":%u,\"worker\":%d,\"cull_ms\":%.4f,\"record_ms\":%.4f,\"gpu_ms\":%.4f,"
                "\"hash\":\"%016llx\",\"skipped\":\"%s\",\"draw_calls\":%u,\"instances\":%u,"
                "\"longest_run\":%u,\"lod_items\":%u}",
                i ? "," : "", v->name, ob_view_type_name(v->type), v->items, v->draws, v->culled,
                v->chunks, v->worker, v->cull_ns * 1e-6, v->record_ns * 1e-6, v->gpu_ms,
                (unsigned long long)v->hash.hash, ob_skip_reason_name(v->skipped), v->draw_calls,
                v->instances, v->longest_run, v->lod_items);
    }
    fputs("],\"skipped\":[", f);
    for (uint32_t i = 0; i < st->skipped_count; i++)
        fprintf(f, "%s{\"name\":\"%s\",\"reason\":\"%s\"}", i ? "," : "", st->skipped[i].name,
                ob_skip_reason_name(st->skipped[i].reason));
    fputs("]", f);
    if (mem)
        fprintf(f, ",\"rss_kb\":%llu,\"peak_rss_kb\":%llu,\"heap_in_use_kb\":%llu,"
                "\"obelisk_heap_kb\":%llu", mem->rss_kb, mem->peak_rss_kb, mem->heap_in_use_kb,
                mem->obelisk_heap_kb);
    fputs("}", f);
}

#define LEAN_MATERIALS 24

/* A line of the report's materials: a material name drawn with one effect. */
typedef struct lean_row {
    const char *material, *effect;
    const ob_material *first;  /* its left-out features stand for the row's */
    uint32_t entities;
} lean_row;

/* One row per (material name, effect) in the order the scene's renderables
 * first use it: many materials of one kind (the mirror scene's palette)
 * make one row with their entity count. Rows past LEAN_MATERIALS are
 * counted in *out_other. */
static uint32_t lean_rows(ob_demo *d, lean_row rows[LEAN_MATERIALS], uint32_t *out_other)
{
    uint32_t row_count = 0, other_entities = 0, count = 0;
    ob_render_soa soa = {0};
    if (d->world.scene) ob_scene_render_soa(d->world.scene, &soa);
    count = soa.count;
    ob_view *main = d->world.main ? ob_perspective_view_base(d->world.main) : NULL;
    for (uint32_t i = 0; i < count; i++) {
        ob_material *m = soa.materials[soa.material[i]];
        if (!m) continue;
        ob_result r = OB_OK;
        const ob_effect *e = main ? ob_material_get_view_effect(m, d->world.r, soa.node[i], main,
                                                                false, &r)
                                  : NULL;
        const char *name = ob_material_name(m), *effect = e ? ob_effect_name(e) : NULL;
        uint32_t k = 0;
        while (k < row_count && (strcmp(rows[k].material, name) ||
                                 (rows[k].effect != effect &&
                                  (!rows[k].effect || !effect || strcmp(rows[k].effect, effect)))))
            k++;
        if (k == row_count) {
            if (row_count == LEAN_MATERIALS) {
                other_entities++;
                continue;
            }
            rows[row_count++] = (lean_row){name, effect, m, 0};
        }
        rows[k].entities++;
    }
    *out_other = other_entities;
    return row_count;
}

void ob_demo_print_lean_report(ob_demo *d, FILE *f)
{
    const ob_demo_lean *l = &d->lean;
    fprintf(f, "lean: %llu shader variants and %llu pipelines created over %u frames\n",
            (unsigned long long)l->variants_created, (unsigned long long)l->pipelines_created,
            d->history_count);
    fputs("lean: views left out:", f);
    for (uint32_t i = 0; i < l->view_count; i++)
        fprintf(f, "%s %s (%s, %u frames)", i ? "," : "", l->views[i].name,
                ob_skip_reason_name(l->views[i].reason), l->views[i].frames);
    if (l->views_more) fprintf(f, " and up to %u more", l->views_more);
    fputs(l->view_count ? "\n" : " none\n", f);
    fputs("lean: views drawn (last frame):", f);
    for (uint32_t i = 0; i < l->drawn_count; i++)
        fprintf(f, "%s %s (%s, %u draws)", i ? "," : "", l->drawn[i].name,
                ob_view_type_name(l->drawn[i].type), l->drawn[i].draws);
    if (l->drawn_more) fprintf(f, " and %u more", l->drawn_more);
    fputs(l->drawn_count ? "\n" : " none\n", f);
    fprintf(f, "lean: draws: %u entities in %u draw calls (%u as instances, longest run %u, "
               "%u runs as multi-draw indirect; last frame)\n",
            l->draws, l->draw_calls, l->instances, l->longest_run, l->multi_draw_runs);
    uint32_t samples = d->world.main ? ob_perspective_view_samples(d->world.main) : 1;
    if (samples > 1)
        fprintf(f, "lean: MSAA targets: view 'main' draws %ux into multisampled colour and depth "
                   "targets, resolved before the composite\n", samples);
    else
        fputs("lean: MSAA targets: none (view 'main' is single-sampled)\n", f);
    lean_row rows[LEAN_MATERIALS];
    uint32_t other_entities;
    uint32_t row_count = lean_rows(d, rows, &other_entities);
    for (uint32_t k = 0; k < row_count; k++) {
        char left[256];
        uint32_t n_left = ob_material_pbr_left_out(rows[k].first, left, sizeof left);
        fprintf(f, "lean: material %s: %s", rows[k].material,
                rows[k].effect ? rows[k].effect : "(no effect in the main view)");
        if (n_left) fprintf(f, " (left out: %s)", left);
        if (rows[k].entities > 1) fprintf(f, " [%u entities]", rows[k].entities);
        fputc('\n', f);
    }
    if (other_entities)
        fprintf(f, "lean: and %u more entities with other materials\n", other_entities);
}

/* A JSON string: quotes, backslashes and control characters escaped (names
 * come from model files). */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++) {
        if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
        else if (*p < 0x20 || *p == 0x7f) fprintf(f, "\\u%04x", *p);
        else fputc(*p, f);
    }
    fputc('"', f);
}

/* The lean report as one JSON object: what ob_demo_print_lean_report says. */
static void write_lean_json(ob_demo *d, FILE *f)
{
    const ob_demo_lean *l = &d->lean;
    fprintf(f, "{\"frames\":%u,\"variants_created\":%llu,\"pipelines_created\":%llu,\"views_left_out\":[",
            d->history_count, (unsigned long long)l->variants_created,
            (unsigned long long)l->pipelines_created);
    for (uint32_t i = 0; i < l->view_count; i++) {
        fputs(i ? ",{\"name\":" : "{\"name\":", f);
        json_string(f, l->views[i].name);
        fprintf(f, ",\"reason\":\"%s\",\"frames\":%u}", ob_skip_reason_name(l->views[i].reason),
                l->views[i].frames);
    }
    fputs("],\"views_drawn\":[", f);
    for (uint32_t i = 0; i < l->drawn_count; i++) {
        fputs(i ? ",{\"name\":" : "{\"name\":", f);
        json_string(f, l->drawn[i].name);
        fprintf(f, ",\"type\":\"%s\",\"draws\":%u}", ob_view_type_name(l->drawn[i].type),
                l->drawn[i].draws);
    }
    fprintf(f, "],\"views_drawn_more\":%u", l->drawn_more);
    fprintf(f, ",\"views_left_out_more\":%u,\"msaa_samples\":%u,\"draws\":%u,"
            "\"draw_calls\":%u,\"instances\":%u,\"longest_run\":%u,\"multi_draw_runs\":%u,"
            "\"materials\":[",
            l->views_more, d->world.main ? ob_perspective_view_samples(d->world.main) : 1, l->draws,
            l->draw_calls, l->instances, l->longest_run, l->multi_draw_runs);
    lean_row rows[LEAN_MATERIALS];
    uint32_t other_entities;
    uint32_t row_count = lean_rows(d, rows, &other_entities);
    for (uint32_t k = 0; k < row_count; k++) {
        char left[256];
        uint32_t n_left = ob_material_pbr_left_out(rows[k].first, left, sizeof left);
        fputs(k ? ",{\"material\":" : "{\"material\":", f);
        json_string(f, rows[k].material);
        fputs(",\"effect\":", f);
        if (rows[k].effect) json_string(f, rows[k].effect);
        else fputs("null", f);
        fputs(",\"left_out\":", f);
        json_string(f, n_left ? left : "");
        fprintf(f, ",\"entities\":%u}", rows[k].entities);
    }
    fprintf(f, "],\"other_entities\":%u}", other_entities);
}

/* Ends --stats-json: the lean report goes into the last frame's object as
 * "lean" (the file stays an array with one entry per frame, so readers that
 * count entries as frames are unaffected), then the array is closed and
 * every write and the close are checked: a full disk is an error, not a
 * short file and exit 0. */
static bool finish_stats_json(ob_demo *d)
{
    FILE *f = d->json;
    d->json = NULL;
    bool ok = true;
    if (d->history_count > 0) {
        /* Reopen the last object: its closing brace is the file's last byte. */
        ok = fflush(f) == 0 && fseek(f, -1, SEEK_END) == 0;
        if (ok) {
            fputs(",\"lean\":", f);
            write_lean_json(d, f);
            fputc('}', f);
        }
    }
    fputs("\n]\n", f);
    ok = ok && !ferror(f);
    int err = errno;
    if (fclose(f) != 0) {
        ok = false;
        err = errno;
    }
    if (!ok) fprintf(stderr, "cannot write the stats file '%s': %s\n", d->opt.stats_json, strerror(err));
    return ok;
}

static void print_summary(const ob_demo *d)
{
    static const struct { const char *name; size_t off; } phases[] = {
        {"update", offsetof(ob_demo_frame_times, update_ns)},
        {"pre-render", offsetof(ob_demo_frame_times, pre_render_ns)},
        {"record", offsetof(ob_demo_frame_times, record_ns)},
        {"assemble", offsetof(ob_demo_frame_times, assemble_ns)},
        {"submit", offsetof(ob_demo_frame_times, submit_ns)},
        {"cpu work", offsetof(ob_demo_frame_times, cpu_work_ns)},
        {"waiting", offsetof(ob_demo_frame_times, waiting_ns)},
        {"frame", offsetof(ob_demo_frame_times, frame_ns)},
        {"gpu", offsetof(ob_demo_frame_times, gpu_ms)},
    };
    uint32_t counts[2] = {0, 0};
    for (uint32_t i = 0; i < d->history_count; i++) counts[d->history[i].workers > 0]++;
    printf("summary: median ms per phase over %u frames\n  %-10s", d->history_count, "mode");
    for (size_t p = 0; p < OB_ARRAY_COUNT(phases); p++) printf(" %10s", phases[p].name);
    printf("\n");
    double med[2][OB_ARRAY_COUNT(phases)];
    for (int m = 0; m < 2; m++) {
        if (!counts[m]) continue;
        printf("  %-3s (%4u)", m ? "MT" : "ST", counts[m]);
        for (size_t p = 0; p < OB_ARRAY_COUNT(phases); p++) {
            med[m][p] = ob_demo_median_ms(d, m, phases[p].off);
            printf(" %10.3f", med[m][p]);
        }
        printf("\n");
    }
    if (counts[0] && counts[1]) {
        printf("  MT/ST     ");
        for (size_t p = 0; p < OB_ARRAY_COUNT(phases); p++)
            printf(" %10.3f", med[0][p] > 0 ? med[1][p] / med[0][p] : NAN);
        printf("\n");
    }
}

/* ------------------------------------------------------------ frames */

static ob_threading frame_mode(const ob_demo_options *o, uint32_t frame, bool flipped)
{
    ob_threading base = ob_demo_options_threading(o);
    bool flip = flipped != (o->toggle && (frame / o->toggle) % 2 == 1);
    if (flip) return base == OB_THREADING_SINGLE ? OB_THREADING_MULTI : OB_THREADING_SINGLE;
    return base;
}

/* The overlay shows the newest complete frame (ob_renderer_last_stats:
 * frames in flight behind), in summary or, after O, in detail. */
static void overlay_text(ob_demo *d)
{
    if (!d->world.overlay) return;
    const ob_frame_stats *st = ob_renderer_last_stats(d->world.r);
    char text[4096];
    int n = snprintf(text, sizeof text,
                     "OBELISK  %s  workers %u\ncpu %.2f ms  wait %.2f ms  gpu %.2f ms\n"
                     "views %u  draws %u  culled %u",
                     ob_threading_name(st->mode), st->workers,
                     (double)ob_frame_stats_cpu_work_ns(st) * 1e-6,
                     (double)ob_frame_stats_wait_ns(st) * 1e-6, st->gpu_ms, st->view_count,
                     st->draws, st->culled);
    if (d->overlay_detail) {
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "\nframe %llu  update %.2f  pre-render %.2f  record %.2f  assemble %.2f  "
                      "submit %.2f\nwait: gpu %.2f  image %.2f  present %.2f  (ms)%s%s",
                      (unsigned long long)st->frame, (double)st->update_ns * 1e-6,
                      (double)st->pre_render_ns * 1e-6, (double)st->record_ns * 1e-6,
                      (double)st->assemble_ns * 1e-6, (double)st->submit_ns * 1e-6,
                      (double)st->gpu_wait_ns * 1e-6, (double)st->acquire_ns * 1e-6,
                      (double)st->present_ns * 1e-6, d->wireframe ? "\nwireframe" : "",
                      d->overlay_extra[0] ? "\n" : "");
        if (d->overlay_extra[0] && n < (int)sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n, "%s", d->overlay_extra);
        for (uint32_t i = 0; i < st->view_count && n < (int)sizeof text - 80; i++)
            n += snprintf(text + n, sizeof text - (size_t)n, "\n  %-20.20s %5u draws %s", st->views[i].name,
                          st->views[i].draws, ob_view_type_name(st->views[i].type));
    }
    ob_overlay_view_set_text(d->world.overlay, text);
}

int ob_demo_run(ob_demo *d, ob_demo_update_fn update, void *user)
{
    const double dt = 1.0 / 60.0;
    /* F1 in the window flips the mode. */
    const bool counted = frames_bound_run(&d->opt);
    for (uint32_t f = 0; (!counted || f < d->opt.frames) && (!d->window || ob_window_poll(d->window));
         f++) {
        if (d->window && ob_window_take_toggle(d->window)) d->flipped = !d->flipped;
        if (d->script)
            ob_input_script_play(d->script, f,
                                 &(ob_input_handler){on_key, on_button, on_cursor, on_scroll, d});
        if (d->stop) break;
        if (d->window && d->opt.resize_width && f == d->opt.resize_frame)
            ob_window_request_size(d->window, d->opt.resize_width, d->opt.resize_height);
        ob_renderer_set_threading(d->world.r, frame_mode(&d->opt, f, d->flipped),
                                  d->opt.threads > 0 ? (uint32_t)d->opt.threads : 0);
        if (update) update(d, f, d->world.stack->time, user);
        ob_result r = ob_stack_frame_begin(d->world.stack, dt);
        if (r != OB_OK) {
            fprintf(stderr, "frame %u: begin_frame failed: %s\n", f, ob_result_name(r));
            return 1;
        }
        overlay_text(d);
        ob_views_render(d->world.views, d->world.stack->final_view);
        r = ob_renderer_end_frame(d->world.r);
        if (r != OB_OK) {
            fprintf(stderr, "frame %u: %s\n", f, ob_result_name(r));
            return 1;
        }
        if (d->screenshot_pending && (r = take_screenshot(d)) != OB_OK) {
            fprintf(stderr, "frame %u: screenshot: %s\n", f, ob_result_name(r));
            return 1;
        }
    }
    if (ob_renderer_wait_idle(d->world.r) != OB_OK) return 1;
    print_summary(d);
    ob_demo_print_lean_report(d, stdout);
    ob_demo_memory mem = ob_demo_memory_now();
    if (mem.rss_kb)
        printf("memory: resident %.1f MiB (peak %.1f MiB), heap in use %.1f MiB, of it "
               "Obelisk's %.1f MiB\n", mem.rss_kb / 1024.0, mem.peak_rss_kb / 1024.0,
               mem.heap_in_use_kb / 1024.0, mem.obelisk_heap_kb / 1024.0);
    if (d->window) {
        ob_present_stats ps = ob_renderer_present_stats(d->world.r);
        printf("window: %u frames presented, %u skipped (minimised or swapchain out of date), "
               "%u swapchains, last %ux%u\n", ps.presented, ps.skipped, ps.swapchains, ps.width,
               ps.height);
    }
    ob_validation_counts vc = ob_device_validation_counts(ob_renderer_device(d->world.r));
    if (ob_device_validation_enabled(ob_renderer_device(d->world.r)))
        printf("validation: %u errors, %u warnings\n", vc.errors, vc.warnings);
    if (d->json && !finish_stats_json(d)) return 1;
    if (d->opt.out) {
        ob_result r = ob_image_write_png(ob_renderer_device(d->world.r),
                                         ob_composite_view_target(d->world.composite), d->opt.out);
        if (r != OB_OK) {
            fprintf(stderr, "cannot write '%s': %s\n", d->opt.out, ob_result_name(r));
            return 1;
        }
        ob_image_info info = {0};
        ob_image_get_info(ob_renderer_device(d->world.r), ob_composite_view_target(d->world.composite), &info);
        printf("wrote %s (%ux%u)\n", d->opt.out, info.width, info.height);
    }
    if (ob_device_validation_enabled(ob_renderer_device(d->world.r)) && (vc.errors || vc.warnings))
        return 3;
    return 0;
}
