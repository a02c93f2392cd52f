/* cube_png — the smallest Obelisk program: a lit, shadowed cube on a floor,
 * rendered headless (lavapipe works, no GPU needed) and written to a PNG.
 *
 *   cube_png [out.png]        (default cube.png)
 *
 * Build it against an installed Obelisk with examples/CMakeLists.txt, or
 *   cc -std=c11 cube_png.c $(pkg-config --cflags --libs obelisk) -o cube_png
 */
#include <obelisk/obelisk.h>

#include <stdio.h>

static ob_result build_scene(ob_stack *s)
{
    ob_result r;
    ob_mesh mesh = {0};   /* generated on the host; the stack keeps the GPU copy */
    ob_geometry *cube = NULL, *ground = NULL;
    if ((r = ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &mesh)) == OB_OK)
        cube = ob_stack_add_geometry(s, &mesh, "cube", &r);
    ob_mesh_release(&mesh);
    if (!cube) return r;
    if ((r = ob_mesh_plane(6.0f, 6.0f, 1, &mesh)) == OB_OK)
        ground = ob_stack_add_geometry(s, &mesh, "floor", &r);
    ob_mesh_release(&mesh);
    if (!ground) return r;

    ob_material_desc red = {.name = "red", .kind = OB_MATERIAL_LIT,
                            .diffuse = {0.9f, 0.25f, 0.2f, 1.0f}, .casts_shadows = true};
    ob_material_desc grey = {.name = "grey", .kind = OB_MATERIAL_LIT,
                             .diffuse = {0.7f, 0.7f, 0.65f, 1.0f}};
    ob_material *cube_material = ob_material_create(s->materials, &red, &r);
    if (!cube_material) return r;
    ob_material *ground_material = ob_material_create(s->materials, &grey, &r);
    if (!ground_material) return r;

    ob_node *box = ob_stack_add_entity(s, NULL, "cube", cube, cube_material, &r);
    if (!box) return r;
    ob_node_set_position(box, (const double[3]){0.0, 0.5, 0.0});
    ob_node_set_euler(box, 0.0f, 0.6f, 0.0f);
    if (!ob_stack_add_entity(s, NULL, "floor", ground, ground_material, &r)) return r;

    ob_node *sun = ob_node_create(s->scene, NULL, "sun", &r);
    if (!sun) return r;
    ob_light_desc light = {.type = OB_LIGHT_DIRECTIONAL, .intensity = 1.0f, .casts_shadows = true};
    if ((r = ob_node_set_light(sun, &light)) != OB_OK) return r;
    ob_node_set_position(sun, (const double[3]){3.0, 6.0, 2.0});
    const double origin[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 1.0, 0.0};
    if ((r = ob_node_look_at(sun, origin, up)) != OB_OK) return r;

    ob_node_set_position(s->camera, (const double[3]){2.2, 1.8, 3.0});
    return ob_node_look_at(s->camera, (const double[3]){0.0, 0.4, 0.0}, up);
}

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "cube.png";
    ob_result r;
    ob_stack *s = ob_stack_create(&(ob_stack_desc){.width = 320, .height = 240}, &r);
    if (s && (r = build_scene(s)) == OB_OK && (r = ob_stack_frame(s, 0.0)) == OB_OK)
        r = ob_image_write_png(s->device, ob_stack_final_image(s), out);
    ob_stack_destroy(s);
    /* Bad input is logged and the rest renders (a shader that cannot be read
     * draws nothing): a program that must not keep a wrong image checks both. */
    if (r != OB_OK || ob_log_count(OB_LOG_ERROR) > 0) {
        fprintf(stderr, "cube_png: %s\n", r != OB_OK ? ob_result_text(r) : "errors logged");
        return 1;
    }
    printf("cube_png: wrote %s\n", out);
    return 0;
}
