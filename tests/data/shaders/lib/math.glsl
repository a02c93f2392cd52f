// Found next to its includer: "consts.glsl" lives in lib/ too.
#include "consts.glsl"

float saturate1(float x) { return clamp(x, 0.0, OB_ONE); }
