/* Hostile model files (issue 26), as a user would notice them: nothing
 * hangs on a FIFO, nothing outside the model's folder is read, a lying .glb
 * is refused before anything is allocated for it, and a skinned glTF that
 * crashed assimp opens (drawn in its bind pose). Every refusal names the
 * model and the file or chunk. The inputs are written here, in a temporary
 * folder, by the test itself. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_model.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DATA OB_SOURCE_DIR "/tests/data/models/"

/* A folder with a model folder inside: root/model/ holds the models, root/
 * holds what they must not reach. */
static char root[64], model_dir[96];

static int make_dirs(void **state)
{
    (void)state;
    snprintf(root, sizeof root, "/tmp/ob_test_model_hostile_XXXXXX");
    if (!mkdtemp(root)) return -1;
    snprintf(model_dir, sizeof model_dir, "%s/model", root);
    return mkdir(model_dir, 0700);
}

static int remove_dirs(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    return system(cmd) == 0 ? 0 : -1;
}

static void write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    assert_int_equal(fclose(f), 0);
}

static void write_text(const char *path, const char *text) { write_file(path, text, strlen(text)); }

/* A glTF's opening up to its buffers: one node, one mesh whose primitive
 * reads POSITION from accessor 0, and one 36-byte buffer holding a triangle
 * (0,0,0), (1,0,0), (0,1,0) as a data URI. The test adds views and accessors. */
#define TRIANGLE_GLTF_HEAD                                                                         \
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"                      \
    "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"     \
    "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"                \
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"

/* One triangle, its positions in buffer file `uri` (36 bytes). */
static void write_gltf_with_buffer(const char *path, const char *uri)
{
    char text[1024];
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
             uri);
    write_text(path, text);
}

static void write_triangle_bin(const char *path)
{
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    write_file(path, tri, sizeof tri);
}

static ob_result open_model(const char *path, bool any_folder, ob_model **out)
{
    ob_test_log_clear();
    return ob_model_open(&(ob_model_desc){.path = path, .allow_any_folder = any_folder}, out);
}

/* Any FIFO named by a model — the model itself, a glTF buffer, an OBJ's
 * mtllib — is refused at once; nothing writes to these FIFOs, so a loader
 * that opened one for reading would block forever and the test would time
 * out. */
static void fifos_are_refused_without_blocking(void **state)
{
    (void)state;
    char fifo[160], path[160];
    snprintf(fifo, sizeof fifo, "%s/buffer.bin", model_dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    snprintf(path, sizeof path, "%s/fifo_buffer.gltf", model_dir);
    write_gltf_with_buffer(path, "buffer.bin");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_null(m);
    assert_true(ob_test_log_has("fifo_buffer.gltf: refused to read", "buffer.bin", "not a regular file (a FIFO)", NULL));

    snprintf(fifo, sizeof fifo, "%s/fifo.mtl", model_dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    snprintf(path, sizeof path, "%s/fifo_mtl.obj", model_dir);
    write_text(path, "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_true(ob_test_log_has("fifo_mtl.obj: refused to read", "fifo.mtl", "a FIFO", NULL));

    snprintf(path, sizeof path, "%s/model_fifo.gltf", model_dir);
    assert_int_equal(mkfifo(path, 0600), 0);
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_true(ob_test_log_has("model_fifo.gltf: cannot open model file: not a regular file (a FIFO)", NULL));
}

/* Referenced files must resolve inside the model's folder after symbolic
 * links: "../" and a link pointing out are refused naming the URI; the
 * caller may allow any folder. */
static void references_stay_inside_the_models_folder(void **state)
{
    (void)state;
    char bin[160], path[160], link[160];
    snprintf(bin, sizeof bin, "%s/outside.bin", root);
    write_triangle_bin(bin);
    snprintf(path, sizeof path, "%s/dotdot.gltf", model_dir);
    write_gltf_with_buffer(path, "../outside.bin");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_null(m);
    assert_true(ob_test_log_has("dotdot.gltf: refused to read", "outside.bin", "outside the model's folder", NULL));
    /* Trusted content: allowed explicitly, it loads. */
    assert_int_equal(open_model(path, true, &m), OB_OK);
    assert_int_equal(m->primitives[0].mesh.vertex_count, 3);
    ob_model_close(m);

    snprintf(link, sizeof link, "%s/inside.bin", model_dir);
    assert_int_equal(symlink(bin, link), 0);
    snprintf(path, sizeof path, "%s/link.gltf", model_dir);
    write_gltf_with_buffer(path, "inside.bin");
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_true(ob_test_log_has("link.gltf: refused to read", "inside.bin", "outside the model's folder", NULL));

    /* A texture reaching out of the folder refuses the model too. */
    snprintf(path, sizeof path, "%s/outside.png", root);
    FILE *png = fopen(DATA "checker.png", "rb");
    assert_non_null(png);
    char bytes[4096];
    size_t n = fread(bytes, 1, sizeof bytes, png);
    fclose(png);
    write_file(path, bytes, n);
    snprintf(path, sizeof path, "%s/tex.obj", model_dir);
    write_text(path, "mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n");
    snprintf(path, sizeof path, "%s/tex.mtl", model_dir);
    write_text(path, "newmtl t\nKd 1 1 1\nmap_Kd ../outside.png\n");
    snprintf(path, sizeof path, "%s/tex.obj", model_dir);
    assert_int_equal(open_model(path, false, &m), OB_ERR_IO);
    assert_true(ob_test_log_has("tex.obj: material", "refused to read image '../outside.png'", NULL));
    assert_int_equal(open_model(path, true, &m), OB_OK);
    assert_int_equal(m->image_count, 1);
    ob_model_close(m);

    /* A texture that is a FIFO inside the folder is dropped with what it is. */
    snprintf(path, sizeof path, "%s/pipe.png", model_dir);
    assert_int_equal(mkfifo(path, 0600), 0);
    snprintf(path, sizeof path, "%s/pipe.mtl", model_dir);
    write_text(path, "newmtl t\nKd 1 1 1\nmap_Kd pipe.png\n");
    snprintf(path, sizeof path, "%s/pipe.obj", model_dir);
    write_text(path, "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n");
    assert_int_equal(open_model(path, false, &m), OB_OK);
    assert_int_equal(m->image_count, 0);
    assert_true(ob_test_log_has("pipe.obj: material", "pipe.png' a FIFO, not a regular file", NULL));
    ob_model_close(m);
}

/* A .glb whose header or JSON chunk claims more bytes than the file has is
 * refused by Obelisk, naming what lies, before assimp allocates it. */
static void lying_glb_lengths_are_refused(void **state)
{
    (void)state;
    static const char json[] = "{\"asset\":{\"version\":\"2.0\"}}    ";
    unsigned char glb[12 + 8 + sizeof json - 1];
    const uint32_t header[5] = {0x46546C67u, 2, sizeof glb, 0xFFFFFFF0u, 0x4E4F534Au};
    memcpy(glb, header, sizeof header);
    memcpy(glb + 20, json, sizeof json - 1);
    char path[160];
    snprintf(path, sizeof path, "%s/chunk.glb", model_dir);
    write_file(path, glb, sizeof glb);
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_BAD_MODEL);
    assert_true(ob_test_log_has("chunk.glb: not a valid binary glTF: its JSON chunk claims 4294967280 bytes, "
                                "the file has 51", NULL));
    const uint32_t total = 0xFFFFFF00u;
    memcpy(glb + 8, &total, 4);
    snprintf(path, sizeof path, "%s/total.glb", model_dir);
    write_file(path, glb, sizeof glb);
    assert_int_equal(open_model(path, false, &m), OB_ERR_BAD_MODEL);
    assert_true(ob_test_log_has("total.glb: not a valid binary glTF: its header's total length claims", NULL));
    /* The flattening loader (ob_model_load_mesh) checks the same. */
    ob_mesh mesh;
    ob_test_log_clear();
    assert_int_equal(ob_model_load_mesh(&(ob_model_desc){.path = path}, &mesh, NULL), OB_ERR_BAD_MODEL);
    assert_null(mesh.vertices);
}

/* A byteStride shorter than its element makes vertices overlap; assimp read
 * them silently. Refused, naming the accessor, the view and the sizes. */
static void short_byte_stride_is_refused(void **state)
{
    (void)state;
    char path[160];
    snprintf(path, sizeof path, "%s/stride.gltf", model_dir);
    write_text(path,
               TRIANGLE_GLTF_HEAD
               "\"accessors\":[{\"type\":\"VEC3\",\"bufferView\":0,\"componentType\":5126,\"count\":3}],"
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36,\"byteStride\":4}]}");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_BAD_MODEL);
    assert_true(ob_test_log_has("stride.gltf: accessor 0: bufferView 0 has byteStride 4, smaller than one "
                                "element (3 components of 4 bytes = 12 bytes)", NULL));
}

/* A sparse accessor whose count needs more indices than their view holds
 * made assimp copy past its buffer (found by fuzz_model's generated glTF). */
static void lying_sparse_count_is_refused(void **state)
{
    (void)state;
    char path[160];
    snprintf(path, sizeof path, "%s/sparse.gltf", model_dir);
    write_text(path,
               TRIANGLE_GLTF_HEAD
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteLength\":4},"
               "{\"buffer\":0,\"byteLength\":24}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
               "\"sparse\":{\"count\":3,\"indices\":{\"bufferView\":1,\"componentType\":5123},"
               "\"values\":{\"bufferView\":2}}}]}");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_BAD_MODEL);
    assert_true(ob_test_log_has("sparse.gltf: accessor 0: sparse count 3 needs 6 bytes of indices, its "
                                "bufferView 1 has 4", NULL));
}

/* A LINE_LOOP whose index is past the vertex count crashed assimp 5.2
 * (SIGSEGV; found by fuzz_model). Obelisk drops points and lines anyway:
 * their indices are hidden from assimp, and the triangle beside it opens. */
static void line_loop_with_a_bad_index_does_not_crash(void **state)
{
    (void)state;
    ob_model *m = NULL;
    assert_int_equal(open_model(DATA "line_loop_bad_index.gltf", false, &m), OB_OK);
    assert_int_equal(m->primitive_count, 1);
    assert_int_equal(m->primitives[0].mesh.index_count, 3);
    ob_model_close(m);
}

/* Names from a file are printed (logs, the lean report): a terminal
 * escape or invalid UTF-8 in a node, mesh or material name becomes '?'. */
static void names_with_terminal_escapes_are_made_printable(void **state)
{
    (void)state;
    char path[160];
    snprintf(path, sizeof path, "%s/names.gltf", model_dir);
    write_text(path,
               "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
               "\"nodes\":[{\"mesh\":0,\"name\":\"n\\u001b[2J\"}],"
               "\"meshes\":[{\"name\":\"m\\u009b31m\",\"primitives\":[{\"attributes\":{\"POSITION\":0},"
               "\"material\":0}]}],\"materials\":[{\"name\":\"x\\u0007y\"}],"
               "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
               "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
               "\"min\":[0,0,0],\"max\":[1,1,0]}]}");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_OK);
    bool node_seen = false;
    for (uint32_t i = 0; i < m->node_count; i++) {
        for (const char *p = m->nodes[i].name; *p; p++) assert_true((unsigned char)*p >= 0x20 && *p != 0x7f);
        node_seen = node_seen || strcmp(m->nodes[i].name, "n?[2J") == 0;
    }
    assert_true(node_seen);
    assert_string_equal(m->primitives[0].name, "m??31m");   /* U+009B is two bytes in UTF-8 */
    assert_string_equal(m->materials[0].name, "x?y");
    ob_model_close(m);
}

/* assimp's own words for two glTF faults ("No suitable reader found" for a
 * NaN literal, "Mesh has no faces" for indices past the vertex count) get
 * the likely cause added. */
static void assimp_messages_get_their_cause(void **state)
{
    (void)state;
    char path[160];
    snprintf(path, sizeof path, "%s/nan.gltf", model_dir);
    write_text(path, "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"scale\":[NaN,1,1]}]}");
    ob_model *m = NULL;
    assert_int_equal(open_model(path, false, &m), OB_ERR_PARSE);
    assert_true(ob_test_log_has("nan.gltf: assimp could not read the model", "its glTF JSON does not parse", NULL));
    assert_int_equal(open_model(DATA "index_out_of_range.gltf", false, &m), OB_ERR_PARSE);
    assert_true(ob_test_log_has("index_out_of_range.gltf", "has no faces", "indices are past the vertex count", NULL));
}

/* A skin without inverseBindMatrices (valid glTF) crashed assimp 5.2 with
 * SIGSEGV; joints past the joint count and NaN weights too. Obelisk does
 * not animate skins: the model opens, drawn in its bind pose, and says so. */
static void skinned_gltf_opens_in_its_bind_pose(void **state)
{
    (void)state;
    ob_model *m = NULL;
    assert_int_equal(open_model(DATA "skin_no_ibm.gltf", false, &m), OB_OK);
    assert_true(ob_test_log_has("skin_no_ibm.gltf: skins ignored", NULL));
    assert_int_equal(m->primitive_count, 1);
    assert_int_equal(m->primitives[0].mesh.vertex_count, 3);
    ob_model_close(m);
    ob_mesh mesh;
    ob_test_log_clear();
    assert_int_equal(ob_model_load_mesh(&(ob_model_desc){.path = DATA "skin_no_ibm.gltf"}, &mesh, NULL), OB_OK);
    assert_int_equal(mesh.index_count, 3);
    ob_mesh_release(&mesh);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fifos_are_refused_without_blocking),
        cmocka_unit_test(references_stay_inside_the_models_folder),
        cmocka_unit_test(lying_glb_lengths_are_refused),
        cmocka_unit_test(short_byte_stride_is_refused),
        cmocka_unit_test(lying_sparse_count_is_refused),
        cmocka_unit_test(line_loop_with_a_bad_index_does_not_crash),
        cmocka_unit_test(assimp_messages_get_their_cause),
        cmocka_unit_test(names_with_terminal_escapes_are_made_printable),
        cmocka_unit_test(skinned_gltf_opens_in_its_bind_pose),
    };
    return cmocka_run_group_tests(tests, make_dirs, remove_dirs);
}
