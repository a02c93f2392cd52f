#version 450
layout(location = 0) out vec4 outColor;

void main()
{
    vec4 c = vec4(1.0);
    c = c * * 2.0;
    outColor = c;
}
