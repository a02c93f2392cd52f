#include "ob_stack.h"

#include <string.h>

#include "ob_scene_layer_internal.h"

ob_stack *ob_stack_create(const ob_stack_desc *desc, ob_result *out_result)
{
    ob_stack_desc d = desc ? *desc : (ob_stack_desc){0};
    ob_result r = OB_ERR_OUT_OF_HOST_MEMORY;
    ob_stack *s = ob_calloc(1, sizeof *s);
    if (!s) {
        OB_LOG_E("stack", "no memory for the stack");
        goto fail_report;
    }

    if (!(s->renderer = ob_renderer_create(&d.renderer, &r))) goto fail_destroy_stack;
    s->device = ob_renderer_device(s->renderer);
    s->effects = ob_effect_context_create(s->device, ob_renderer_registry(s->renderer),
                                          d.cache_dir, &r);
    if (!s->effects) goto fail_destroy_stack;
    if (!(s->materials = ob_material_library_create(s->effects, NULL, &r))) goto fail_destroy_stack;
    ob_views_desc vd = {.renderer = s->renderer, .materials = s->materials,
                        .effects = s->effects, .env_map_size = d.env_map_size,
                        .shadow_map_size = d.shadow_map_size,
                        .shadow_cascades = d.shadow_cascades,
                        .shadow_distance = d.shadow_distance,
                        .shadow_split_lambda = d.shadow_split_lambda};
    memcpy(vd.ambient, d.ambient, sizeof vd.ambient);
    vd.env_map_kind = d.env_map_kind;
    if (!(s->views = ob_views_create(&vd, &r))) goto fail_destroy_stack;

    if (!(s->scene = ob_scene_create(&r))) goto fail_destroy_stack;
    if (!(s->camera = ob_node_create(s->scene, NULL, "camera", &r))) goto fail_destroy_stack;
    if ((r = ob_node_set_camera(s->camera, &d.camera)) != OB_OK) goto fail_destroy_stack;
    ob_perspective_desc pd = {.name = "main", .camera = s->camera,
                              .width = d.width ? d.width : 640,
                              .height = d.height ? d.height : 480,
                              .clear_color = {OB_STACK_CLEAR_R, OB_STACK_CLEAR_G,
                                              OB_STACK_CLEAR_B, 1.0f},
                              .samples = d.msaa};
    static const float no_color[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    if (memcmp(d.clear_color, no_color, sizeof no_color) != 0)
        memcpy(pd.clear_color, d.clear_color, sizeof pd.clear_color);
    if (!(s->main = ob_perspective_view_create(s->views, &pd, &r))) goto fail_destroy_stack;
    /* Reflections show the scene's sky: the main view's clear colour unless
     * the description names another. */
    float sky[4];
    memcpy(sky, memcmp(d.sky_color, no_color, sizeof no_color) != 0 ? d.sky_color : pd.clear_color,
           sizeof sky);
    sky[3] = 1.0f;
    ob_views_set_sky_color(s->views, sky);
    s->composite = ob_composite_view_create(s->views, ob_perspective_view_base(s->main), &r);
    if (!s->composite) goto fail_destroy_stack;
    if (d.exposure != 0.0f && !ob_composite_view_set_exposure(s->composite, d.exposure)) {
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_destroy_stack;
    }
    s->final_view = ob_composite_view_base(s->composite);
    if (d.overlay) {
        if (!(s->overlay = ob_overlay_view_create(s->views, s->final_view, &r))) goto fail_destroy_stack;
        s->final_view = ob_overlay_view_base(s->overlay);
    }
    if (out_result) *out_result = OB_OK;
    return s;

fail_destroy_stack:
    ob_stack_destroy(s);
fail_report:
    if (out_result) *out_result = r;
    return NULL;
}

void ob_stack_destroy(ob_stack *s)
{
    if (!s) return;
    if (s->renderer) ob_renderer_wait_idle(s->renderer);
    ob_stack_content_unload_scenes(s);
    if (s->views) {
        ob_overlay_view_destroy(s->views, s->overlay);
        ob_composite_view_destroy(s->views, s->composite);
        ob_perspective_view_destroy(s->views, s->main);
    }
    ob_scene_destroy(s->scene);
    ob_stack_content_destroy(s);   /* the models' materials and geometry, once no entity draws them */
    ob_views_destroy(s->views);
    ob_material_library_destroy(s->materials);
    for (uint32_t i = 0; i < s->geometry_count; i++) ob_geometry_destroy(s->device, s->geometry[i]);
    ob_free(s->geometry);
    ob_effect_context_destroy(s->effects);
    ob_renderer_destroy(s->renderer);
    ob_free(s);
}

ob_geometry *ob_stack_add_geometry_desc(ob_stack *s, const ob_geometry_desc *desc,
                                        ob_result *out_result)
{
    const char *name = desc && desc->name ? desc->name : "";
    ob_result r = desc ? ob_array_reserve((void **)&s->geometry, &s->geometry_cap,
                                          s->geometry_count + 1, sizeof *s->geometry)
                       : OB_ERR_INVALID_ARGUMENT;
    ob_geometry *g = NULL;
    if (r != OB_OK) OB_LOG_E("stack", "geometry '%s': %s", name,
                             desc ? "no memory to keep it" : "no description");
    if (r == OB_OK) {
        ob_geometry_desc gd = *desc;
        if (!gd.id) gd.id = s->geometry_count + 1;
        g = ob_geometry_create(s->device, &gd, &r);
        if (g) s->geometry[s->geometry_count++] = g;
    }
    if (out_result) *out_result = r;
    return g;
}

ob_geometry *ob_stack_add_geometry(ob_stack *s, const ob_mesh *mesh, const char *name,
                                   ob_result *out_result)
{
    return ob_stack_add_geometry_desc(s, &(ob_geometry_desc){.mesh = mesh, .name = name},
                                      out_result);
}

ob_node *ob_stack_add_entity(ob_stack *s, ob_node *parent, const char *name, ob_geometry *geometry,
                             ob_material *material, ob_result *out_result)
{
    ob_result r = OB_ERR_INVALID_ARGUMENT;
    ob_node *n = NULL;
    const ob_bounds *b = ob_geometry_bounds(geometry);
    if (!b) {
        OB_LOG_E("stack", "entity '%s': no geometry", name ? name : "");
        goto done;
    }
    if (!(n = ob_node_create(s->scene, parent, name, &r))) goto done;
    ob_renderable rd = {.material = material, .geometry = geometry, .local_radius = b->radius};
    memcpy(rd.local_center, b->center, sizeof rd.local_center);
    if ((r = ob_node_set_renderable(n, &rd)) != OB_OK) {
        ob_node_destroy(n);
        n = NULL;
    }
done:
    if (out_result) *out_result = r;
    return n;
}

ob_result ob_stack_frame_begin(ob_stack *s, double dt)
{
    double time = s->time;
    bool first = s->frames++ == 0;
    s->time += dt;
    /* On the worker pool as the mode set for this frame says; the update's
     * time and CPU time go to this frame's stats. */
    ob_result r = ob_renderer_update_scene(s->renderer, s->scene, first ? 0.0 : dt);
    if (r != OB_OK) return r;
    ob_views_set_time(s->views, time, dt);
    return ob_renderer_begin_frame(s->renderer, s->scene);
}

ob_result ob_stack_frame(ob_stack *s, double dt)
{
    ob_result r = ob_stack_frame_begin(s, dt);
    if (r != OB_OK) return r;
    ob_result degraded = ob_views_render(s->views, s->final_view);
    r = ob_renderer_end_frame(s->renderer);
    return r != OB_OK ? r : degraded;
}

ob_image ob_stack_final_image(const ob_stack *s)
{
    return s ? ob_composite_view_target(s->composite) : (ob_image){0};
}

bool ob_stack_resize(ob_stack *s, uint32_t width, uint32_t height)
{
    return ob_view_resize(ob_perspective_view_base(s->main), width, height);
}
