/* ob_stack.h — what a typical program sets up, created and destroyed in order:
 * renderer → effect context → material library → views → scene with a
 * camera node → main perspective view → composite (the final target) →
 * optional overlay; plus the geometry the program uploads through it.
 *
 * Everything is plain engine objects reachable through the struct's fields,
 * so a program that outgrows a default calls the module's own functions on
 * them. The fields are read-only to the program: the stack owns what they
 * point to.
 *
 * Lifecycle: ob_stack_create → [ob_stack_add_geometry, ob_stack_add_entity,
 * materials in s->materials, lights on nodes of s->scene; models, a sun,
 * scene files and the camera's framing through ob_stack_content.h] → frames
 * (ob_stack_frame, or ob_stack_frame_begin + the program's own PreRender
 * and end) → ob_stack_destroy. Views the program made itself on s->views (particle
 * systems, more perspective views) are destroyed by the program first.
 * Thread rule: [render thread] for every function (the renderer's rule).
 */
#ifndef OB_STACK_H
#define OB_STACK_H

#include "ob_views.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The default clear colour, in linear scene units: after the composite's
 * tone map (at the default exposure) and sRGB encode it shows as the dark
 * blue-grey (0.08, 0.09, 0.12) the stack cleared to before rendering was
 * linear. */
#define OB_STACK_CLEAR_R 0.0149f
#define OB_STACK_CLEAR_G 0.0166f
#define OB_STACK_CLEAR_B 0.0220f

typedef struct ob_stack_desc {
    ob_renderer_desc renderer;   /* zero → defaults (worker count = cores, headless) */
    const char *cache_dir;       /* pipeline cache folder; NULL → the effect context's default */
    uint32_t width, height;      /* main view and final target; 0 → 640 x 480 */
    float clear_color[4];        /* linear; all zero → opaque OB_STACK_CLEAR_R/G/B */
    ob_camera_desc camera;       /* zero → ob_node_set_camera's defaults */
    uint32_t env_map_size;       /* 0 → the views' default (256) */
    ob_env_map_kind env_map_kind;  /* 0 → OB_ENV_MAP_PARABOLOID */
    float sky_color[4];          /* linear; what env maps clear to; all zero → clear_color */
    uint32_t shadow_map_size;    /* 0 → the views' default (1024) */
    uint32_t shadow_cascades;    /* 0 → the views' default (4); 1..OB_SHADOW_MAX_CASCADES */
    float shadow_distance;       /* 0 → from what the camera sees (ob_views_desc) */
    float shadow_split_lambda;   /* 0 → the views' default (0.75); (0, 1] */
    float ambient[4];            /* rgb, w = intensity; zero → the views' default */
    bool overlay;                /* also an overlay view, drawn last over the composite */
    uint32_t msaa;               /* main view's samples per pixel: 0 or 1 → none; 2, 4, 8
                                    (lowered to what the device offers, logged) */
    float exposure;              /* the composite's exposure; 0 → OB_COMPOSITE_DEFAULT_EXPOSURE;
                                    negative or not finite: creation fails (logged) */
} ob_stack_desc;

typedef struct ob_stack {
    ob_renderer *renderer;
    ob_device *device;                /* the renderer's */
    ob_effect_context *effects;
    ob_material_library *materials;   /* owns the materials made from it */
    ob_views *views;
    ob_scene *scene;                  /* owns its nodes */
    ob_node *camera;                  /* a node of scene with a camera */
    ob_perspective_view *main;        /* sees the scene from camera */
    ob_composite_view *composite;     /* main's colour in the final target */
    ob_overlay_view *overlay;         /* NULL unless desc.overlay */
    ob_view *final_view;              /* overlay or composite: what ob_stack_frame renders */
    ob_geometry **geometry;           /* what ob_stack_add_geometry made */
    uint32_t geometry_count, geometry_cap;
    double time;                      /* seconds simulated by ob_stack_frame */
    uint64_t frames;                  /* frames ob_stack_frame started */
    /* What ob_stack_content.h loaded into the stack (models with their
     * textures, scene files); private, freed by ob_stack_destroy. */
    struct ob_stack_content *content;
} ob_stack;

/* Creates the whole stack. Failure: NULL, *out_result set (out_result may
 * be NULL), the cause logged by the step that failed, and everything
 * created so far destroyed. */
ob_stack *ob_stack_create(const ob_stack_desc *desc, ob_result *out_result);
/* Waits idle, then destroys in reverse order: the scene files loaded with
 * ob_stack_load_scene, overlay, composite, main view, scene (its nodes), the
 * models and textures of ob_stack_add_model, views, material library (its
 * materials), geometry, effect context, renderer. NULL is a no-op. */
void ob_stack_destroy(ob_stack *s);

/* Uploads mesh (the caller keeps and releases it) as geometry the stack
 * owns; the id for command hashes is its index + 1. Failure: NULL,
 * *out_result set, logged. */
ob_geometry *ob_stack_add_geometry(ob_stack *s, const ob_mesh *mesh, const char *name,
                                   ob_result *out_result);
/* The same from a full description (levels of detail, layout, topology);
 * desc->id 0 → its index + 1. */
ob_geometry *ob_stack_add_geometry_desc(ob_stack *s, const ob_geometry_desc *desc,
                                        ob_result *out_result);
/* A node of s->scene under parent (NULL → root) drawing geometry with
 * material, its bounds taken from the geometry. Failure: NULL, *out_result
 * set, nothing left in the scene. */
ob_node *ob_stack_add_entity(ob_stack *s, ob_node *parent, const char *name, ob_geometry *geometry,
                             ob_material *material, ob_result *out_result);

/* One frame: updates the scene (by dt; 0 on the first frame), sets the
 * views' time, begins the frame, runs the PreRender from s->final_view and
 * ends the frame (records and submits; it does not wait: ob_renderer_wait_idle
 * or a read-back such as ob_image_write_png does). s->time advances by dt
 * even when a step fails. Returns the first failure of those steps; when
 * they all succeed but the PreRender went on without something that failed
 * (a material's effect that does not compile, an env map that could not be
 * made: ob_frame_stats.errors), the frame is submitted and its first_error
 * is returned, so a degraded picture never comes with OB_OK. */
ob_result ob_stack_frame(ob_stack *s, double dt);

/* The first half of ob_stack_frame, for a program that acts between the
 * frame's start and its PreRender (overlay text, more views, a look at the
 * frame before it is recorded): updates the scene (by dt; 0 on the first
 * frame), sets the views' time and begins the frame. The program then runs
 * the PreRender (ob_views_render(s->views, s->final_view), and any other
 * view it queues) and ends the frame (ob_renderer_end_frame(s->renderer)).
 * s->time advances by dt even when a step fails. Failure: the update's or
 * begin_frame's result, and the frame is not begun (do not end it). */
ob_result ob_stack_frame_begin(ob_stack *s, double dt);

/* Resizes the main view and with it the final image, from the next frame
 * on (ob_view_resize). A zero side is refused: logged, false. */
bool ob_stack_resize(ob_stack *s, uint32_t width, uint32_t height);

/* The final image: the composite's target (the overlay draws into it too). */
ob_image ob_stack_final_image(const ob_stack *s);

#ifdef __cplusplus
}
#endif
#endif /* OB_STACK_H */
