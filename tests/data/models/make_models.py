#!/usr/bin/env python3
"""Writes the small model files tests/unit/test_model_open.c reads.

Run from anywhere: python3 tests/data/models/make_models.py. The outputs are
committed; this script says exactly what is in them (the test's expected
values come from here, not from the loader under test).
"""
import base64, json, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png(width, height, channels, pixels):
    """pixels: bytes, row-major, `channels` per texel (1 grey, 3 RGB, 4 RGBA)."""
    colour_type = {1: 0, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\0" + pixels[y * width * channels:(y + 1) * width * channels] for y in range(height))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


# Images: a 4x4 colour checker, a flat tangent-space normal map (colour), a
# grey height map (one channel) and a 2x2 RGBA image embedded as a data URI.
checker = bytes(c for y in range(4) for x in range(4) for c in ((255, 0, 0) if (x + y) % 2 else (0, 0, 255)))
write("checker.png", png(4, 4, 3, checker))
write("normal.png", png(2, 2, 3, bytes([128, 128, 255] * 4)))
write("height.png", png(2, 2, 1, bytes([0, 64, 128, 255])))
EMBEDDED_PNG = png(2, 2, 4, bytes([255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 128]))


class Buffer:
    def __init__(self):
        self.data = b""
        self.views = []
        self.accessors = []

    def add(self, fmt, values, kind, component, target=None, minmax=False):
        while len(self.data) % 4:
            self.data += b"\0"
        packed = b"".join(struct.pack("<" + fmt, *v) for v in values)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(packed)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.data += packed
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": len(values), "type": kind}
        if minmax:
            acc["min"] = [min(v[i] for v in values) for i in range(len(values[0]))]
            acc["max"] = [max(v[i] for v in values) for i in range(len(values[0]))]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def gltf_fields(self):
        uri = "data:application/octet-stream;base64," + base64.b64encode(self.data).decode()
        return {"buffers": [{"byteLength": len(self.data), "uri": uri}],
                "bufferViews": self.views, "accessors": self.accessors}


FLOAT, USHORT = 5126, 5123
# A unit quad in the XY plane facing +Z; glTF uv (0,0) is the image's top
# left, and the image stands upright seen from +Z: top of the image at +Y.
QUAD_POS = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
QUAD_UV = [(0, 1), (1, 1), (1, 0), (0, 0)]
QUAD_IDX = [(0,), (1,), (2,), (0,), (2,), (3,)]


def quad(buf, tangents=None, colors=None, indices=QUAD_IDX):
    attrs = {"POSITION": buf.add("3f", QUAD_POS, "VEC3", FLOAT, 34962, True),
             "NORMAL": buf.add("3f", [(0, 0, 1)] * 4, "VEC3", FLOAT, 34962),
             "TEXCOORD_0": buf.add("2f", QUAD_UV, "VEC2", FLOAT, 34962)}
    if tangents:
        attrs["TANGENT"] = buf.add("4f", tangents, "VEC4", FLOAT, 34962)
    if colors:
        attrs["COLOR_0"] = buf.add("4f", colors, "VEC4", FLOAT, 34962)
    return {"attributes": attrs, "indices": buf.add("H", indices, "SCALAR", USHORT, 34963)}


def triangle_gltf(extra):
    buf = Buffer()
    prim = {"attributes": {"POSITION": buf.add("3f", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], "VEC3", FLOAT, 34962, True)},
            "indices": buf.add("H", extra.pop("indices", [(0,), (1,), (2,)]), "SCALAR", USHORT, 34963)}
    if "material" in extra:
        prim["material"] = 0
        extra["materials"] = [extra.pop("material")]
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"name": "tri", "mesh": 0}], "meshes": [{"name": "tri", "primitives": [prim]}]}
    doc.update(buf.gltf_fields())
    doc.update(extra)
    return doc


def dump(name, doc):
    write(name, json.dumps(doc, indent=1).encode())


# features.gltf: hierarchy, instancing, every material field, embedded and
# external images, file tangents, COLOR_0, generated tangents.
buf = Buffer()
mesh_quad = {"name": "quad", "primitives": [
    dict(quad(buf, tangents=[(0, 1, 0, -1)] * 4,
              colors=[(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 0.5), (1, 1, 1, 1)]), material=0),
    dict(quad(buf), material=1)]}
mesh_tri = {"name": "tri", "primitives": [{"attributes": {"POSITION": buf.add(
    "3f", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], "VEC3", FLOAT, 34962, True)}, "material": 2}]}
features = {
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "scene": 0, "scenes": [{"nodes": [0, 3]}],
    "nodes": [
        {"name": "parent", "translation": [1, 2, 3], "children": [1]},
        {"name": "child", "scale": [2, 2, 2], "mesh": 0, "children": [2]},
        {"name": "grandchild", "rotation": [0, 0.7071068, 0, 0.7071068], "mesh": 0},
        {"name": "sibling", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1], "mesh": 1},
    ],
    "meshes": [mesh_quad, mesh_tri],
    "materials": [
        {"name": "masked", "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 0.8], "metallicFactor": 0.2,
                                  "roughnessFactor": 0.7, "baseColorTexture": {"index": 0},
                                  "metallicRoughnessTexture": {"index": 1}},
         "normalTexture": {"index": 0, "scale": 0.5},
         "occlusionTexture": {"index": 1, "strength": 0.25},
         "emissiveTexture": {"index": 0}, "emissiveFactor": [0.1, 0.2, 0.3]},
        {"name": "blended", "alphaMode": "BLEND",
         "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]},
         "normalTexture": {"index": 1}},
        {"name": "plain"},
    ],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
    "samplers": [{"magFilter": 9728, "minFilter": 9987, "wrapS": 33071, "wrapT": 33648}],
    "images": [{"name": "dot", "uri": "data:image/png;base64," + base64.b64encode(EMBEDDED_PNG).decode()},
               {"uri": "checker.png"}],
}
features.update(buf.gltf_fields())
dump("features.gltf", features)

required = triangle_gltf({"extensionsUsed": ["KHR_imaginary_feature", "KHR_materials_unlit"],
                          "extensionsRequired": ["KHR_imaginary_feature"]})
dump("requires_unknown.gltf", required)

# The same as a .glb: the JSON chunk, then the binary chunk (the buffer).
glb_doc = triangle_gltf({"extensionsUsed": ["KHR_imaginary_feature"],
                         "extensionsRequired": ["KHR_imaginary_feature"]})
bin_data = base64.b64decode(glb_doc["buffers"][0]["uri"].split(",", 1)[1])
glb_doc["buffers"] = [{"byteLength": len(bin_data)}]
js = json.dumps(glb_doc).encode()
js += b" " * (-len(js) % 4)
bin_data += b"\0" * (-len(bin_data) % 4)
body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bin_data), b"BIN\0") + bin_data
write("requires_unknown.glb", b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body)

dump("missing_texture.gltf", triangle_gltf({
    "material": {"name": "lost", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
    "textures": [{"source": 0}], "images": [{"uri": "does_not_exist.png"}]}))

dump("index_out_of_range.gltf", triangle_gltf({"indices": [(0,), (1,), (7,)]}))

# OBJ + .mtl: factors, a colour "bump" map (a normal map) and a grey one (a height map).
write("mtl_quad.obj", b"""mtllib mtl_quad.mtl
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
g bumpy
usemtl bumpy
f 1/1/1 2/2/1 3/3/1
g heighty
usemtl heighty
f 1/1/1 3/3/1 4/4/1
""")
write("mtl_quad.mtl", b"""newmtl bumpy
Kd 0.2 0.4 0.6
Ke 0.5 0.25 0
Ns 98
d 0.5
map_Kd checker.png
map_Bump -bm 0.75 normal.png

newmtl heighty
Kd 1 1 1
Ns 0
bump height.png
""")

# mirror.gltf: one red quad facing +Z placed twice, once through a mirroring
# node (scale x -0.5): both must face the camera (the mirrored copy's
# triangles are wound the other way by the loader).
buf = Buffer()
mirror = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "left", "translation": [-1.5, 0, 0], "scale": [-0.5, 0.5, 0.5], "mesh": 0},
              {"name": "right", "translation": [1.5, 0, 0], "scale": [0.5, 0.5, 0.5], "mesh": 0}],
    "meshes": [{"name": "quad", "primitives": [dict(quad(buf), material=0)]}],
    "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1], "metallicFactor": 0}}],
}
mirror.update(buf.gltf_fields())
dump("mirror.gltf", mirror)

# lights.gltf: KHR_lights_punctual on nodes: a point light with a range, a
# spot light aimed down (rotated -90 degrees about X: its -Z becomes -Y) and
# a directional one, over a white quad. glTF folds nothing: assimp
# multiplies colour by intensity, the loader splits them again.
buf = Buffer()
s = 0.5 ** 0.5
lights = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "lamp", "type": "point", "color": [1, 0.5, 0.25], "intensity": 4, "range": 5},
        {"name": "torch", "type": "spot", "intensity": 2,
         "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}},
        {"name": "sky", "type": "directional", "color": [0.5, 0.5, 1]}]}},
    "nodes": [{"name": "floor", "mesh": 0},
              {"name": "lamp_node", "translation": [0, 0, 2],
               "extensions": {"KHR_lights_punctual": {"light": 0}}},
              {"name": "torch_node", "translation": [1, 0, 3], "rotation": [-s, 0, 0, s],
               "extensions": {"KHR_lights_punctual": {"light": 1}}},
              {"name": "sky_node", "extensions": {"KHR_lights_punctual": {"light": 2}}}],
    "meshes": [{"name": "quad", "primitives": [dict(quad(buf), material=0)]}],
    "materials": [{"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0}}],
}
lights.update(buf.gltf_fields())
dump("lights.gltf", lights)
