/* libFuzzer target for the scene-file parser (views/scene/ob_scene_file.h).
 *
 * Any input must either parse into a description that keeps the documented
 * invariants (references in range and pointing backwards, every number
 * finite, paths and names present) or fail with a message naming the file;
 * never crash, leak (ASan) or hit undefined behaviour (UBSan). A broken
 * invariant traps, so libFuzzer saves the input. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "ob_scene_file.h"

#define CHECK(cond) do { if (!(cond)) __builtin_trap(); } while (0)

static void check_finite(const float *v, int n)
{
    for (int i = 0; i < n; i++) CHECK(isfinite(v[i]));
}

static void check_finite_d(const double *v, int n)
{
    for (int i = 0; i < n; i++) CHECK(isfinite(v[i]));
}

static void check_description(const ob_scene_file *sf)
{
    CHECK(sf->path && strcmp(sf->path, "fuzz/scene.json") == 0);
    if (sf->camera.present) {
        check_finite_d(sf->camera.position, 3);
        check_finite_d(sf->camera.target, 3);
        check_finite_d(sf->camera.up, 3);
        CHECK(sf->camera.fov_degrees > 0.0f && sf->camera.fov_degrees < 180.0f && sf->camera.znear > 0.0f);
    }
    for (uint32_t i = 0; i < sf->light_count; i++) {
        const ob_scene_file_light *l = &sf->lights[i];
        CHECK(l->name && l->name[0]);
        check_finite_d(l->position, 3);
        check_finite_d(l->direction, 3);
        check_finite(l->desc.color, 3);
        CHECK(l->desc.intensity >= 0.0f && l->desc.range >= 0.0f);
    }
    for (uint32_t i = 0; i < sf->material_count; i++) {
        const ob_scene_file_material *m = &sf->materials[i];
        CHECK(m->name && m->desc.name == m->name);
        check_finite(m->desc.diffuse, 4);
        check_finite(m->desc.specular, 4);
        check_finite(m->desc.emissive, 4);
        CHECK(m->desc.specular[3] > 0.0f);
    }
    for (uint32_t i = 0; i < sf->entity_count; i++) {
        const ob_scene_file_entity *e = &sf->entities[i];
        CHECK(e->name && e->name[0] && e->index == i);
        CHECK(e->parent == OB_SCENE_FILE_NONE || e->parent < i);
        CHECK(e->material == OB_SCENE_FILE_NONE || e->material < sf->material_count);
        CHECK((e->geometry.kind == OB_SCENE_GEOMETRY_MODEL) == (e->geometry.model != NULL));
        CHECK(e->geometry.kind != OB_SCENE_GEOMETRY_NONE || e->material == OB_SCENE_FILE_NONE);
        check_finite_d(e->position, 3);
        check_finite_d(e->rotation, 4);
        check_finite(e->scale, 3);
        CHECK(ob_scene_file_geometry_equal(&e->geometry, &e->geometry));
        CHECK(ob_scene_file_geometry_kind_name(e->geometry.kind)[0] != 'u');
        for (uint32_t k = 0; k < e->controller_count; k++) {
            check_finite(e->controllers[k].axis, 3);
            CHECK(e->controllers[k].radius >= 0.0);
        }
    }
    for (uint32_t i = 0; i < sf->particle_count; i++) {
        const ob_scene_file_particles *p = &sf->particles[i];
        CHECK(p->name && p->desc.name == p->name);
        CHECK(p->parent == OB_SCENE_FILE_NONE || p->parent < sf->entity_count);
        CHECK(p->desc.count >= 1 && p->desc.count <= OB_SCENE_FILE_MAX_PARTICLES);
        check_finite(p->desc.color, 4);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ob_scene_file sf;
    ob_scene_file_error err;
    ob_result r = ob_scene_file_parse((const char *)data, size, "fuzz/scene.json", &sf, &err);
    if (r == OB_OK) {
        CHECK(err.message[0] == '\0');
        check_description(&sf);
        ob_scene_file_release(&sf);
    } else {
        CHECK(r == OB_ERR_PARSE || r == OB_ERR_OUT_OF_HOST_MEMORY);
        CHECK(strncmp(err.message, "fuzz/scene.json", 15) == 0);
        CHECK(memchr(err.message, '\0', sizeof err.message) != NULL);
        CHECK(sf.entities == NULL && sf.materials == NULL && sf.path == NULL);
    }
    return 0;
}
