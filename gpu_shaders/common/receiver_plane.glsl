// The receiver's own plane (normal n) seen in a shadow map: its depth change per texel of offset, so that
// a filter tap is compared with the plane's depth there, not the centre's (else a surface lit at a slant
// shadows itself across the filter's disc). The map sends a world vector v to texel offsets
// (dot(row_x, v), dot(row_y, v)) x texels_per_ndc, depth along `axis`. From two tangents of the plane,
// their texel steps a, b and depth steps da, db: depth(delta) = [da db] [a b]^-1 delta. 0 where the light
// grazes the plane (it receives almost nothing there anyway).
vec2 receiver_depth_per_texel(vec3 n, vec3 row_x, vec3 row_y, vec2 texels_per_ndc, vec3 axis) {
    vec3 t1 = normalize(cross(n, abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 t2 = cross(n, t1);
    vec2 a = vec2(dot(row_x, t1), dot(row_y, t1)) * texels_per_ndc;
    vec2 b = vec2(dot(row_x, t2), dot(row_y, t2)) * texels_per_ndc;
    float da = dot(t1, axis);
    float db = dot(t2, axis);
    float det = a.x * b.y - a.y * b.x;
    return abs(det) > 1e-12 ? vec2(b.y * da - a.y * db, a.x * db - b.x * da) / det : vec2(0.0);
}
