/* obelisk-mirror-scene — obelisk-mirror's scene as a scene file, and the
 * check that a scene file is that scene.
 *
 *   obelisk-mirror-scene [--objects N] [--seed S] [--out FILE]
 *       writes the scene (ob_mirror_scene_write_json) to FILE or stdout;
 *       demos/scenes/mirror.json is the output for the defaults (200, 1).
 *   obelisk-mirror-scene [--objects N] [--seed S] --check FILE
 *       builds the scene from its definition (ob_mirror_scene_build) and
 *       loads FILE (ob_scene_load, seed S) on a second stack; both run the
 *       same frames, and after each every node of the built scene must have
 *       a node of the same name in the loaded one with the same world
 *       transform (positions within 4e-6 relative), geometry (vertex and index counts, bounds), material kind
 *       (entities sharing a material share it there too), light and camera;
 *       the two final images must match (up to 0.1% of values rounded the
 *       other way: orbits pass through the file as float degrees). Exit 0 when equal, 1 naming the
 *       first difference, 2 for bad options.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_mirror_scene.h"
#include "ob_scene_load.h"

#define CHECK_W 160u
#define CHECK_H 120u
#define CHECK_FRAMES 4u

typedef struct checker {
    ob_scene *built, *loaded;
    const ob_material *from[64], *to[64];   /* the material map built -> loaded */
    uint32_t material_count;
    uint32_t nodes, failures;
} checker;

static void differ(checker *c, const char *what, const char *name)
{
    if (c->failures++ < 10) fprintf(stderr, "obelisk-mirror-scene: node '%s': %s differs\n", name, what);
}

/* |a - b| <= tol * max(1, |a|). */
static bool near3(const double *a, const double *b, double tol)
{
    double d = 0.0, n = 0.0;
    for (int i = 0; i < 3; i++) {
        d += (a[i] - b[i]) * (a[i] - b[i]);
        n += a[i] * a[i];
    }
    return sqrt(d) <= tol * fmax(1.0, sqrt(n));
}

static bool same_material(checker *c, const ob_material *a, const ob_material *b)
{
    if (ob_material_get_kind(a) != ob_material_get_kind(b)) return false;
    for (uint32_t i = 0; i < c->material_count; i++)
        if (c->from[i] == a || c->to[i] == b) return c->from[i] == a && c->to[i] == b;
    if (c->material_count == OB_ARRAY_COUNT(c->from)) return false;
    c->from[c->material_count] = a;
    c->to[c->material_count++] = b;
    return true;
}

static void check_node(checker *c, const ob_node *a)
{
    const char *name = ob_node_name(a);
    const ob_node *b = ob_scene_find(c->loaded, name);
    c->nodes++;
    if (!b) {
        differ(c, "presence (not in the file)", name);
        return;
    }
    double pa[3], pb[3];
    float ra[3], ua[3], fa[3], rb[3], ub[3], fb[3];
    ob_node_world_position(a, pa);
    ob_node_world_position(b, pb);
    /* An orbit's rate and phase pass through the file as float degrees,
     * which cannot hold every float radian: the angles may be a float step
     * (up to 5e-7 rad at 2pi) apart, the positions that times the radius. */
    if (!near3(pa, pb, 4e-6)) differ(c, "world position", name);
    ob_node_world_axes(a, ra, ua, fa);
    ob_node_world_axes(b, rb, ub, fb);
    for (int i = 0; i < 3; i++)
        if (fabsf(ra[i] - rb[i]) > 1e-5f || fabsf(ua[i] - ub[i]) > 1e-5f || fabsf(fa[i] - fb[i]) > 1e-5f) {
            differ(c, "world orientation", name);
            break;
        }
    const ob_renderable *xa = ob_node_get_renderable(a), *xb = ob_node_get_renderable(b);
    if (!xa != !xb) {
        differ(c, "being drawn", name);
    } else if (xa) {
        if (!xa->geometry != !xb->geometry ||
            (xa->geometry && (ob_geometry_vertex_count(xa->geometry) != ob_geometry_vertex_count(xb->geometry) ||
                              ob_geometry_index_count(xa->geometry) != ob_geometry_index_count(xb->geometry))))
            differ(c, "geometry", name);
        if (xa->local_radius != xb->local_radius ||
            memcmp(xa->local_center, xb->local_center, sizeof xa->local_center) != 0)
            differ(c, "bounds", name);
        if (!same_material(c, xa->material, xb->material)) differ(c, "material", name);
    }
    const ob_light_desc *la = ob_node_get_light(a), *lb = ob_node_get_light(b);
    if (!la != !lb || (la && (la->type != lb->type || la->intensity != lb->intensity ||
                              la->range != lb->range || la->casts_shadows != lb->casts_shadows ||
                              memcmp(la->color, lb->color, sizeof la->color) != 0)))
        differ(c, "light", name);
    const ob_camera_desc *ca = ob_node_get_camera(a), *cb = ob_node_get_camera(b);
    if (!ca != !cb || (ca && (fabsf(ca->fovy - cb->fovy) > 1e-6f || ca->znear != cb->znear)))
        differ(c, "camera", name);
    for (const ob_node *k = ob_node_first_child(a); k; k = ob_node_next_sibling(k)) check_node(c, k);
}

static int check(const ob_mirror_scene_desc *md, const char *path)
{
    ob_demo_options dopt = {.frames = 1, .width = CHECK_W, .height = CHECK_H, .seed = md->seed,
                            .objects = md->objects, .quiet = true};
    ob_demo d;
    ob_result r = ob_demo_init(&d, &dopt);
    if (r == OB_OK) r = ob_mirror_scene_build(&d, md);
    if (r == OB_OK) ob_mirror_scene_camera(d.world.camera, 0.0);
    ob_stack *s = NULL;
    ob_scene_loaded loaded = {0};
    ob_scene_file_error err = {0};
    if (r == OB_OK) {
        /* The built stack's set-up (ob_demo's), so only the scene differs. */
        ob_stack_desc sd = {.renderer = {.device = {.app_name = "obelisk-mirror-scene"}},
                            .width = CHECK_W, .height = CHECK_H};
        s = ob_stack_create(&sd, &r);
    }
    if (r == OB_OK) {
        r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = path, .seed = md->seed}, &loaded, &err);
        if (r != OB_OK) fprintf(stderr, "obelisk-mirror-scene: %s\n", err.message);
    }
    checker c = {.built = d.world.scene, .loaded = s ? s->scene : NULL};
    uint8_t *a = NULL, *b = NULL;
    uint32_t image_differing = 0;
    for (uint32_t f = 0; r == OB_OK && f < CHECK_FRAMES && !c.failures; f++) {
        if ((r = ob_stack_frame(d.world.stack, 0.25)) != OB_OK || (r = ob_stack_frame(s, 0.25)) != OB_OK) break;
        if (ob_scene_node_count(d.world.scene) != ob_scene_node_count(s->scene)) {
            fprintf(stderr, "obelisk-mirror-scene: %u nodes built, %u loaded\n",
                    ob_scene_node_count(d.world.scene), ob_scene_node_count(s->scene));
            c.failures++;
        }
        for (const ob_node *k = ob_node_first_child(ob_scene_root(d.world.scene)); k; k = ob_node_next_sibling(k))
            check_node(&c, k);
    }
    if (r == OB_OK && !c.failures) {
        a = malloc((size_t)CHECK_W * CHECK_H * 4);
        b = malloc((size_t)CHECK_W * CHECK_H * 4);
        r = a && b ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
        if (r == OB_OK) r = ob_image_read_rgba8(d.world.stack->device, ob_stack_final_image(d.world.stack), a);
        if (r == OB_OK) r = ob_image_read_rgba8(s->device, ob_stack_final_image(s), b);
        uint32_t differing = 0, max = 0;
        for (size_t i = 0; r == OB_OK && i < (size_t)CHECK_W * CHECK_H * 4; i++) {
            uint32_t dv = (uint32_t)abs((int)a[i] - (int)b[i]);
            differing += dv != 0;
            if (dv > max) max = dv;
        }
        /* The float-degree orbits above move an edge by a fraction of a
         * pixel at most: a few values may round the other way, no more. */
        if (r == OB_OK && differing > CHECK_W * CHECK_H * 4 / 1000) {
            fprintf(stderr, "obelisk-mirror-scene: the images differ in %u channel values (max %u)\n",
                    differing, max);
            c.failures++;
        }
        image_differing = differing;
    }
    free(a);
    free(b);
    if (s) ob_renderer_wait_idle(s->renderer);
    ob_scene_unload(&loaded);
    ob_stack_destroy(s);
    ob_demo_shutdown(&d);
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-mirror-scene: checking %s failed: %s\n", path, ob_result_name(r));
        return 1;
    }
    if (c.failures) {
        fprintf(stderr, "obelisk-mirror-scene: %s is not the scene ob_mirror_scene_build makes "
                        "(%u differences); regenerate it: obelisk-mirror-scene --out %s\n",
                path, c.failures, path);
        return 1;
    }
    printf("%s: %u node checks over %u frames and the final image (%u of %u channel values "
           "off by rounding) agree with the definition\n",
           path, c.nodes, CHECK_FRAMES, image_differing, CHECK_W * CHECK_H * 4);
    return 0;
}

int main(int argc, char **argv)
{
    /* cJSON's allocations counted with Obelisk's (the heap figures). */
    ob_scene_file_hook_cjson();
    ob_mirror_scene_desc md = {.objects = 200, .seed = 1};
    const char *out = NULL, *check_path = NULL;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(argv[i], "--objects") && v) {
            md.objects = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if (!strcmp(argv[i], "--seed") && v) {
            md.seed = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if (!strcmp(argv[i], "--out") && v) {
            out = argv[++i];
        } else if (!strcmp(argv[i], "--check") && v) {
            check_path = argv[++i];
        } else {
            fprintf(stderr, "usage: %s [--objects N] [--seed S] [--out FILE | --check FILE]\n", argv[0]);
            return 2;
        }
    }
    if (check_path) return check(&md, check_path);
    FILE *f = out ? fopen(out, "w") : stdout;
    if (!f) {
        perror(out);
        return 1;
    }
    ob_result r = ob_mirror_scene_write_json(&md, f);
    if (out && fclose(f) != 0) r = OB_ERR_IO;
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-mirror-scene: writing %s failed\n", out ? out : "stdout");
        return 1;
    }
    return 0;
}
