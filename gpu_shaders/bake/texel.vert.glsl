// Texel G-buffer for bakes: the object's triangles rasterized in UV space, one pixel per texel.
// Every vertex carries its whole triangle (uv0..2, p0..2, n0..2, the same at its three vertices) and
// its own corner index. gl_Position comes from the UV, so V = 0 is GL row 0 (the image's bottom).
// With `dilate` = 1 the triangle is grown conservatively (common/conservative.glsl); the fragment
// shader clips the over-grown corners with the triangle's bounding box; an edge texel whose centre lies
// outside the triangle takes the nearest point on it, and the depth test keeps the nearest triangle.
#include "common/conservative.glsl"

void main() {
    int k = int(corner + 0.5);
    vec2 t0 = uv0 * texel_size;
    vec2 t1 = uv1 * texel_size;
    vec2 t2 = uv2 * texel_size;
    vec2 a = k == 0 ? t0 : (k == 1 ? t1 : t2);   // this vertex
    vec2 b = k == 0 ? t1 : (k == 1 ? t2 : t0);   // next
    vec2 c = k == 0 ? t2 : (k == 1 ? t0 : t1);   // previous
    vec2 p = a;
    float area2 = (t1.x - t0.x) * (t2.y - t0.y) - (t1.y - t0.y) * (t2.x - t0.x);
    if (dilate > 0.5 && abs(area2) > 1e-12) {
        p = conservative_corner(a, b, c);
    }
    // Barycentrics of p in (t0, t1, t2): affine in p, so their linear interpolation is exact everywhere.
    vec3 bary = vec3(float(k == 0), float(k == 1), float(k == 2));
    if (abs(area2) > 1e-12) {
        float l1 = ((p.x - t0.x) * (t2.y - t0.y) - (p.y - t0.y) * (t2.x - t0.x)) / area2;
        float l2 = ((t1.x - t0.x) * (p.y - t0.y) - (t1.y - t0.y) * (p.x - t0.x)) / area2;
        bary = vec3(1.0 - l1 - l2, l1, l2);
    }
    gl_Position = vec4(p / texel_size * 2.0 - 1.0, 0.0, 1.0);
    v_bary = bary;
    v_t0 = t0;
    v_t1 = t1;
    v_t2 = t2;
    v_bbox = vec4(min(min(t0, t1), t2) - 0.5, max(max(t0, t1), t2) + 0.5);
    v_p0 = p0;
    v_p1 = p1;
    v_p2 = p2;
    v_n0 = n0;
    v_n1 = n1;
    v_n2 = n2;
    v_albedo = albedo;
}
