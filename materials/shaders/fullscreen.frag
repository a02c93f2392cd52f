#version 450
// fullscreen.frag — copies "SourceImage" (sampler parameter
// "SourceImageSampler") to the target: the composite pass.

layout(set = 1, binding = 0) uniform sampler2D SourceImage;

layout(location = 0) in vec2 vUV;
layout(location = 0) out vec4 outColor;

void main()
{
    outColor = texture(SourceImage, vUV);
}
