// The exact shadow tests' margins (direct/shade.comp.glsl, sky/direct.comp.glsl), in texels of the shadow
// map the test belongs to. How far the segment starts off the receiver's surface: far above fp32's
// rounding of a position (1e-7 of the scene's size, against 2e-5 for a sun's 1024-texel map), far below
// a pixel.
const float EXACT_LIFT_TEXELS = 0.02;
// Crossings nearer the start than the uniform `exact_near_texels` (texels) do not shadow: a margin for
// where the G-buffer's points come from (passes/direct_light.py, NEAR_TEXELS).

// Whether q + s w crosses the triangle (a, b, c), either side, for s_min < s < s_max (Moller and
// Trumbore's test).
bool ray_crosses_triangle(vec3 a, vec3 b, vec3 c, vec3 q, vec3 w, float s_min, float s_max) {
    vec3 e1 = b - a;
    vec3 e2 = c - a;
    vec3 h = cross(w, e2);
    float det = dot(e1, h);
    if (abs(det) <= 1e-7 * length(e1) * length(e2)) {
        return false;  // the segment runs along the triangle's plane (or it has no area): no crossing
    }
    vec3 from_a = q - a;
    float u = dot(from_a, h) / det;
    vec3 g = cross(from_a, e1);
    float v = dot(w, g) / det;
    float s_hit = dot(e2, g) / det;
    return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && s_hit > s_min && s_hit < s_max;
}
