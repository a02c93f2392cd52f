#version 450
// particles.frag — a soft round sprite, premultiplied alpha.

layout(location = 0) in vec4 vColor;
layout(location = 1) in vec2 vCorner;
layout(location = 0) out vec4 outColor;

void main()
{
    float a = vColor.a * clamp(1.0 - dot(vCorner, vCorner), 0.0, 1.0);
    if (a <= 0.0) discard;
    outColor = vec4(vColor.rgb * a, a);
}
