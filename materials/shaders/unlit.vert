#version 450
#extension GL_GOOGLE_include_directive : require
// unlit.vert — flat colour: DiffuseColor, times a vertex colour with VERTEX_COLOR.
//
// Variants:
//   SCREEN_SPACE  positions are in pixels (origin top-left, y down), moved by
//                 WorldMatrix (identity for plain overlay text) and mapped to
//                 clip space with ScreenSize; no camera. Used by the overlay.
//   VERTEX_COLOR  location 3 carries an rgba colour (e.g. R8G8B8A8_UNORM from
//                 stb_easy_font's 16-byte vertices: vec3 position + 4 bytes).
// Without SCREEN_SPACE positions go through WorldMatrix and ViewProjMatrix
// like every 3D surface (standard layout: only location 0 is read).
#define OB_VERTEX_STAGE
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
#if defined(VERTEX_COLOR)
layout(location = 3) in vec4 inColor;
#endif

layout(location = 0) out vec4 vColor;

void main()
{
    vec4 color = DiffuseColor;
#if defined(VERTEX_COLOR)
    color *= inColor;
#endif
    vColor = color;
#if defined(SCREEN_SPACE)
    vec2 pixel = (WorldMatrix * vec4(inPosition, 1.0)).xy;
    gl_Position = vec4(pixel * ScreenSize.zw * 2.0 - 1.0, 0.0, 1.0);
#else
    gl_Position = ViewProjMatrix * (WorldMatrix * vec4(inPosition, 1.0));
#endif
}
