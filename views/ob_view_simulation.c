#include "ob_views_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A particle system: a compute-only simulation view that steps particles in a
 * storage buffer, and an emitter entity whose CUSTOM material draws them as
 * camera-facing quads pulled from the same buffer (6 vertices, one instance
 * per particle). The perspective view queues the simulation when the emitter
 * is visible, so the step always runs before the draw that reads it. */

typedef struct particle { float position[4], velocity[4]; } particle;

typedef struct sim_view {
    ob_view base;
    ob_particle_system *ps;
} sim_view;

struct ob_particle_system {
    ob_views *ctx;
    sim_view sim;
    ob_node *node;
    ob_buffer buffer;
    ob_geometry *quads;
    ob_material *material;
    ob_scene *scene;
    ob_particle_desc desc;
    ob_param particles, step, emitter, force;
};

static void sim_pre_render(ob_view *v, ob_renderer *r)
{
    if (!ob_renderer_queue_view(r, v)) return;
    sim_view *sv = (sim_view *)v;
    ob_views *ctx = sv->ps->ctx;
    ob_views_prepare_effect(ctx, r, ob_material_library_find_effect(ctx->materials,
                                                                    OB_STD_PARTICLES_SIM, 0), v);
}

static void sim_params(ob_particle_system *ps, ob_params *params)
{
    const ob_particle_desc *d = &ps->desc;
    float step[4] = {(float)ps->ctx->dt, (float)fmod(ps->ctx->time, 4096.0), (float)d->count, d->size};
    float emitter[4] = {0.0f, 0.0f, 0.0f, d->lifetime};
    float force[4] = {d->gravity[0], d->gravity[1], d->gravity[2], d->speed};
    ob_params_set_vec4(params, ps->step, step);
    ob_params_set_vec4(params, ps->emitter, emitter);
    ob_params_set_vec4(params, ps->force, force);
    ob_params_set_buffer(params, ps->particles, ps->buffer);
}

static void sim_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                       uint32_t first, uint32_t count)
{
    sim_view *sv = (sim_view *)v;
    ob_particle_system *ps = sv->ps;
    (void)r;
    (void)layer;
    (void)first;
    (void)count;
    ob_effect *e = ob_material_library_find_effect(ps->ctx->materials, OB_STD_PARTICLES_SIM, 0);
    if (!e) return;
    uint32_t id = 0;
    VkPipeline p = ob_effect_pipeline(e, VK_FORMAT_UNDEFINED, VK_FORMAT_UNDEFINED, &id);
    if (!p) return;
    ob_pipeline_manager_set_pipeline(pm, p, id, ob_effect_program(e));
    sim_params(ps, ob_pipeline_manager_params(pm));
    uint32_t local[3];
    ob_effect_local_size(e, local);
    ob_pipeline_manager_dispatch(pm, (ps->desc.count + local[0] - 1) / local[0], 1, 1);
}

/* The drawing side reads the same parameters (size, lifetime, buffer). */
static void sim_usage_params(ob_view *v, ob_renderer *r, ob_params *params, const ob_view *consumer)
{
    (void)r;
    (void)consumer;
    sim_params(((sim_view *)v)->ps, params);
}

static const ob_view_vtbl sim_vtbl = {
    .type_name = "simulation",
    .pre_render = sim_pre_render,
    .set_usage_params = sim_usage_params,
    .record = sim_record,
};

static void seed_particles(particle *p, const ob_particle_desc *d)
{
    uint32_t s = d->seed * 2654435761u + 12345u;
    for (uint32_t i = 0; i < d->count; i++) {
        s = s * 1664525u + 1013904223u;
        /* Staggered lives so the fountain starts full instead of in one burst. */
        float life = d->lifetime * (float)(s >> 8) / (float)(1u << 24);
        p[i] = (particle){{0.0f, 0.0f, 0.0f, -life}, {0.0f, 0.0f, 0.0f, 0.0f}};
    }
}

ob_particle_system *ob_particle_system_create(ob_views *ctx, ob_scene *scene, ob_node *parent,
                                              const ob_particle_desc *desc, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_particle_system *ps = ob_calloc(1, sizeof *ps);
    particle *init = NULL;
    if (!ps) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_destroy_system;
    }
    ps->ctx = ctx;
    ps->scene = scene;
    ps->desc = desc ? *desc : (ob_particle_desc){0};
    ob_particle_desc *d = &ps->desc;
    if (!d->count) d->count = 4096;
    if (!(d->lifetime > 0.0f)) d->lifetime = 3.0f;
    if (!(d->speed > 0.0f)) d->speed = 2.0f;
    if (!(d->size > 0.0f)) d->size = 0.05f;
    if (d->color[3] <= 0.0f) {
        static const float warm[4] = {1.0f, 0.8f, 0.5f, 1.0f};
        memcpy(d->color, warm, sizeof warm);
    }
    const char *name = d->name ? d->name : "particles";
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    ps->particles = ob_param_find(reg, "Particles");
    ps->step = ob_param_find(reg, "SimStep");
    ps->emitter = ob_param_find(reg, "SimEmitter");
    ps->force = ob_param_find(reg, "SimForce");

    init = ob_malloc(sizeof *init * d->count);
    if (!init) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_destroy_system;
    }
    seed_particles(init, d);
    ob_buffer_desc bd = {.size = sizeof *init * d->count, .usage = OB_BUFFER_STORAGE,
                         .data = init, .name = name};
    ps->buffer = ob_buffer_create(ctx->dev, &bd, &r);
    ob_free(init);
    init = NULL;
    if (!ps->buffer.id) goto fail_destroy_system;

    ob_geometry_desc gd = {.name = name, .vertex_count = 6, .instance_count = d->count};
    ps->quads = ob_geometry_create(ctx->dev, &gd, &r);
    if (!ps->quads) goto fail_destroy_system;
    /* Both effects now: a shader that does not compile fails the creation
     * instead of leaving a system that never moves, logged only. */
    if (!ob_material_library_effect(ctx->materials, OB_STD_PARTICLES_SIM, 0, &r))
        goto fail_destroy_system;
    ob_effect *draw = ob_material_library_effect(ctx->materials, OB_STD_PARTICLES_DRAW, 0, &r);
    if (!draw) goto fail_destroy_system;
    ob_material_desc md = {.name = name, .kind = OB_MATERIAL_CUSTOM, .blended = true};
    memcpy(md.diffuse, d->color, sizeof md.diffuse);
    ps->material = ob_material_create(ctx->materials, &md, &r);
    if (!ps->material) goto fail_destroy_system;
    r = ob_material_set_view_effect(ps->material, OB_VIEW_PERSPECTIVE, draw);
    if (r != OB_OK) goto fail_destroy_system;

    ob_view_init(&ps->sim.base, &sim_vtbl, OB_VIEW_SIMULATION, name);
    ps->sim.ps = ps;
    ps->sim.base.layer_count = 0;
    ps->sim.base.storage_written = ps->buffer;

    ps->node = ob_node_create(scene, parent, name, &r);
    if (!ps->node) goto fail_destroy_system;
    /* The particles stay within speed * lifetime of the emitter. */
    float reach = d->speed * d->lifetime +
                  0.5f * sqrtf(d->gravity[0] * d->gravity[0] + d->gravity[1] * d->gravity[1] +
                               d->gravity[2] * d->gravity[2]) * d->lifetime * d->lifetime;
    ob_renderable rd = {.material = ps->material, .geometry = ps->quads, .local_radius = reach};
    r = ob_node_set_renderable(ps->node, &rd);
    if (r != OB_OK) goto fail_destroy_system;
    r = ob_views_add_system(ctx, ps->node, &ps->sim.base, ps);
    if (r != OB_OK) goto fail_destroy_system;
    if (out_result) *out_result = OB_OK;
    return ps;

fail_destroy_system:
    OB_LOG_E("views", "particle system '%s' not created: %s",
             desc && desc->name ? desc->name : "particles", ob_result_name(r));
    ob_free(init);
    ob_particle_system_destroy(ctx, ps);
    if (out_result) *out_result = r;
    return NULL;
}

void ob_particle_system_destroy(ob_views *ctx, ob_particle_system *ps)
{
    if (!ps) return;
    ob_views_remove_system(ctx, ps);
    /* The entity goes first: it points at the material and the quads. */
    if (ps->node) ob_node_destroy(ps->node);
    ob_material_destroy(ps->material);
    ob_geometry_destroy(ctx->dev, ps->quads);
    ob_buffer_destroy(ctx->dev, ps->buffer);
    ob_view_release(&ps->sim.base);
    ob_free(ps);
}

ob_node *ob_particle_system_node(ob_particle_system *ps) { return ps->node; }
ob_view *ob_particle_system_sim_view(ob_particle_system *ps) { return &ps->sim.base; }
