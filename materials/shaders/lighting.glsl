// lighting.glsl — Blinn-Phong for one directional and four point lights, in
// camera-relative world space (the eye is at the origin).
#ifndef OB_LIGHTING_GLSL
#define OB_LIGHTING_GLSL

// Smooth window so a bounded light reaches exactly zero at its range.
float ob_point_attenuation(float dist, float range)
{
    float falloff = 1.0 / (1.0 + dist * dist);
    if (range <= 0.0) return falloff;
    float r = dist / range;
    float window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return falloff * window * window;
}

vec3 ob_blinn_phong(vec3 n, vec3 v, vec3 l, vec3 radiance, vec3 diffuse, vec4 specular)
{
    float ndotl = max(dot(n, l), 0.0);
    if (ndotl <= 0.0) return vec3(0.0);
    vec3 h = ob_safe_normalize(l + v);
    float spec = specular.w > 0.0 ? pow(max(dot(n, h), 0.0), specular.w) : 0.0;
    return radiance * (diffuse * ndotl + specular.rgb * spec);
}

vec3 ob_point_light(vec4 position, vec4 color, vec3 p, vec3 n, vec3 v,
                    vec3 diffuse, vec4 specular)
{
    if (color.w <= 0.0) return vec3(0.0);
    vec3 to_light = position.xyz - p;
    float dist = length(to_light);
    vec3 l = ob_safe_normalize(to_light);
    float att = ob_point_attenuation(dist, position.w);
    return ob_blinn_phong(n, v, l, color.rgb * color.w * att, diffuse, specular);
}

// Directional light contribution; `visibility` is the shadow term (1 = lit).
vec3 ob_directional_light(vec3 n, vec3 v, vec3 diffuse, vec4 specular, float visibility)
{
    if (LightColor.w <= 0.0) return vec3(0.0);
    vec3 l = ob_safe_normalize(LightDirection.xyz);
    return visibility * ob_blinn_phong(n, v, l, LightColor.rgb * LightColor.w, diffuse, specular);
}

vec3 ob_point_lights(vec3 p, vec3 n, vec3 v, vec3 diffuse, vec4 specular)
{
    return ob_point_light(PointLight0Position, PointLight0Color, p, n, v, diffuse, specular)
         + ob_point_light(PointLight1Position, PointLight1Color, p, n, v, diffuse, specular)
         + ob_point_light(PointLight2Position, PointLight2Color, p, n, v, diffuse, specular)
         + ob_point_light(PointLight3Position, PointLight3Color, p, n, v, diffuse, specular);
}

#endif
