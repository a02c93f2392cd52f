/* test_errors_returned_core.c (unit: no device) — issue 27, "errors reach the
 * caller": every create, load, open or compile path that needs no device
 * fails through what it returns (a NULL object or a zero handle and the
 * ob_result), not only through the log, and the log line names the file or
 * the entity. docs/errors.md lists each path with the test that checks it;
 * the paths that need a device are in tests/gpu/test_errors_returned.c.
 *
 * Each test: provoke one failure (bad input, a missing file, a failed
 * allocation through ob_fault_*), assert the returned result and the NULL
 * object, then assert the logged line names what failed. */
#define _GNU_SOURCE
#include "ob_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_mesh.h"
#include "ob_model.h"
#include "ob_params.h"
#include "ob_scene.h"
#include "ob_scene_file.h"
#include "ob_shader.h"
#include "ob_shader_source.h"

#define MISSING "/nonexistent/obelisk-errors/missing"

/* ------------------------------------------------------------------ core */

static void file_read_missing_is_io(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    size_t size = 1;
    assert_null(ob_file_read(MISSING ".txt", &size, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_logged(MISSING ".txt");
}

static ob_result once_fails(void) { return OB_ERR_UNSUPPORTED; }

static void once_keeps_a_failure_and_names_it(void **state)
{
    (void)state;
    static ob_once broken = OB_ONCE_INIT("test set-up", once_fails);
    assert_int_equal(ob_once_run(&broken), OB_ERR_UNSUPPORTED);
    assert_logged("'test set-up'", "OB_ERR_UNSUPPORTED");
    ob_test_log_clear();
    /* Kept: the second call answers the same, quietly. */
    assert_int_equal(ob_once_run(&broken), OB_ERR_UNSUPPORTED);
    assert_int_equal(ob_test_log_count(OB_LOG_ERROR), 0);
}

/* ob_core.h lists Obelisk's process-wide set-ups: what runs is among them,
 * and parsing a scene file leaves cJSON's hooks alone unless asked. */
static void process_wide_setups_are_the_listed_ones(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    static const char text[] = "{\"entities\": []}";
    assert_int_equal(ob_scene_file_parse(text, sizeof text - 1, NULL, &sf, &err), OB_OK);
    ob_scene_file_release(&sf);
    ob_result r;
    ob_shader_compiler *c = ob_shader_compiler_create(&(ob_shader_compiler_desc){.no_disk_cache = true}, &r);
    assert_non_null(c);
    ob_shader_compiler_destroy(c);
    const char *names[16];
    uint32_t n = ob_once_list(names, 16);
    assert_true(n <= 16);
    bool glslang = false;
    for (uint32_t i = 0; i < n; i++) {
        static const char *const listed[] = {"glslang", "cJSON hooks", "standard input",
                                             "test set-up"};
        bool known = false;
        for (size_t k = 0; k < OB_ARRAY_COUNT(listed); k++) known |= strcmp(names[i], listed[k]) == 0;
        if (!known) fail_msg("process-wide set-up '%s' is not listed in ob_core.h", names[i]);
        glslang |= strcmp(names[i], "glslang") == 0;
        /* A parse alone must not have changed cJSON's process-wide hooks. */
        assert_string_not_equal(names[i], "cJSON hooks");
    }
    assert_true(glslang);
    ob_scene_file_hook_cjson();
    const char *after[16];
    uint32_t m = ob_once_list(after, 16);
    assert_int_equal(m, n + 1);
    assert_string_equal(after[m - 1], "cJSON hooks");
}

/* ---------------------------------------------------------------- params */

static void registry_too_many_slots_is_refused(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    ob_param_registry_desc d = {.slot_count = OB_PARAM_MAX_SLOTS + 1};
    assert_null(ob_param_registry_create(&d, &r));
    assert_int_equal(r, OB_ERR_OUT_OF_RANGE);
    assert_logged("slots");
}

static void registry_out_of_memory_is_returned(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    assert_null(ob_param_registry_create(NULL, &r));
    assert_true(ob_fault_hit(OB_FAULT_HOST_ALLOC));
    assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
    assert_logged("registry", "out of host memory");
}

static void param_registered_twice_differently_is_refused(void **state)
{
    (void)state;
    ob_result r;
    ob_param_registry *reg = ob_param_registry_create(NULL, &r);
    assert_non_null(reg);
    assert_true(ob_param_register(reg, "Tint", OB_PARAM_VEC4, 1, &r).id != 0);
    ob_test_log_clear();
    ob_param p = ob_param_register(reg, "Tint", OB_PARAM_MAT4, 1, &r);
    assert_int_equal(p.id, 0);
    assert_int_equal(r, OB_ERR_DUPLICATE);
    assert_logged("Tint");
    ob_param_registry_destroy(reg);
}

/* ----------------------------------------------------------------- scene */

static void scene_out_of_memory_is_returned(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    assert_null(ob_scene_create(&r));
    assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
    assert_logged("cannot create scene");
}

static void node_under_a_foreign_parent_is_refused(void **state)
{
    (void)state;
    ob_result r;
    ob_scene *a = ob_scene_create(&r), *b = ob_scene_create(&r);
    assert_non_null(a);
    assert_non_null(b);
    ob_node *stranger = ob_node_create(b, NULL, "stranger", &r);
    assert_non_null(stranger);
    assert_null(ob_node_create(a, stranger, "lost", &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("'lost'", "'stranger'", "another scene");
    ob_scene_destroy(a);
    ob_scene_destroy(b);
}

/* ob_node_destroy takes the node alone (its scene cannot be mistaken);
 * what it refuses is returned, named in the log, and leaves the tree. */
static void node_destroy_misuse_is_returned(void **state)
{
    (void)state;
    ob_result r;
    ob_scene *s = ob_scene_create(&r), *other = ob_scene_create(&r);
    assert_non_null(s);
    assert_non_null(other);
    ob_node *mine = ob_node_create(s, NULL, "mine", &r);
    ob_node *theirs = ob_node_create(other, NULL, "theirs", &r);
    assert_non_null(mine);
    assert_non_null(theirs);

    assert_int_equal(ob_node_destroy(NULL), OB_OK);
    assert_int_equal(ob_node_destroy(ob_scene_root(s)), OB_ERR_INVALID_ARGUMENT);
    assert_logged("root", "cannot be destroyed");
    assert_int_equal(ob_scene_node_count(s), 2);

    /* A node of another scene in a batch: refused and named, the rest go. */
    ob_test_log_clear();
    ob_node *batch[] = {theirs, mine};
    assert_int_equal(ob_nodes_destroy(s, batch, 2), OB_ERR_INVALID_ARGUMENT);
    assert_logged("'theirs'", "another scene");
    assert_int_equal(ob_scene_node_count(s), 1);
    assert_int_equal(ob_scene_node_count(other), 2);
    assert_int_equal(ob_node_destroy(theirs), OB_OK);
    assert_int_equal(ob_scene_node_count(other), 1);
    assert_int_equal(ob_nodes_destroy(NULL, batch, 1), OB_ERR_INVALID_ARGUMENT);
    ob_scene_destroy(s);
    ob_scene_destroy(other);
}

/* -------------------------------------------------------------- shaders */

static void shader_source_missing_is_io(void **state)
{
    (void)state;
    ob_shader_source src;
    assert_int_equal(ob_shader_source_load(MISSING, "gone.frag", NULL, &src), OB_ERR_IO);
    assert_logged("gone.frag");
}

static void shader_missing_file_is_io(void **state)
{
    (void)state;
    ob_result r;
    ob_shader_compiler_desc cd = {.shader_dir = MISSING, .no_disk_cache = true};
    ob_shader_compiler *c = ob_shader_compiler_create(&cd, &r);
    assert_non_null(c);
    ob_shader_desc d = {.path = "pbr.frag", .stage = OB_SHADER_FRAGMENT};
    assert_null(ob_shader_get(c, &d, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_logged("pbr.frag", MISSING);
    ob_shader_compiler_destroy(c);
}

static void shader_compile_error_names_file_and_line(void **state)
{
    (void)state;
    ob_result r;
    ob_shader_compiler *c = ob_shader_compiler_create(&(ob_shader_compiler_desc){.no_disk_cache = true}, &r);
    assert_non_null(c);
    ob_shader_desc d = {.path = "broken.frag",
                        .source = "#version 450\nvoid main() {\n  not_a_type x;\n}\n",
                        .stage = OB_SHADER_FRAGMENT};
    assert_null(ob_shader_get(c, &d, &r));
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_logged("broken.frag:3");
    ob_shader_compiler_destroy(c);
}

static void shader_compiler_out_of_memory_is_returned(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    assert_null(ob_shader_compiler_create(NULL, &r));
    assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
    assert_logged("shader compiler");
}

/* -------------------------------------------------------------- geometry */

static void mesh_generator_bad_input_is_refused(void **state)
{
    (void)state;
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_sphere(1.0f, 2, 1, &m), OB_ERR_INVALID_ARGUMENT);
    assert_null(m.vertices);
    assert_logged("sphere");
}

static void model_load_missing_is_io(void **state)
{
    (void)state;
    ob_mesh m = {0};
    ob_model_desc d = {.path = MISSING ".obj"};
    assert_int_equal(ob_model_load_mesh(&d, &m, NULL), OB_ERR_IO);
    assert_null(m.vertices);
    assert_logged(MISSING ".obj");
}

static void model_open_missing_is_io(void **state)
{
    (void)state;
    ob_model *model = (ob_model *)&model;   /* not NULL: the failure must clear it */
    ob_model_desc d = {.path = MISSING ".gltf"};
    assert_int_equal(ob_model_open(&d, &model), OB_ERR_IO);
    assert_null(model);
    assert_logged(MISSING ".gltf");
}

/* ----------------------------------------------------------- scene files */

/* The scene-file parser logs nothing: its caller gets the message. */
static void scene_file_missing_is_io_with_message(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(ob_scene_file_load(MISSING ".json", &sf, &err), OB_ERR_IO);
    assert_non_null(strstr(err.message, MISSING ".json"));
}

static void scene_file_bad_value_names_its_path(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    static const char text[] = "{\"entities\": [{\"name\": \"a\", \"geometry\": \"cube\"}]}";
    assert_int_equal(ob_scene_file_parse(text, sizeof text - 1, "bad.json", &sf, &err), OB_ERR_PARSE);
    assert_non_null(strstr(err.message, "bad.json"));
    assert_non_null(strstr(err.message, "entities[0]"));
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        ob_test_expecting_errors(file_read_missing_is_io),
        ob_test_expecting_errors(once_keeps_a_failure_and_names_it),
        ob_test_expecting_errors(process_wide_setups_are_the_listed_ones),
        ob_test_expecting_errors(registry_too_many_slots_is_refused),
        ob_test_expecting_errors(registry_out_of_memory_is_returned),
        ob_test_expecting_errors(param_registered_twice_differently_is_refused),
        ob_test_expecting_errors(scene_out_of_memory_is_returned),
        ob_test_expecting_errors(node_under_a_foreign_parent_is_refused),
        ob_test_expecting_errors(node_destroy_misuse_is_returned),
        ob_test_expecting_errors(shader_source_missing_is_io),
        ob_test_expecting_errors(shader_missing_file_is_io),
        ob_test_expecting_errors(shader_compile_error_names_file_and_line),
        ob_test_expecting_errors(shader_compiler_out_of_memory_is_returned),
        ob_test_expecting_errors(mesh_generator_bad_input_is_refused),
        ob_test_expecting_errors(model_load_missing_is_io),
        ob_test_expecting_errors(model_open_missing_is_io),
        ob_test_expecting_errors(scene_file_missing_is_io_with_message),
        ob_test_expecting_errors(scene_file_bad_value_names_its_path),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
