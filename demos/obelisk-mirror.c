/* obelisk-mirror — Hieroglyph 3's MirrorMirror on Obelisk.
 *
 * Three reflective spheres whose dual-paraboloid environment maps see each
 * other (a hall of mirrors, bounded by the renderer's recursion limit), N
 * diffuse objects orbiting and spinning around them, a shadow-casting
 * directional light, a particle fountain and a text overlay. Headless by
 * default: it renders --frames frames, prints a line per frame and a
 * summary, and writes --out. --threads / --toggle choose single- or
 * multi-threaded recording per frame; the pixels are the same either way.
 * The scene is demos/scenes/ob_mirror_scene.h, which obelisk-bench measures
 * too. */
#include <stdio.h>

#include "ob_demo.h"
#include "ob_mirror_scene.h"

/* The camera circles the mirrors slowly, looking at their centre. */
static void animate(ob_demo *d, uint32_t frame, double time, void *user)
{
    (void)frame;
    (void)user;
    ob_mirror_scene_camera(d->world.camera, time);
}

int main(int argc, char **argv)
{
    ob_demo_options opt;
    int code;
    if (!ob_demo_options_parse(argc, argv, "  --objects N       orbiting objects (default 200, up to 100000)\n",
                               false, &opt, &code))
        return code;
    ob_demo d;
    ob_result r = ob_demo_init(&d, &opt);
    if (r == OB_OK)
        r = ob_mirror_scene_build(&d, &(ob_mirror_scene_desc){.objects = opt.objects, .seed = opt.seed});
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-mirror: set-up failed: %s (%s)\n", ob_result_name(r), ob_result_text(r));
        ob_demo_shutdown(&d);
        return 1;
    }
    printf("obelisk-mirror: %s, %u objects, %ux%u, threading %s (%u workers)\n",
           ob_device_name(ob_renderer_device(d.world.r)), opt.objects, opt.width, opt.height,
           ob_threading_name(ob_demo_options_threading(&opt)), ob_renderer_worker_count(d.world.r));
    code = ob_demo_run(&d, animate, NULL);
    ob_demo_shutdown(&d);
    return code;
}
