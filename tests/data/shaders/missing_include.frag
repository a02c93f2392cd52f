#version 450
// The include on line 6 does not exist; neither does the one in the inactive #ifdef.
#ifdef NEVER_DEFINED
#include "lib/also_missing.glsl"
#endif
#include "no_such_file.glsl"
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(1.0); }
