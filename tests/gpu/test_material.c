/* test_material.c — materials per view type: render flags, sort info, lazy
 * variants, the env-map queue hook, apply, and drawing many entities that
 * share an effect through one pipeline manager. */
#define _XOPEN_SOURCE 700
#include "ob_test.h"

#include <stdio.h>
#include <string.h>

#include "ob_material.h"
#include "ob_params.h"
#include "ob_pipeline_manager.h"
#include "ob_renderer_layer.h"
#include "ob_resources.h"
#include "ob_scene.h"
#include "ob_view.h"

#define SIZE 64

typedef struct fixture {
    ob_device *dev;
    ob_param_registry *reg;
    ob_effect_context *ctx;
    ob_image color, depth, shadow_depth;
} fixture;

static ob_image make_image(ob_device *dev, VkFormat format, uint32_t usage, const char *name)
{
    ob_result r;
    ob_image img = ob_image_create(dev, &(ob_image_desc){
        .width = SIZE, .height = SIZE, .format = format, .usage = usage, .name = name}, &r);
    assert_int_not_equal(img.id, 0);
    return img;
}

static int setup(void **state)
{
    static fixture f;
    f.dev = ob_test_device_create();
    ob_result r;
    f.reg = ob_param_registry_create(&(ob_param_registry_desc){.slot_count = 2}, &r);
    assert_non_null(f.reg);
    f.color = make_image(f.dev, VK_FORMAT_R8G8B8A8_UNORM,
                         OB_IMAGE_COLOR_TARGET | OB_IMAGE_TRANSFER_SRC, "color");
    f.depth = make_image(f.dev, VK_FORMAT_D32_SFLOAT, OB_IMAGE_DEPTH_TARGET, "depth");
    f.shadow_depth = make_image(f.dev, VK_FORMAT_D32_SFLOAT,
                                OB_IMAGE_DEPTH_TARGET | OB_IMAGE_SAMPLED, "shadow");
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    ob_test_assert_no_validation(f->dev);
    ob_image_destroy(f->dev, f->color);
    ob_image_destroy(f->dev, f->depth);
    ob_image_destroy(f->dev, f->shadow_depth);
    ob_param_registry_destroy(f->reg);
    ob_device_destroy(f->dev);
    return 0;
}

/* Each test gets a fresh context (so variant counters start at zero). */
static ob_material_library *make_library(fixture *f)
{
    ob_result r;
    f->ctx = ob_effect_context_create(f->dev, f->reg, NULL, &r);
    assert_non_null(f->ctx);
    ob_material_library *lib = ob_material_library_create(f->ctx, NULL, &r);
    assert_non_null(lib);
    /* These tests draw through the pipeline manager one entity at a time:
     * the per-draw variants (test_instanced_variants covers the others). */
    ob_material_library_set_instancing(lib, false);
    return lib;
}

static void destroy_library(fixture *f, ob_material_library *lib)
{
    ob_material_library_destroy(lib);
    ob_effect_context_destroy(f->ctx);
    f->ctx = NULL;
}

static const ob_view_vtbl test_vtbl = {.type_name = "test"};

static void make_view(fixture *f, ob_view *v, ob_view_type type, const char *name)
{
    ob_view_init(v, &test_vtbl, type, name);
    v->width = v->height = SIZE;
    switch (type) {
    case OB_VIEW_SHADOW:
        v->depth = f->shadow_depth;
        break;
    case OB_VIEW_OVERLAY:
    case OB_VIEW_COMPOSITE:
        v->color = f->color;
        break;
    case OB_VIEW_SIMULATION:
        v->layer_count = 0;
        break;
    default:
        v->color = f->color;
        v->depth = f->depth;
        break;
    }
}

static ob_material *make_material(ob_material_library *lib, ob_material_kind kind, bool shadows,
                                  bool blended, uint32_t priority)
{
    ob_result r;
    ob_material *m = ob_material_create(lib, &(ob_material_desc){
        .name = "m", .kind = kind, .casts_shadows = shadows, .blended = blended,
        .priority = priority}, &r);
    assert_non_null(m);
    return m;
}

/* Hieroglyph's Params[type].bRender for the standard kinds. */
static void test_render_flags_per_view_type(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    static const struct {
        ob_material_kind kind;
        bool shadows;
        bool expect[OB_VIEW_TYPE_COUNT]; /* perspective, shadow, paraboloid, simulation,
                                            overlay, composite, cube */
    } cases[] = {
        {OB_MATERIAL_LIT, false, {true, false, true, false, false, false, true}},
        {OB_MATERIAL_LIT, true, {true, true, true, false, false, false, true}},
        {OB_MATERIAL_REFLECTIVE, false, {true, false, true, false, false, false, true}},
        {OB_MATERIAL_REFLECTIVE, true, {true, true, true, false, false, false, true}},
        {OB_MATERIAL_UNLIT, false, {true, false, false, false, true, false, false}},
        {OB_MATERIAL_CUSTOM, true, {false, false, false, false, false, false, false}},
    };
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        ob_material *m = make_material(lib, cases[i].kind, cases[i].shadows, false, 0);
        for (uint32_t t = 0; t < OB_VIEW_TYPE_COUNT; t++) {
            if (mi->renders(m, (ob_view_type)t) != cases[i].expect[t])
                fail_msg("kind %d (shadows %d): renders(%s) should be %d", cases[i].kind,
                         cases[i].shadows, ob_view_type_name((ob_view_type)t), cases[i].expect[t]);
            assert_int_equal(ob_material_get_view_params(m, (ob_view_type)t).render,
                             cases[i].expect[t]);
        }
        ob_material_destroy(m);
    }
    /* Nothing was compiled to answer these questions. */
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 0);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

/* A view type with no effect is not drawn: renders() false, apply() false,
 * no pipeline set; a custom effect makes it drawn. */
static void test_no_effect_not_drawn(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_result r;
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = f->dev, .registry = f->reg, .name = "test"}, &r);
    assert_non_null(pm);

    ob_view overlay;
    make_view(f, &overlay, OB_VIEW_OVERLAY, "overlay");
    ob_material *lit = make_material(lib, OB_MATERIAL_LIT, false, false, 0);
    assert_false(mi->renders(lit, OB_VIEW_OVERLAY));
    mi->pre_render(lit, NULL, NULL, &overlay);
    assert_false(mi->apply(lit, NULL, NULL, pm, &overlay));
    assert_null(ob_material_get_view_effect(lit, NULL, NULL, &overlay, true, &r));
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 0);

    ob_material *custom = make_material(lib, OB_MATERIAL_CUSTOM, false, false, 0);
    for (uint32_t t = 0; t < OB_VIEW_TYPE_COUNT; t++) assert_false(mi->renders(custom, t));
    ob_effect *text = ob_material_library_effect(lib, OB_STD_OVERLAY, 0, &r);
    assert_non_null(text);
    assert_int_equal(ob_material_set_view_effect(custom, OB_VIEW_OVERLAY, text), OB_OK);
    assert_true(mi->renders(custom, OB_VIEW_OVERLAY));
    assert_false(mi->renders(custom, OB_VIEW_PERSPECTIVE));
    assert_ptr_equal(ob_material_get_view_params(custom, OB_VIEW_OVERLAY).effect, text);
    mi->pre_render(custom, NULL, NULL, &overlay);
    assert_true(mi->apply(custom, NULL, NULL, pm, &overlay));
    assert_int_equal(ob_material_set_view_effect(custom, OB_VIEW_OVERLAY, NULL), OB_OK);
    assert_false(mi->renders(custom, OB_VIEW_OVERLAY));

    ob_pipeline_manager_destroy(pm);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

/* Opaque before blended; priority passed through; overlay items blend. */
static void test_sort_info(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_material *opaque = make_material(lib, OB_MATERIAL_LIT, false, false, 3);
    ob_material *glass = make_material(lib, OB_MATERIAL_LIT, false, true, 7);
    ob_material *hud = make_material(lib, OB_MATERIAL_UNLIT, false, false, 9);
    uint32_t cls, prio, group0, group;
    mi->sort_info(opaque, OB_VIEW_PERSPECTIVE, &cls, &prio, &group0);
    assert_int_equal(cls, 0);
    assert_int_equal(prio, 3);
    mi->sort_info(glass, OB_VIEW_PERSPECTIVE, &cls, &prio, &group);
    assert_int_not_equal(group, group0); /* two materials, two state groups */
    assert_int_equal(cls, 1);
    assert_int_equal(prio, 7);
    mi->sort_info(hud, OB_VIEW_PERSPECTIVE, &cls, &prio, &group);
    assert_int_equal(cls, 0);
    mi->sort_info(hud, OB_VIEW_OVERLAY, &cls, &prio, &group);
    assert_int_equal(cls, 1);
    assert_int_equal(prio, 9);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

/* Variants are compiled the first time a view needs them, once. */
static void test_variants_compiled_only_when_used(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_view persp, shadow, env;
    make_view(f, &persp, OB_VIEW_PERSPECTIVE, "camera");
    make_view(f, &shadow, OB_VIEW_SHADOW, "sun-shadow");
    make_view(f, &env, OB_VIEW_PARABOLOID, "env");

    ob_material *lit = make_material(lib, OB_MATERIAL_LIT, false, false, 0);
    ob_material *caster = make_material(lib, OB_MATERIAL_LIT, true, false, 0);
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 0);

    mi->pre_render(lit, NULL, NULL, &persp);
    ob_effect_counters c = ob_effect_context_counters(f->ctx);
    assert_int_equal(c.variants_compiled, 1);           /* lit */
    assert_int_equal(c.pipelines_created, 1);           /* ...for the camera's formats */
    mi->pre_render(caster, NULL, NULL, &persp);
    mi->pre_render(lit, NULL, NULL, &persp);
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 1);

    /* A non-caster is not in the shadow view; a caster needs depth-only. */
    assert_false(mi->renders(lit, OB_VIEW_SHADOW));
    mi->pre_render(caster, NULL, NULL, &shadow);
    c = ob_effect_context_counters(f->ctx);
    assert_int_equal(c.variants_compiled, 2);
    assert_non_null(ob_material_library_find_effect(lib, OB_STD_DEPTH, 0));
    assert_null(ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_SHADOWS));

    /* Once the camera depends on a shadow view this frame: SHADOWS variant. */
    ob_view_add_dependency(&persp, &shadow);
    mi->pre_render(lit, NULL, NULL, &persp);
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 3);
    assert_ptr_equal(ob_material_get_view_effect(lit, NULL, NULL, &persp, false, NULL),
                     ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_SHADOWS));

    /* Environment map views use the paraboloid generation effect. */
    mi->pre_render(lit, NULL, NULL, &env);
    assert_int_equal(ob_effect_context_counters(f->ctx).variants_compiled, 4);
    assert_non_null(ob_material_library_find_effect(lib, OB_STD_PARABOLOID, 0));

    /* Nothing here asked for an env-map lookup, unlit or particles. */
    assert_null(ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_ENVMAP));
    assert_null(ob_material_library_find_effect(lib, OB_STD_UNLIT, 0));
    assert_null(ob_material_library_find_effect(lib, OB_STD_PARTICLES_SIM, 0));
    ob_view_release(&persp);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

typedef struct hook_log {
    uint32_t calls;
    ob_node *entity;
    ob_view *requester;
    ob_view_type needed;
} hook_log;

static void record_hook(void *user, ob_node *entity, ob_renderer *r, ob_view *requesting,
                        ob_view_type needed)
{
    (void)r;
    hook_log *log = user;
    log->calls++;
    log->entity = entity;
    log->requester = requesting;
    log->needed = needed;
}

/* Reflective materials ask for their entity's environment map from
 * perspective views only; nothing else asks for anything. */
static void test_reflective_queues_env_map(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    hook_log log = {0};
    ob_material_library_set_queue_hook(lib, record_hook, &log);
    ob_view persp, env;
    make_view(f, &persp, OB_VIEW_PERSPECTIVE, "camera");
    make_view(f, &env, OB_VIEW_PARABOLOID, "env");
    ob_result r;
    ob_scene *scene = ob_scene_create(&r);
    assert_non_null(scene);
    ob_node *ball = ob_node_create(scene, NULL, "mirror-ball", &r);
    assert_non_null(ball);

    ob_material *mirror = make_material(lib, OB_MATERIAL_REFLECTIVE, false, false, 0);
    ob_material *plain = make_material(lib, OB_MATERIAL_LIT, false, false, 0);
    mi->pre_render(plain, ball, NULL, &persp);
    assert_int_equal(log.calls, 0);
    mi->pre_render(mirror, ball, NULL, &persp);
    assert_int_equal(log.calls, 1);
    assert_ptr_equal(log.entity, ball);
    assert_ptr_equal(log.requester, &persp);
    assert_int_equal(log.needed, OB_VIEW_PARABOLOID);
    mi->pre_render(mirror, ball, NULL, &env);   /* drawn in others' maps, asks nothing */
    assert_int_equal(log.calls, 1);
    /* With no map attached the mirror falls back to plain lit shading. */
    assert_ptr_equal(ob_material_get_view_effect(mirror, NULL, ball, &persp, false, NULL),
                     ob_material_library_find_effect(lib, OB_STD_LIT, 0));
    ob_scene_destroy(scene);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

/* apply() sets the pipeline for the view's formats and the material's own
 * parameters in the manager's slot; a variant that appears only after
 * PreRender falls back to an existing one until prepare_view builds it. */
static void test_apply_and_prepare_view(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_result r;
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = f->dev, .registry = f->reg, .slot = 1, .name = "worker"}, &r);
    assert_non_null(pm);
    ob_view persp, shadow;
    make_view(f, &persp, OB_VIEW_PERSPECTIVE, "camera");
    make_view(f, &shadow, OB_VIEW_SHADOW, "shadow");

    ob_material *red = ob_material_create(lib, &(ob_material_desc){
        .name = "red", .diffuse = {1, 0, 0, 1}, .emissive = {0.1f, 0, 0, 0}}, &r);
    ob_material *blue = ob_material_create(lib, &(ob_material_desc){
        .name = "blue", .diffuse = {0, 0, 1, 1}}, &r);
    assert_non_null(red);
    assert_non_null(blue);

    /* Recording without PreRender: skipped, with one warning. */
    ob_test_log_clear();
    assert_false(mi->apply(red, NULL, NULL, pm, &persp));
    assert_false(mi->apply(red, NULL, NULL, pm, &persp));
    assert_true(ob_test_log_has("material 'red'", "camera", NULL));
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 1);

    mi->pre_render(red, NULL, NULL, &persp);
    assert_true(mi->apply(red, NULL, NULL, pm, &persp));
    /* LIT draws with the metallic-roughness model: apply writes its mapped
     * factors (ob_material_desc_to_pbr) into the PbrMaterial block. */
    ob_params *params = ob_pipeline_manager_params(pm);
    const ob_param base_color = ob_param_find(f->reg, "PbrBaseColor");
    float got[4];
    assert_int_equal(ob_params_get_vec4(params, base_color, got), OB_OK);
    const ob_material_pbr red_pbr = ob_material_desc_to_pbr(&(ob_material_desc){
        .diffuse = {1, 0, 0, 1}, .emissive = {0.1f, 0, 0, 0}}).pbr;
    for (int k = 0; k < 4; k++) assert_float_equal(got[k], red_pbr.base_color[k], 1e-6f);
    assert_true(got[0] == 1 && got[1] < 0.01f && got[2] < 0.01f && got[3] == 1);
    assert_int_equal(ob_params_get_vec4(params, ob_param_find(f->reg, "PbrEmissive"), got), OB_OK);
    assert_true(got[0] == 0.1f);
    assert_true(mi->apply(blue, NULL, NULL, pm, &persp));   /* same effect, other colours */
    assert_int_equal(ob_params_get_vec4(params, base_color, got), OB_OK);
    assert_true(got[2] == 1 && got[0] < 0.01f);
    /* Only slot 1 was written: the immediate slot does not hold blue. */
    ob_params immediate;
    assert_int_equal(ob_params_manager(f->reg, 0, &immediate), OB_OK);
    ob_params_get_vec4(&immediate, base_color, got);
    assert_false(got[2] == 1 && got[0] < 0.01f);

    /* A shadow view queued after the entities' PreRender: the camera now
     * wants lit+SHADOWS, which does not exist yet, so apply uses lit. */
    ob_view_add_dependency(&persp, &shadow);
    assert_true(mi->apply(red, NULL, NULL, pm, &persp));
    assert_ptr_equal(ob_material_get_view_effect(red, NULL, NULL, &persp, false, NULL),
                     ob_material_library_find_effect(lib, OB_STD_LIT, 0));
    /* prepare_view builds what the draw list needs. */
    ob_scene *scene = ob_scene_create(&r);
    ob_node *n = ob_node_create(scene, NULL, "box", &r);
    assert_int_equal(ob_node_set_renderable(n, &(ob_renderable){.material = red,
                                                                 .local_radius = 1}), OB_OK);
    ob_draw_item item = {.node = n};
    persp.items = &item;
    persp.item_count = 1;
    ob_material_library_prepare_view(lib, NULL, &persp);
    persp.items = NULL;
    persp.item_count = 0;
    ob_effect *shadowed = ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_SHADOWS);
    assert_non_null(shadowed);
    assert_int_equal(ob_effect_pipeline_count(shadowed), 1);
    assert_ptr_equal(ob_material_get_view_effect(red, NULL, NULL, &persp, false, NULL), shadowed);

    ob_scene_destroy(scene);
    ob_pipeline_manager_destroy(pm);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

static void barrier_to(fixture *f, VkCommandBuffer cmd, ob_image img, VkImageLayout layout,
                       VkPipelineStageFlags2 stages, VkAccessFlags2 access)
{
    VkImageMemoryBarrier2 b;
    ob_image_state next = {layout, stages, access};
    if (!ob_image_transition(f->dev, img, &next, &b)) return;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                            .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
    vkCmdPipelineBarrier2(cmd, &dep);
}

/* The fixture's colour and depth targets cleared and rendered to by cmd
 * (dynamic rendering, SIZE x SIZE), through pm, as the draw tests below
 * need. */
static void begin_target(fixture *f, VkCommandBuffer cmd, ob_pipeline_manager *pm)
{
    barrier_to(f, cmd, f->color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    barrier_to(f, cmd, f->depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                   VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
               VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                   VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    VkRenderingAttachmentInfo color_att = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(f->dev, f->color),
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR, .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.color.float32 = {0, 0, 0, 1},
    };
    VkRenderingAttachmentInfo depth_att = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(f->dev, f->depth),
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR, .storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
        .clearValue.depthStencil = {0.0f, 0},
    };
    VkRenderingInfo ri = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                          .renderArea = {{0, 0}, {SIZE, SIZE}}, .layerCount = 1,
                          .colorAttachmentCount = 1, .pColorAttachments = &color_att,
                          .pDepthAttachment = &depth_att};
    vkCmdBeginRendering(cmd, &ri);
    ob_pipeline_manager_begin_frame(pm, 0, 1);
    ob_pipeline_manager_begin(pm, cmd);
    ob_pipeline_manager_set_viewport(pm, 0, 0, SIZE, SIZE);
    ob_pipeline_manager_set_scissor(pm, 0, 0, SIZE, SIZE);
}

/* 100 entities sharing one material draw through one pipeline manager with
 * a single pipeline bind, and the emissive colour reaches the image. */
static void test_hundred_entities_one_pipeline(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_result r;
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = f->dev, .registry = f->reg, .slot = 0, .name = "immediate"}, &r);
    assert_non_null(pm);
    ob_view persp;
    make_view(f, &persp, OB_VIEW_PERSPECTIVE, "camera");
    ob_material *green = ob_material_create(lib, &(ob_material_desc){
        .name = "green", .diffuse = {0, 0, 0, 1}, .specular = {0, 0, 0, 1},
        .emissive = {0, 1, 0, 0}}, &r);
    assert_non_null(green);
    mi->pre_render(green, NULL, NULL, &persp);

    /* One small triangle (standard layout) in clip space: ViewProj is identity.
     * Counter-clockwise as seen on screen (clip y points down). */
    const float tri[3][8] = {{-0.05f, -0.05f, 0.5f, 0, 0, 1, 0, 0},
                             {0.0f, 0.05f, 0.5f, 0, 0, 1, 0.5f, 1},
                             {0.05f, -0.05f, 0.5f, 0, 0, 1, 1, 0}};
    ob_buffer vb = ob_buffer_create(f->dev, &(ob_buffer_desc){
        .size = sizeof tri, .usage = OB_BUFFER_VERTEX, .data = tri, .name = "triangle"}, &r);
    assert_int_not_equal(vb.id, 0);

    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(f->dev, &cmd), OB_OK);
    begin_target(f, cmd, pm);
    ob_params *params = ob_pipeline_manager_params(pm);
    ob_param world = ob_param_registry_builtins(f->reg)->world;
    for (int i = 0; i < 100; i++) {
        /* A 10 x 10 grid of triangles across the target. */
        float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,
                       -0.9f + 0.2f * (float)(i % 10), -0.9f + 0.2f * (float)(i / 10), 0, 1};
        assert_int_equal(ob_params_set_mat4(params, world, m), OB_OK);
        assert_true(mi->apply(green, NULL, NULL, pm, &persp));
        ob_pipeline_manager_set_vertex_buffer(pm, vb, 0);
        assert_int_equal(ob_pipeline_manager_draw(pm, 3, 1, 0, 0), OB_OK);
    }
    ob_cmd_hash h = ob_pipeline_manager_end(pm);
    vkCmdEndRendering(cmd);
    assert_int_equal(ob_device_oneshot_submit(f->dev, cmd), OB_OK);

    ob_pipeline_manager_stats s = ob_pipeline_manager_stats_take(pm);
    assert_int_equal(h.draws, 100);
    assert_int_equal(s.draws, 100);
    assert_int_equal(s.pipeline_binds_requested, 100);
    assert_int_equal(s.pipeline_binds_issued, 1);
    assert_int_equal(ob_effect_context_counters(f->ctx).pipelines_created, 1);

    uint8_t pixels[SIZE * SIZE * 4];
    assert_int_equal(ob_image_read_rgba8(f->dev, f->color, pixels), OB_OK);
    /* Triangle 0 sits around clip (-0.9, -0.9): pixel (3, 3) at 64 x 64. */
    const uint8_t *p = &pixels[(3 * SIZE + 3) * 4];
    assert_int_equal(p[0], 0);
    assert_int_equal(p[1], 255);
    assert_int_equal(p[2], 0);
    /* Between triangles: the clear colour. */
    p = &pixels[(6 * SIZE + 6) * 4];
    assert_int_equal(p[1], 0);

    ob_buffer_destroy(f->dev, vb);
    ob_pipeline_manager_destroy(pm);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

/* One grid of 100 triangles recorded in `way`: 0 by draw data (indexed),
 * 1 by indexed indirect draws, 2 by non-indexed indirect draws, each
 * triangle's world matrix set as the parameter. Returns the image. */
static void draw_grid(fixture *f, ob_material *green, ob_view *persp, int way, uint8_t *pixels,
                      ob_cmd_hash *out_hash)
{
    const ob_material_iface *mi = ob_material_iface_get();
    ob_result r;
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = f->dev, .registry = f->reg, .slot = 0, .name = "immediate"}, &r);
    assert_non_null(pm);
    const float tri[3][8] = {{-0.05f, -0.05f, 0.5f, 0, 0, 1, 0, 0},
                             {0.0f, 0.05f, 0.5f, 0, 0, 1, 0.5f, 1},
                             {0.05f, -0.05f, 0.5f, 0, 0, 1, 1, 0}};
    const uint32_t indices[3] = {0, 1, 2};
    const VkDrawIndexedIndirectCommand indexed_args = {3, 1, 0, 0, 0};
    const VkDrawIndirectCommand plain_args = {3, 1, 0, 0};
    ob_buffer vb = ob_buffer_create(f->dev, &(ob_buffer_desc){
        .size = sizeof tri, .usage = OB_BUFFER_VERTEX, .data = tri, .name = "triangle"}, &r);
    ob_buffer ib = ob_buffer_create(f->dev, &(ob_buffer_desc){
        .size = sizeof indices, .usage = OB_BUFFER_INDEX, .data = indices, .name = "indices"}, &r);
    ob_buffer args = way == 1
        ? ob_buffer_create(f->dev, &(ob_buffer_desc){.size = sizeof indexed_args,
              .usage = OB_BUFFER_INDIRECT, .data = &indexed_args, .name = "indexed args"}, &r)
        : ob_buffer_create(f->dev, &(ob_buffer_desc){.size = sizeof plain_args,
              .usage = OB_BUFFER_INDIRECT, .data = &plain_args, .name = "args"}, &r);
    assert_int_not_equal(vb.id, 0);
    assert_int_not_equal(ib.id, 0);
    assert_int_not_equal(args.id, 0);

    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(f->dev, &cmd), OB_OK);
    begin_target(f, cmd, pm);
    ob_params *params = ob_pipeline_manager_params(pm);
    ob_param world = ob_param_registry_builtins(f->reg)->world;
    const ob_draw_data dd = {.vertex_buffer = vb, .index_buffer = ib,
                             .index_type = VK_INDEX_TYPE_UINT32, .count = 3, .instance_count = 1};
    for (int i = 0; i < 100; i++) {
        float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,
                       -0.9f + 0.2f * (float)(i % 10), -0.9f + 0.2f * (float)(i / 10), 0, 1};
        assert_int_equal(ob_params_set_mat4(params, world, m), OB_OK);
        assert_true(mi->apply(green, NULL, NULL, pm, persp));
        if (way == 0) {
            assert_int_equal(ob_pipeline_manager_draw_data(pm, &dd, NULL), OB_OK);
            continue;
        }
        ob_pipeline_manager_set_vertex_buffer(pm, vb, 0);
        if (way == 1) {
            ob_pipeline_manager_set_index_buffer(pm, ib, 0, VK_INDEX_TYPE_UINT32);
            assert_int_equal(ob_pipeline_manager_draw_indexed_indirect(pm, args, 0, 1), OB_OK);
        } else {
            assert_int_equal(ob_pipeline_manager_draw_indirect(pm, args, 0, 1), OB_OK);
        }
    }
    /* A stale argument buffer is refused, and nothing is recorded. */
    ob_buffer stale = args;
    stale.id ^= 0x5a5a0000u;
    assert_int_equal(ob_pipeline_manager_draw_indexed_indirect(pm, stale, 0, 1),
                     OB_ERR_INVALID_HANDLE);
    *out_hash = ob_pipeline_manager_end(pm);
    vkCmdEndRendering(cmd);
    assert_int_equal(ob_device_oneshot_submit(f->dev, cmd), OB_OK);
    ob_pipeline_manager_stats st = ob_pipeline_manager_stats_take(pm);
    assert_int_equal(st.draws, 100);
    assert_int_equal(st.skipped_draws, 1);
    assert_int_equal(ob_image_read_rgba8(f->dev, f->color, pixels), OB_OK);
    ob_buffer_destroy(f->dev, args);
    ob_buffer_destroy(f->dev, ib);
    ob_buffer_destroy(f->dev, vb);
    ob_pipeline_manager_destroy(pm);
}

/* The draw-data path and both indirect draws (the arguments read by the
 * device from a buffer) draw the same image; their command hashes tell the
 * three apart. */
static void test_indirect_draws_match_direct_ones(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    const ob_material_iface *mi = ob_material_iface_get();
    ob_result r;
    ob_view persp;
    make_view(f, &persp, OB_VIEW_PERSPECTIVE, "camera");
    ob_material *green = ob_material_create(lib, &(ob_material_desc){
        .name = "green", .diffuse = {0, 0, 0, 1}, .specular = {0, 0, 0, 1},
        .emissive = {0, 1, 0, 0}}, &r);
    assert_non_null(green);
    mi->pre_render(green, NULL, NULL, &persp);
    static uint8_t pixels[3][SIZE * SIZE * 4];
    ob_cmd_hash hash[3];
    for (int way = 0; way < 3; way++) draw_grid(f, green, &persp, way, pixels[way], &hash[way]);
    /* Triangle 0 around clip (-0.9, -0.9): pixel (3, 3) at 64 x 64. */
    const uint8_t *p = &pixels[0][(3 * SIZE + 3) * 4];
    assert_int_equal(p[1], 255);
    assert_memory_equal(pixels[0], pixels[1], sizeof pixels[0]);
    assert_memory_equal(pixels[0], pixels[2], sizeof pixels[0]);
    assert_int_equal(hash[0].draws, 100);
    assert_int_equal(hash[1].draws, 100);
    assert_true(hash[0].hash != hash[1].hash && hash[1].hash != hash[2].hash);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

typedef struct usage_log {
    ob_view base;                 /* first: the renderer sees an ob_view */
    uint32_t calls;
    const ob_view *consumer;
} usage_log;

static void record_usage(ob_view *v, ob_renderer *r, ob_params *params, const ob_view *consumer)
{
    (void)r, (void)params;
    usage_log *u = (usage_log *)v;
    u->calls++;
    u->consumer = consumer;
}

static const ob_view_vtbl env_vtbl = {.type_name = "test-env", .set_usage_params = record_usage};

/* With an environment map attached to its entity (as the views layer does in
 * the queue hook), a reflective material draws with the ENVMAP lookup
 * variant and binds that entity's map per draw; other materials do not. */
static void test_reflective_uses_attached_env_map(void **state)
{
    fixture *f = *state;
    ob_result r;
    ob_renderer *rd = ob_renderer_create(&(ob_renderer_desc){
        .device = {.app_name = "test-material", .validation = 1}, .worker_count = 1}, &r);
    assert_non_null(rd);
    ob_device *dev = ob_renderer_device(rd);
    ob_effect_context *ctx = ob_effect_context_create(dev, ob_renderer_registry(rd), NULL, &r);
    assert_non_null(ctx);
    ob_material_library *lib = ob_material_library_create(ctx, NULL, &r);
    assert_non_null(lib);
    ob_material_library_set_instancing(lib, false); /* the variants below are per-draw */
    const ob_material_iface *mi = ob_material_iface_get();
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = dev, .registry = ob_renderer_registry(rd), .name = "test"}, &r);
    assert_non_null(pm);

    ob_view persp;
    ob_view_init(&persp, &test_vtbl, OB_VIEW_PERSPECTIVE, "camera");
    persp.color = make_image(dev, VK_FORMAT_R8G8B8A8_UNORM, OB_IMAGE_COLOR_TARGET, "color");
    persp.depth = make_image(dev, VK_FORMAT_D32_SFLOAT, OB_IMAGE_DEPTH_TARGET, "depth");
    usage_log env = {0};
    ob_view_init(&env.base, &env_vtbl, OB_VIEW_PARABOLOID, "envmap:mirror");

    ob_scene *scene = ob_scene_create(&r);
    ob_node *ball = ob_node_create(scene, NULL, "mirror", &r);
    ob_node *cube = ob_node_create(scene, NULL, "cube", &r);
    ob_material *mirror = make_material(lib, OB_MATERIAL_REFLECTIVE, false, false, 0);
    ob_material *plain = make_material(lib, OB_MATERIAL_LIT, false, false, 0);

    mi->pre_render(mirror, ball, rd, &persp);   /* nothing attached: plain lit */
    assert_ptr_equal(ob_material_get_view_effect(mirror, rd, ball, &persp, false, NULL),
                     ob_material_library_find_effect(lib, OB_STD_LIT, 0));
    assert_null(ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_ENVMAP));

    assert_int_equal(ob_renderer_attach_view(rd, ball, &env.base), OB_OK);
    mi->pre_render(mirror, ball, rd, &persp);
    ob_effect *lookup = ob_material_library_find_effect(lib, OB_STD_LIT, OB_VARIANT_ENVMAP);
    assert_non_null(lookup);
    assert_ptr_equal(ob_material_get_view_effect(mirror, rd, ball, &persp, false, NULL), lookup);
    assert_true(mi->apply(mirror, ball, rd, pm, &persp));
    assert_int_equal(env.calls, 1);
    assert_ptr_equal(env.consumer, &persp);
    /* The REFLECTIVE default mix 0.6 is in the mapped F0 (mostly metal);
     * the map's term is then weighted by the model's Fresnel alone. */
    float got[4];
    ob_params *mp = ob_pipeline_manager_params(pm);
    ob_params_get_vec4(mp, ob_param_find(ob_renderer_registry(rd), "Reflectivity"), got);
    assert_true(got[0] == 1.0f);
    ob_params_get_vec4(mp, ob_param_find(ob_renderer_registry(rd), "PbrFactors"), got);
    const ob_material_pbr mapped =
        ob_material_desc_to_pbr(&(ob_material_desc){.kind = OB_MATERIAL_REFLECTIVE}).pbr;
    assert_float_equal(got[0], mapped.metallic, 1e-6f);
    assert_true(got[0] > 0.5f && got[1] == 0.0f);   /* a mirror: roughness 0 */

    /* Another entity with the same reflective material has no map: plain lit. */
    assert_true(mi->apply(mirror, cube, rd, pm, &persp));
    assert_int_equal(env.calls, 1);
    /* A lit material on the entity that owns the map ignores it. */
    mi->pre_render(plain, ball, rd, &persp);
    assert_true(mi->apply(plain, ball, rd, pm, &persp));
    assert_int_equal(env.calls, 1);

    ob_scene_destroy(scene);
    ob_pipeline_manager_destroy(pm);
    ob_material_library_destroy(lib);
    ob_effect_context_destroy(ctx);
    ob_image_destroy(dev, persp.color);
    ob_image_destroy(dev, persp.depth);
    ob_test_assert_no_validation(dev);
    ob_renderer_destroy(rd);
    ob_test_assert_no_validation(f->dev);
}

/* Every name of the standard shaders' interface can be looked up as soon as
 * the library exists, with the type the shaders declare. */
static void test_library_registers_standard_interface(void **state)
{
    fixture *f = *state;
    ob_material_library *lib = make_library(f);
    static const struct {
        const char *name;
        ob_param_type type;
    } expect[] = {
        {"DiffuseColor", OB_PARAM_VEC4},  {"Reflectivity", OB_PARAM_VEC4},
        {"LightTable", OB_PARAM_BYTES}, {"ParaboloidDirection", OB_PARAM_VEC4},
        {"ShadowMatrices", OB_PARAM_MAT4_ARRAY}, {"ShadowSplits", OB_PARAM_VEC4},
        {"ShadowCascades", OB_PARAM_VEC4}, {"ShadowAxis", OB_PARAM_VEC4},
        {"EnvMapMatrix", OB_PARAM_MAT4},
        {"ShadowMap", OB_PARAM_TEXTURE},  {"EnvMapSampler", OB_PARAM_SAMPLER},
        {"Particles", OB_PARAM_STORAGE_BUFFER}, {"SimStep", OB_PARAM_VEC4},
    };
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(expect); i++) {
        ob_param p = ob_param_find(f->reg, expect[i].name);
        if (!p.id) fail_msg("parameter '%s' not registered", expect[i].name);
        assert_int_equal(ob_param_get_type(f->reg, p), expect[i].type);
    }
    /* The shadow sampler default compares (reversed-Z) in every slot. */
    ob_params worker;
    assert_int_equal(ob_params_manager(f->reg, 1, &worker), OB_OK);
    ob_sampler s = {0};
    assert_int_equal(ob_params_get_sampler(&worker, ob_param_find(f->reg, "ShadowMapSampler"), &s),
                     OB_OK);
    assert_int_not_equal(s.id, 0);
    destroy_library(f, lib);
    ob_test_assert_no_validation(f->dev);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_flags_per_view_type),
        cmocka_unit_test(test_no_effect_not_drawn),
        cmocka_unit_test(test_sort_info),
        cmocka_unit_test(test_variants_compiled_only_when_used),
        cmocka_unit_test(test_reflective_queues_env_map),
        cmocka_unit_test(test_apply_and_prepare_view),
        cmocka_unit_test(test_hundred_entities_one_pipeline),
        cmocka_unit_test(test_indirect_draws_match_direct_ones),
        cmocka_unit_test(test_reflective_uses_attached_env_map),
        cmocka_unit_test(test_library_registers_standard_interface),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
