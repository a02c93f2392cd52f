/* ob_model_instance.c — models into the scene: materials, geometry variants
 * and the entity tree (ob_model_instance.h). */
#include "ob_model_instance.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define LOG_MODULE "model"

/* Geometry variants of one primitive: the extended layout or not. (A
 * mirroring node needs no variant of its own: the pipeline manager turns
 * the front face and the normal matrix keeps normals outward for any world
 * transform with a negative determinant.) The id range keeps room for
 * OB_MODEL_ASSETS_IDS_PER_PRIMITIVE variants. */
#define VARIANT_EXTENDED 1u
#define VARIANT_TEXCOORD1 2u   /* with VARIANT_EXTENDED: the layout with TEXCOORD1 */
#define VARIANT_COUNT OB_MODEL_ASSETS_IDS_PER_PRIMITIVE

struct ob_model_assets {
    ob_renderer *renderer;
    ob_material_library *library;
    ob_texture_cache *textures;       /* the desc's, or own_textures */
    ob_texture_cache *own_textures;   /* made here when the desc gives none */
    ob_model *model;
    char *name;
    uint32_t first_geometry_id;
    uint32_t lods;              /* desc.lods, at most OB_GEOMETRY_MAX_LODS - 1 */
    ob_material **materials;          /* per model material, NULL when no primitive uses it */
    uint8_t *material_variant;        /* per model material: the VARIANT_* layout its effects read */
    ob_geometry *(*geometry)[VARIANT_COUNT];   /* per primitive */
    uint32_t geometry_count;
};

/* ------------------------------------------------------------ materials */

bool ob_model_material_has_vertex_colors(const ob_model *model, uint32_t index)
{
    for (uint32_t p = 0; model && p < model->primitive_count; p++)
        if (model->primitives[p].material == index && model->primitives[p].mesh.colors) return true;
    return false;
}

/* One texture slot of a model material through the cache. A texture that
 * does not load is warned about by the cache (model, material, slot and
 * file) and the slot stays empty: the material falls back to its factor. */
static ob_material_texture model_texture(const ob_model_material_context *ctx,
                                         const ob_model_material *mm, const ob_model_texture *t,
                                         bool srgb, const char *slot)
{
    ob_material_texture out = {.uv_set = t->uv_set, .has_transform = t->transform.present};
    memcpy(out.transform, t->transform.uv, sizeof out.transform);
    const ob_model *model = ctx->model;
    if (t->image < 0) return out;
    if ((uint32_t)t->image >= model->image_count) {
        OB_LOG_W(LOG_MODULE, "%s: material '%s' %s names image %d of %u; drawn without it",
                 model->path, mm->name, slot, t->image, model->image_count);
        return out;
    }
    if (!ctx->textures) {
        OB_LOG_W(LOG_MODULE, "%s: material '%s' %s: no texture cache given; drawn without it",
                 model->path, mm->name, slot);
        return out;
    }
    const ob_model_image *img = &model->images[t->image];
    char context[384];
    snprintf(context, sizeof context, "%s: material '%s' %s",
             ctx->model_name ? ctx->model_name : model->path, mm->name, slot);
    ob_texture_desc d = {
        .path = img->path, .data = img->data, .size = img->size, .srgb = srgb,
        .sampling = ob_texture_sampling_from_gltf(t->sampler.mag_filter, t->sampler.min_filter,
                                                  t->sampler.wrap_s, t->sampler.wrap_t),
        .context = context};
    out.texture = ob_texture_cache_load(ctx->textures, &d, NULL);
    return out;
}

ob_material *ob_model_material_to_material(const ob_model_material_context *ctx, uint32_t index,
                                           bool *out_extended_layout, ob_result *out_result)
{
    if (out_extended_layout) *out_extended_layout = false;
    if (!ctx || !ctx->library || !ctx->model || index >= ctx->model->material_count) {
        OB_LOG_E(LOG_MODULE, "ob_model_material_to_material: %s",
                 !ctx || !ctx->library ? "no material library" : !ctx->model ? "no model"
                                                                : "material index out of range");
        if (out_result) *out_result = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    const ob_model_material *mm = &ctx->model->materials[index];
    char name[256];
    snprintf(name, sizeof name, "%s/%s", ctx->model_name ? ctx->model_name : ctx->model->path, mm->name);
    /* glTF 2 metallic-roughness, as the file gives it: factors, the five
     * texture slots (colour data sRGB, data maps UNORM) with their uv sets
     * and transforms, clearcoat, alpha mode and sidedness; vertex colours
     * when a primitive of the material has them. */
    ob_material_pbr pbr = ob_material_pbr_defaults();
    memcpy(pbr.base_color, mm->base_color, sizeof pbr.base_color);
    memcpy(pbr.emissive, mm->emissive, sizeof pbr.emissive);
    pbr.metallic = mm->metallic;
    pbr.roughness = mm->roughness;
    pbr.normal_scale = mm->normal_scale;
    pbr.occlusion_strength = mm->occlusion_strength;
    pbr.alpha_mode = mm->alpha_mode == OB_MODEL_ALPHA_MASK    ? OB_ALPHA_MASK
                     : mm->alpha_mode == OB_MODEL_ALPHA_BLEND ? OB_ALPHA_BLEND
                                                              : OB_ALPHA_OPAQUE;
    pbr.alpha_cutoff = mm->alpha_cutoff;
    pbr.double_sided = mm->double_sided;
    pbr.vertex_colors = ob_model_material_has_vertex_colors(ctx->model, index);
    pbr.base_color_texture = model_texture(ctx, mm, &mm->base_color_texture, true, "baseColorTexture");
    pbr.metallic_roughness_texture =
        model_texture(ctx, mm, &mm->metallic_roughness_texture, false, "metallicRoughnessTexture");
    pbr.normal_texture = model_texture(ctx, mm, &mm->normal_texture, false, "normalTexture");
    pbr.occlusion_texture = model_texture(ctx, mm, &mm->occlusion_texture, false, "occlusionTexture");
    pbr.emissive_texture = model_texture(ctx, mm, &mm->emissive_texture, true, "emissiveTexture");
    pbr.clearcoat = mm->clearcoat;
    pbr.clearcoat_roughness = mm->clearcoat_roughness;
    pbr.clearcoat_normal_scale = mm->clearcoat_normal_scale;
    if (mm->clearcoat > 0.0f) {   /* the textures of an absent layer are not loaded */
        pbr.clearcoat_texture = model_texture(ctx, mm, &mm->clearcoat_texture, false, "clearcoatTexture");
        pbr.clearcoat_roughness_texture =
            model_texture(ctx, mm, &mm->clearcoat_roughness_texture, false, "clearcoatRoughnessTexture");
        pbr.clearcoat_normal_texture =
            model_texture(ctx, mm, &mm->clearcoat_normal_texture, false, "clearcoatNormalTexture");
    }
    ob_material_desc desc = {.name = name, .kind = OB_MATERIAL_PBR, .pbr = pbr,
                             .casts_shadows = pbr.alpha_mode != OB_ALPHA_BLEND};
    ob_result r;
    ob_material *m = ob_material_create(ctx->library, &desc, &r);
    if (!m)
        OB_LOG_E(LOG_MODULE, "%s: material %u '%s' could not be made: %s", ctx->model->path, index,
                 mm->name, ob_result_name(r));
    else if (out_extended_layout)
        *out_extended_layout = true;   /* PBR effects read the extended layout */
    if (out_result) *out_result = m ? OB_OK : r;
    return m;
}

/* ------------------------------------------------------------ assets */

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

ob_model_assets *ob_model_assets_create(const ob_model_assets_desc *desc, ob_model *model,
                                        ob_result *out_result)
{
    ob_result r = OB_OK;
    if (!desc || !desc->renderer || !desc->materials || !model) {
        OB_LOG_E(LOG_MODULE, "ob_model_assets_create: no %s", !desc ? "desc" : !desc->renderer ? "renderer"
                 : !desc->materials ? "material library" : "model");
        ob_model_close(model);
        if (out_result) *out_result = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    ob_model_assets *a = ob_calloc(1, sizeof *a);
    if (!a) {
        OB_LOG_E(LOG_MODULE, "%s: out of memory for the model's assets", model->path);
        ob_model_close(model);
        if (out_result) *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
        return NULL;
    }
    a->renderer = desc->renderer;
    a->library = desc->materials;
    a->textures = desc->textures;
    a->model = model;
    a->first_geometry_id = desc->first_geometry_id;
    a->lods = OB_MIN(desc->lods, OB_GEOMETRY_MAX_LODS - 1);
    a->name = ob_strdup(desc->name ? desc->name : base_name(model->path));
    a->materials = ob_calloc(model->material_count, sizeof *a->materials);
    a->material_variant = ob_calloc(model->material_count, sizeof *a->material_variant);
    a->geometry = ob_calloc(model->primitive_count, sizeof *a->geometry);
    if (!a->name || !a->materials || !a->material_variant || !a->geometry) {
        OB_LOG_E(LOG_MODULE, "%s: out of memory for the model's assets", model->path);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_destroy_assets;
    }
    if (!a->textures && model->image_count > 0) {
        a->own_textures = ob_texture_cache_create(ob_renderer_device(a->renderer), &r);
        if (!a->own_textures) {
            OB_LOG_E(LOG_MODULE, "%s: no texture cache: %s", model->path, ob_result_name(r));
            goto fail_destroy_assets;
        }
        a->textures = a->own_textures;
    }
    /* One material per model material a primitive uses, in material order. */
    ob_model_material_context ctx = {.library = a->library, .textures = a->textures, .model = model,
                                     .model_name = a->name};
    for (uint32_t m = 0; m < model->material_count; m++) {
        bool used = false;
        for (uint32_t p = 0; p < model->primitive_count && !used; p++)
            used = model->primitives[p].material == m;
        if (!used) continue;
        bool extended;
        a->materials[m] = ob_model_material_to_material(&ctx, m, &extended, &r);
        if (!a->materials[m]) goto fail_destroy_assets;
        a->material_variant[m] = (uint8_t)((extended ? VARIANT_EXTENDED : 0u) |
                                           (ob_material_reads_texcoord1(a->materials[m]) ? VARIANT_TEXCOORD1 : 0u));
    }
    if (out_result) *out_result = OB_OK;
    return a;

fail_destroy_assets:
    ob_model_assets_destroy(a);
    if (out_result) *out_result = r;
    return NULL;
}

void ob_model_assets_destroy(ob_model_assets *a)
{
    if (!a) return;
    ob_device *dev = ob_renderer_device(a->renderer);
    for (uint32_t p = 0; a->geometry && p < a->model->primitive_count; p++)
        for (uint32_t v = 0; v < VARIANT_COUNT; v++) ob_geometry_destroy(dev, a->geometry[p][v]);
    for (uint32_t m = 0; a->materials && m < a->model->material_count; m++)
        ob_material_destroy(a->materials[m]);
    ob_texture_cache_destroy(a->own_textures);   /* after the materials that use its textures */
    ob_free(a->geometry);
    ob_free(a->materials);
    ob_free(a->material_variant);
    ob_free(a->name);
    ob_model_close(a->model);
    ob_free(a);
}

const ob_model *ob_model_assets_model(const ob_model_assets *a) { return a ? a->model : NULL; }
uint32_t ob_model_assets_geometry_count(const ob_model_assets *a) { return a ? a->geometry_count : 0; }

ob_material *ob_model_assets_material(const ob_model_assets *a, uint32_t model_material)
{
    return a && model_material < a->model->material_count ? a->materials[model_material] : NULL;
}

/* Primitive p's geometry in one variant, uploaded on first need. */
static ob_geometry *variant(ob_model_assets *a, uint32_t p, uint32_t v, ob_result *out_result)
{
    if (a->geometry[p][v]) return a->geometry[p][v];
    const ob_model_primitive *prim = &a->model->primitives[p];
    ob_mesh mesh = prim->mesh;   /* shallow: the arrays stay the model's */
    if (!(v & VARIANT_EXTENDED)) mesh.tangents = NULL, mesh.colors = NULL;
    if (!(v & VARIANT_TEXCOORD1)) mesh.uv1 = NULL;   /* only a material reading it gets TEXCOORD1 */
    else if (!mesh.uv1)
        OB_LOG_W(LOG_MODULE, "%s: primitive %u '%s' has no TEXCOORD_1 but its material reads it; "
                 "TEXCOORD_0 stands in", a->model->path, p, prim->name);
    char name[160];
    snprintf(name, sizeof name, "%s/%s", a->name, prim->name);
    ob_mesh level_meshes[OB_GEOMETRY_MAX_LODS - 1] = {{0}};
    ob_geometry_lod lods[OB_GEOMETRY_MAX_LODS - 1] = {{0}};
    uint32_t levels = 0;
    if (a->lods) {
        ob_result lr = ob_geometry_make_lods(&mesh, a->lods, level_meshes, lods, &levels);
        if (lr != OB_OK)
            OB_LOG_W(LOG_MODULE, "%s: primitive %u '%s': its levels of detail could not be made "
                     "(%s); drawn at full detail", a->model->path, p, prim->name,
                     ob_result_name(lr));
        else if (levels < a->lods)
            OB_LOG_I(LOG_MODULE, "%s: primitive %u '%s': %u of the %u levels of detail asked "
                     "for (its seams and borders stay)", a->model->path, p, prim->name, levels,
                     a->lods);
    }
    ob_geometry_desc gd = {.mesh = &mesh, .name = name, .extended = (v & VARIANT_EXTENDED) != 0,
                           .texcoord1 = (v & VARIANT_TEXCOORD1) != 0,
                           .id = a->first_geometry_id ? a->first_geometry_id + p * VARIANT_COUNT + v : 0,
                           .lods = lods, .lod_count = levels};
    ob_geometry *g = ob_geometry_create(ob_renderer_device(a->renderer), &gd, out_result);
    for (uint32_t l = 0; l < levels; l++) ob_mesh_release(&level_meshes[l]);
    if (!g) {
        OB_LOG_E(LOG_MODULE, "%s: primitive %u '%s' could not be uploaded: %s", a->model->path, p,
                 prim->name, ob_result_name(*out_result));
        return NULL;
    }
    a->geometry[p][v] = g;
    a->geometry_count++;
    return g;
}

/* ------------------------------------------------------------ instances */

/* A local matrix (column-major) as position, rotation and scale. glTF
 * matrices decompose exactly (the spec rules out shear); other formats'
 * shear is dropped (the rotation is re-orthogonalized). A negative
 * determinant becomes a negative x scale. */
static void decompose(const float *m, double pos[3], double quat[4], float scale[3])
{
    double c[3][3];
    for (int k = 0; k < 3; k++) {
        pos[k] = m[12 + k];
        for (int r = 0; r < 3; r++) c[k][r] = m[k * 4 + r];
    }
    double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) -
                 c[1][0] * (c[0][1] * c[2][2] - c[0][2] * c[2][1]) +
                 c[2][0] * (c[0][1] * c[1][2] - c[0][2] * c[1][1]);
    double s[3];
    for (int k = 0; k < 3; k++) s[k] = sqrt(c[k][0] * c[k][0] + c[k][1] * c[k][1] + c[k][2] * c[k][2]);
    if (det < 0.0) s[0] = -s[0];
    for (int k = 0; k < 3; k++) scale[k] = (float)s[k];
    quat[0] = quat[1] = quat[2] = 0.0;
    quat[3] = 1.0;
    if (!(fabs(s[0]) > 1e-30 && fabs(s[1]) > 1e-30 && fabs(s[2]) > 1e-30)) return;   /* zero scale */
    /* Rotation columns, Gram-Schmidt against shear. */
    double R[3][3];
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++) R[k][r] = c[k][r] / s[k];
    double d01 = R[0][0] * R[1][0] + R[0][1] * R[1][1] + R[0][2] * R[1][2];
    for (int r = 0; r < 3; r++) R[1][r] -= d01 * R[0][r];
    double l1 = sqrt(R[1][0] * R[1][0] + R[1][1] * R[1][1] + R[1][2] * R[1][2]);
    if (!(l1 > 1e-30)) return;
    for (int r = 0; r < 3; r++) R[1][r] /= l1;
    R[2][0] = R[0][1] * R[1][2] - R[0][2] * R[1][1];
    R[2][1] = R[0][2] * R[1][0] - R[0][0] * R[1][2];
    R[2][2] = R[0][0] * R[1][1] - R[0][1] * R[1][0];
    /* Matrix (row r, column k) = R[k][r] → quaternion (x, y, z, w). */
    double m00 = R[0][0], m11 = R[1][1], m22 = R[2][2];
    double tr = m00 + m11 + m22;
    if (tr > 0.0) {
        double q = sqrt(tr + 1.0) * 2.0;
        quat[3] = 0.25 * q;
        quat[0] = (R[1][2] - R[2][1]) / q;
        quat[1] = (R[2][0] - R[0][2]) / q;
        quat[2] = (R[0][1] - R[1][0]) / q;
    } else if (m00 > m11 && m00 > m22) {
        double q = sqrt(1.0 + m00 - m11 - m22) * 2.0;
        quat[3] = (R[1][2] - R[2][1]) / q;
        quat[0] = 0.25 * q;
        quat[1] = (R[1][0] + R[0][1]) / q;
        quat[2] = (R[2][0] + R[0][2]) / q;
    } else if (m11 > m22) {
        double q = sqrt(1.0 + m11 - m00 - m22) * 2.0;
        quat[3] = (R[2][0] - R[0][2]) / q;
        quat[0] = (R[1][0] + R[0][1]) / q;
        quat[1] = 0.25 * q;
        quat[2] = (R[2][1] + R[1][2]) / q;
    } else {
        double q = sqrt(1.0 + m22 - m00 - m11) * 2.0;
        quat[3] = (R[0][1] - R[1][0]) / q;
        quat[0] = (R[2][0] + R[0][2]) / q;
        quat[1] = (R[2][1] + R[1][2]) / q;
        quat[2] = 0.25 * q;
    }
}

ob_result ob_model_assets_instantiate(ob_model_assets *a, ob_scene *scene, ob_node *root,
                                      ob_material *override, uint32_t *out_entities)
{
    if (out_entities) *out_entities = 0;
    if (!a || !scene || !root) {
        OB_LOG_E(LOG_MODULE, "ob_model_assets_instantiate: no %s", !a ? "assets" : !scene ? "scene" : "root");
        return OB_ERR_INVALID_ARGUMENT;
    }
    const ob_model *model = a->model;
    ob_node **nodes = ob_calloc(model->node_count, sizeof *nodes);
    ob_result r = OB_OK;
    uint32_t made = 0;
    if (!nodes) {
        OB_LOG_E(LOG_MODULE, "%s: out of memory instantiating %u nodes", model->path, model->node_count);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    uint32_t next_light = 0;   /* model->lights are in node order */
    for (uint32_t i = 0; i < model->node_count && r == OB_OK; i++) {
        const ob_model_node *mn = &model->nodes[i];
        ob_node *parent = mn->parent >= 0 ? nodes[mn->parent] : root;
        ob_node *n = ob_node_create(scene, parent, mn->name, &r);
        if (!n) break;
        nodes[i] = n;
        made++;
        double pos[3], quat[4];
        float scale[3];
        decompose(mn->local, pos, quat, scale);
        ob_node_set_position(n, pos);
        ob_node_set_rotation_d(n, quat);
        ob_node_set_scale(n, scale);
        /* A glTF light sits on its node: the node's origin and -Z. */
        for (; next_light < model->light_count && model->lights[next_light].node == i; next_light++)
            if ((r = ob_node_set_light(n, &model->lights[next_light].desc)) != OB_OK) break;
        if (r != OB_OK) break;
        for (uint32_t k = 0; k < mn->primitive_count && r == OB_OK; k++) {
            uint32_t p = mn->primitives[k];
            uint32_t mat = model->primitives[p].material;
            uint32_t v = override ? 0u : a->material_variant[mat];
            ob_geometry *g = variant(a, p, v, &r);
            if (!g) break;
            ob_node *e = ob_node_create(scene, n, model->primitives[p].name, &r);
            if (!e) break;
            made++;
            const ob_bounds *b = ob_geometry_bounds(g);
            ob_renderable rd = {.material = override ? override : a->materials[mat], .geometry = g,
                                .local_radius = b->radius};
            memcpy(rd.local_center, b->center, sizeof rd.local_center);
            r = ob_node_set_renderable(e, &rd);
        }
    }
    if (r != OB_OK) {
        OB_LOG_E(LOG_MODULE, "%s: instance under '%s' failed after %u entities: %s", model->path,
                 ob_node_name(root), made, ob_result_name(r));
        /* Roots of the model's subtrees: destroying them takes the rest. */
        for (uint32_t i = model->node_count; i-- > 0;)
            if (nodes[i] && model->nodes[i].parent < 0) ob_node_destroy(nodes[i]);
        made = 0;
    }
done:
    ob_free(nodes);
    if (out_entities) *out_entities = made;
    return r;
}
