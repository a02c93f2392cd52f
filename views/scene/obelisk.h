/* obelisk.h — the whole public API of an installed Obelisk:
 * #include <obelisk/obelisk.h>, link Obelisk::obelisk (CMake) or
 * `pkg-config --libs obelisk`. examples/cube_png.c is the smallest program.
 *
 * examples/model_png.c shows a model file with its textures, lit and framed
 * (ob_stack_content.h).
 *
 * Layers, bottom up (each header says its lifecycle and thread rule):
 *   engine     results, logging, allocation (ob_core.h); device and resources;
 *              parameters; programs and the pipeline manager; scene graph and
 *              math; the render-view interface; the renderer (frame, workers,
 *              stats)
 *   materials  run-time shader compiler, render effects, materials
 *   geometry   meshes and generators, model loading, GPU geometry
 *   views      the standard views (perspective, shadow, env map, simulation,
 *              overlay, composite)
 *   scene      (views/scene) ob_stack, the usual set-up in one call, and
 *              content into it in one call each (ob_stack_content.h:
 *              models, a sun, scene files, the camera framed); scene
 *              files: parsing (ob_scene_file.h) and loading into a scene
 *              (ob_scene_load.h); models placed with their materials
 *              (ob_model_instance.h); bounds and framing (ob_framing.h)
 * Only the Vulkan headers come along; cglm, stb and cJSON stay inside the
 * library.
 */
#ifndef OBELISK_H
#define OBELISK_H

#include "ob_core.h"
#include "ob_device.h"
#include "ob_math.h"
#include "ob_params.h"
#include "ob_pipeline_manager.h"
#include "ob_program.h"
#include "ob_reflect.h"
#include "ob_renderer.h"
#include "ob_resources.h"
#include "ob_scene.h"
#include "ob_texture.h"
#include "ob_view.h"

#include "ob_effect.h"
#include "ob_material.h"
#include "ob_shader.h"

#include "ob_geometry.h"
#include "ob_mesh.h"
#include "ob_model.h"
#include "ob_model_instance.h"

#include "ob_framing.h"
#include "ob_scene_file.h"
#include "ob_scene_load.h"
#include "ob_stack.h"
#include "ob_stack_content.h"
#include "ob_views.h"

#endif /* OBELISK_H */
