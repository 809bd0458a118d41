// World position (w = 1: texel covered), the surface's own interpolated normal (not flipped: Cycles
// bakes the front side) and albedo (w: how it is covered) of the texel centre; see texel.vert.glsl. A
// centre outside the triangle (conservative coverage) takes the triangle's nearest point in texel space, and its distance
// in texels becomes the depth, so where several triangles reach a texel the one containing its centre
// (depth 0), else the nearest, wins.

// Barycentrics of the point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision
// Detection 5.1.5, in 2D).
vec3 nearest_barycentrics(vec2 p, vec2 a, vec2 b, vec2 c) {
    vec2 ab = b - a;
    vec2 ac = c - a;
    vec2 ap = p - a;
    float d1 = dot(ab, ap);
    float d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return vec3(1.0, 0.0, 0.0);
    }
    vec2 bp = p - b;
    float d3 = dot(ab, bp);
    float d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return vec3(0.0, 1.0, 0.0);
    }
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        float t = d1 / (d1 - d3);
        return vec3(1.0 - t, t, 0.0);
    }
    vec2 cp = p - c;
    float d5 = dot(ab, cp);
    float d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return vec3(0.0, 0.0, 1.0);
    }
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        float t = d2 / (d2 - d6);
        return vec3(1.0 - t, 0.0, t);
    }
    float va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        float t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return vec3(0.0, 1.0 - t, t);
    }
    float inv = 1.0 / (va + vb + vc);
    return vec3(1.0 - (vb + vc) * inv, vb * inv, vc * inv);
}

void main() {
    if (any(lessThan(gl_FragCoord.xy, v_bbox.xy)) || any(greaterThan(gl_FragCoord.xy, v_bbox.zw))) {
        discard;
    }
    vec3 l = v_bary;  // exact (affine) inside the triangle
    float dist = 0.0;
    if (any(lessThan(l, vec3(0.0)))) {
        l = nearest_barycentrics(gl_FragCoord.xy, v_t0, v_t1, v_t2);
        dist = length(gl_FragCoord.xy - (l.x * v_t0 + l.y * v_t1 + l.z * v_t2));
    }
    gl_FragDepth = clamp(dist * 0.25, 0.0, 1.0);
    vec3 n = l.x * v_n0 + l.y * v_n1 + l.z * v_n2;
    float len_n = length(n);
    out_position = vec4(l.x * v_p0 + l.y * v_p1 + l.z * v_p2, 1.0);
    out_normal = vec4(len_n > 0.0 ? n / len_n : vec3(0.0, 0.0, 1.0), 0.0);
    // alpha: covered, by its centre (1) or only touched (CONSERVATIVE_COVERAGE): a supersampled bake
    // averages the sub-texels whose centres the surface covers (lightmap.block_mean). Undilated, every
    // fragment's centre is covered (the rasterizer's rule), rounding aside: the count adds 1 per triangle.
    out_albedo = vec4(v_albedo, dilate > 0.0 && dist > 0.0 ? CONSERVATIVE_COVERAGE : 1.0);
}
