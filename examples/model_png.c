/* model_png — a model file (glTF 2, OBJ, PLY, ...) with its materials and
 * textures, lit by a sun, the camera framed on it, rendered headless to a PNG.
 *
 *   model_png MODEL OUT.png
 *   cc -std=c11 model_png.c $(pkg-config --cflags --libs obelisk) -o model_png
 */
#include <obelisk/obelisk.h>

#include <stdio.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: model_png MODEL OUT.png\n");
        return 2;
    }
    ob_result r;
    ob_stack *s = ob_stack_create(&(ob_stack_desc){.width = 640, .height = 480}, &r);
    ob_node *model = s ? ob_stack_add_model(s, &(ob_stack_model_desc){.path = argv[1]}, &r) : NULL;
    if (model && ob_stack_add_sun(s, NULL, &r) && (r = ob_stack_fit_camera(s, model)) == OB_OK &&
        (r = ob_stack_frame(s, 0.0)) == OB_OK)
        r = ob_image_write_png(s->device, ob_stack_final_image(s), argv[2]);
    ob_stack_destroy(s);
    /* Errors were logged naming the file; a texture that did not load is a
     * warning, and the model rendered without it. */
    if (r != OB_OK) {
        fprintf(stderr, "model_png: %s: %s\n", argv[1], ob_result_text(r));
        return 1;
    }
    printf("model_png: wrote %s\n", argv[2]);
    return 0;
}
