/* ob_demo.h — the demo runner the demo programs share: options, the
 * standard set-up (an ob_stack from views/scene/ob_stack.h, with the window when
 * --window is given), the frame loop with its ST/MT toggling, input (the
 * window's events and --input scripts, one listener: ob_input.h) with the
 * runner's keys, per-frame lines (the engine's CPU work apart from waiting),
 * the JSON stats, the summary of medians per mode and the lean-scene
 * report (what the run left out).
 *
 * Lifecycle: ob_demo_options_parse → ob_demo_init → build the scene →
 * ob_demo_run → ob_demo_shutdown (also after a failed init). Thread rule:
 * [render thread] for every function (the renderer's and GLFW's rule).
 * Failure: init returns the failing step's result (logged by the engine);
 * the helpers that make things return NULL, the cause logged.
 */
#ifndef OB_DEMO_H
#define OB_DEMO_H

#include <stdio.h>

#include "ob_geometry.h"
#include "ob_input.h"
#include "ob_mesh.h"
#include "ob_world.h"
#include "ob_window.h"

typedef struct ob_demo_options {
    uint32_t frames;          /* --frames F (default 60; with --window: until closed) */
    int threads;              /* --threads T: 0 = single-threaded, N workers, -1 = auto */
    uint32_t toggle;          /* --toggle K: switch ST/MT every K frames (0 = never) */
    uint32_t width, height;   /* --size WxH (640x480) */
    const char *out;          /* --out image.png */
    const char *stats_json;   /* --stats-json stats.json */
    uint32_t seed;            /* --seed S */
    uint32_t objects;         /* --objects N (obelisk-mirror) */
    uint32_t env_size;        /* --env-size (paraboloid half or cube face size) */
    ob_env_map_kind env_map_kind; /* --env-map paraboloid|cube */
    bool env_map_given;
    uint32_t shadow_size;     /* --shadow-size */
    uint32_t msaa;            /* --msaa 1|2|4|8 (main view; 0 = not given → 1) */
    float exposure;           /* --exposure F (> 0; 0 = not given → the default) */
    bool overlay;             /* --overlay / --no-overlay */
    bool window;              /* --window */
    uint32_t resize_frame, resize_width, resize_height; /* --window-resize F:WxH (0 = none) */
    bool quiet;               /* --quiet: no per-frame lines */
    bool no_instancing;       /* --no-instancing: one draw per entity */
    uint32_t malloc_threshold_kib; /* --malloc-threshold: glibc's thresholds (0 = its own) */
    ob_gpu_timing gpu_timing; /* ob_renderer_desc.gpu_timing (obelisk-bench --gpu-timing) */
    const char *input;        /* positional argument (obelisk-view FILE) */
    /* Set by the parser when --size / --threads were given, so that settings
     * from a scene file do not override the command line; frames_given makes
     * a windowed run stop after --frames. */
    bool size_given, threads_given, frames_given, exposure_given;
    /* obelisk-view: --allow-missing renders a scene whose models did not all
     * load and exits 0 (otherwise it exits 2 after rendering the rest);
     * --allow-any-folder lets models and scene files refer to files outside
     * their own folder (ob_model_desc.allow_any_folder): trusted content. */
    bool allow_missing, allow_any_folder;
    float clear_color[4];     /* main view clear colour; all zero → dark blue-grey */
    float sky_color[4];       /* what env maps clear to; all zero → clear_color */
    float ambient[4];         /* rgb, w = intensity; w = 0 → the views' default */
    /* --input SCRIPT (ob_input.h; "@FILE" reads it from FILE): events fed to
     * the same listener as the window's, before the update of their frame. */
    const char *input_script;
    /* --screenshot-prefix P: the S key writes P0001.png, P0002.png, ...
     * (default "obelisk-shot-", in the working directory). */
    const char *screenshot_prefix;
} ob_demo_options;

/* The mode --threads asks for: 0 → single, N → multi, auto → auto. */
ob_threading ob_demo_options_threading(const ob_demo_options *o);

/* Parses argv into *o (defaults first). Prints usage and returns false on
 * --help or a bad option (*out_exit says the exit code). */
bool ob_demo_options_parse(int argc, char **argv, const char *usage_extra, bool takes_input,
                           ob_demo_options *o, int *out_exit);

/* What the summary keeps of each completed frame. (A whole ob_frame_stats
 * is 23 KB: kept for every frame, 10,000 frames grew the process by 230 MB.) */
typedef struct ob_demo_frame_times {
    uint32_t workers;         /* 0 = single-threaded */
    uint64_t update_ns, pre_render_ns, record_ns, assemble_ns, submit_ns, frame_ns;
    double gpu_ms;
    /* ob_frame_stats_cpu_work_ns and ob_frame_stats_wait_ns: the engine's
     * CPU work apart from waiting for the GPU, an image and the present. */
    uint64_t cpu_work_ns, waiting_ns;
} ob_demo_frame_times;

/* What the run's frames left out, for the lean-scene report: each view
 * that some frame left out (ob_frame_stats.skipped, and views that ran with
 * nothing to draw), with the reason and the number of frames, and what the
 * run created. */
#define OB_DEMO_LEAN_VIEWS 16
typedef struct ob_demo_lean {
    struct { char name[48]; ob_skip_reason reason; uint32_t frames; } views[OB_DEMO_LEAN_VIEWS];
    uint32_t view_count, views_more;  /* views_more: distinct ones past the table */
    /* The views the last frame drew, in execution order: a shadow view's
     * name says its light (shadow:<light>, shadow:<light>:c<i> a cascade). */
    struct { char name[48]; ob_view_type type; uint32_t draws; } drawn[OB_DEMO_LEAN_VIEWS];
    uint32_t drawn_count, drawn_more;
    uint64_t pipelines_created, variants_created;
    /* The last frame's draws: entities drawn, draw commands, instances of
     * instanced draws, the longest run in one draw. */
    uint32_t draws, draw_calls, instances, longest_run, multi_draw_runs;
} ob_demo_lean;

typedef struct ob_demo {
    ob_demo_options opt;
    /* The stack under its short names (world.r, world.scene, world.camera,
     * ...; world.overlay is NULL unless --overlay or --window); owns
     * everything but the window and the systems. */
    ob_world world;
    ob_particle_system **systems;
    uint32_t system_count, system_cap;
    ob_demo_frame_times *history;  /* completed frames' times, in order */
    uint32_t history_count, history_cap;
    FILE *json;
    ob_window *window;        /* --window */
    bool flipped;             /* F1: the mode is the opposite of what the options say */
    ob_demo_lean lean;
    /* Input (ob_demo_set_input): the window's and --input's events go to
     * the runner's keys first (F1, S, W, O; Escape from a script stops the
     * run), then all of them to the program's listener. */
    ob_input_script *script;  /* --input, parsed; NULL without */
    ob_input_handler app_input;
    bool stop;                /* Escape from a script */
    bool screenshot_pending;
    uint32_t screenshots;     /* written so far (the next is numbered screenshots + 1) */
    bool wireframe;           /* W: the main view draws edges */
    uint32_t overlay_detail;  /* O: 0 = summary, 1 = phases and views */
    /* A program's extra overlay lines (detail level 1), e.g. the camera. */
    char overlay_extra[256];
} ob_demo;

/* The keys the runner handles, for a program's --help:
 *   F1 single/multi-threaded; S screenshot; W wireframe; O overlay detail;
 *   Escape quit. */
#define OB_DEMO_KEYS_HELP                                                                 \
    "keys of every demo (in the window, or from --input):\n"                               \
    "  F1                switch single/multi-threaded recording\n"                            \
    "  S                 screenshot: the next numbered PNG (--screenshot-prefix), path printed\n" \
    "  W                 wireframe on/off (needs the device feature fillModeNonSolid)\n"      \
    "  O                 overlay detail: summary, or phases, waits, views and camera\n"       \
    "  Escape            quit\n"

/* Sets the program's listener (copied; NULL: none): it gets every input
 * event after the runner's own keys have been handled. */
void ob_demo_set_input(ob_demo *d, const ob_input_handler *h);

/* The window (--window), then the stack: renderer (worker count from
 * --threads), effect context, material library, views, an empty scene with
 * a camera node (fovy 1, near 0.05), the main perspective view, the
 * composite (final target) and the overlay; then --stats-json is opened.
 * Failure: the failing step's result; ob_demo_shutdown is still due. */
ob_result ob_demo_init(ob_demo *d, const ob_demo_options *o);
/* Waits idle and destroys all (particle systems, window, stack), closes the
 * JSON stats. A zeroed d is fine. */
void ob_demo_shutdown(ob_demo *d);

/* Uploads a mesh (the caller keeps and releases it) as geometry the stack
 * owns. Failure: NULL, logged. */
ob_geometry *ob_demo_geometry(ob_demo *d, const ob_mesh *mesh, const char *name);
/* A node with geometry and material; local bounds from the geometry.
 * Failure: NULL, logged, nothing left in the scene. */
ob_node *ob_demo_entity(ob_demo *d, ob_node *parent, const char *name, ob_geometry *g,
                        ob_material *m);
/* A particle system under parent that the demo destroys at shutdown.
 * Failure: NULL, logged, and *out_result (may be NULL) says why — a shader
 * that cannot be read stays OB_ERR_IO up to the user's message, not
 * "out of memory". */
ob_particle_system *ob_demo_particles(ob_demo *d, ob_node *parent, const ob_particle_desc *desc,
                                      ob_result *out_result);

/* Frame callback: animate before the scene update. */
typedef void (*ob_demo_update_fn)(ob_demo *d, uint32_t frame, double time, void *user);

/* Runs opt.frames frames with fixed dt = 1/60 (so images do not depend on
 * wall time), switching modes per --threads / --toggle, printing a line per
 * frame and a summary, writing --stats-json and --out. Returns 0 on success. */
int ob_demo_run(ob_demo *d, ob_demo_update_fn update, void *user);

/* Prints the lean-scene report once to f: the views the frames left out and
 * why, the shader variants and pipelines created, whether the main view has
 * MSAA targets, and each material the scene draws with its main-view effect
 * (the PBR variant, e.g. "pbr:base+sh") and the PBR features that variant
 * leaves out (ob_material_pbr_left_out). ob_demo_run prints it after the
 * summary; call it after frames have run (variants exist then). */
void ob_demo_print_lean_report(ob_demo *d, FILE *f);

/* Medians of a phase over the recorded frames of one mode (NAN if none);
 * phase_offset is offsetof(ob_demo_frame_times, <phase>). */
double ob_demo_median_ms(const ob_demo *d, int mode_workers_filter, size_t phase_offset);


/* The process's memory: resident set and its peak (/proc/self/status, 0
 * where there is none), what the C heap holds live (glibc's mallinfo2, 0
 * elsewhere: the driver's and the validation layer's memory included) and
 * what of it Obelisk allocated (ob_heap_stats_now). */
typedef struct ob_demo_memory {
    unsigned long long rss_kb, peak_rss_kb, heap_in_use_kb, obelisk_heap_kb;
} ob_demo_memory;
ob_demo_memory ob_demo_memory_now(void);

/* Writes one frame's stats as a JSON object (with the memory figures when
 * mem is not NULL). */
void ob_demo_write_stats_json(FILE *f, const ob_frame_stats *st, const ob_demo_memory *mem);

#endif /* OB_DEMO_H */
