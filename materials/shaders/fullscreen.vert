#version 450
// fullscreen.vert — one triangle covering the target, no vertex input:
// draw 3 vertices. uv (0,0) is the top-left corner in Vulkan clip space.

layout(location = 0) out vec2 vUV;

void main()
{
    vUV = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    gl_Position = vec4(vUV * 2.0 - 1.0, 0.0, 1.0);
}
