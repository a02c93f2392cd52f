#version 450
// unlit.frag — writes the interpolated colour, premultiplied by its alpha
// (the blend state is ONE, ONE_MINUS_SRC_ALPHA).

layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;

void main()
{
    outColor = vec4(vColor.rgb * vColor.a, vColor.a);
}
