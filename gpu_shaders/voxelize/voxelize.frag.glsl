// Writes the fragment into layer `layer` of the axis volume if the triangle's depth range over this
// pixel overlaps the layer's slab [layer, layer + 1). Additive: value x weight and weight, divided out by
// the merge. The weight is the surface area in the cell: the area of the triangle clipped to the pixel
// (a pixel is a whole cell; exact, by clipping the polygon to the pixel's four sides), / |n_w| to turn
// projected area into surface area, x the share of the plane's depth range over the pixel that lies in
// this slab (a tilted surface spans two slabs per pixel: weighing each 1 gave the slab it barely
// touches a whole cell of opacity, a dark occluder in front of its lit VPLs in VCT, and the Cornell
// box's surfaces 27 % too much area). Conservative rasterization also emits the pixels a triangle only
// grazes: unclipped, each would weigh a whole pixel (min(triangle area, 1)), and meshes of many small
// triangles would count every edge twice and more.

// Area (pixel units) of triangle (p0, p1, p2) inside the square [lo, lo + 1]^2: Sutherland-Hodgman
// against the four sides, then the shoelace formula. Exactly, each side adds at most one corner (7 in
// all); in fp32 a clipped polygon can come out slightly non-convex, and a side then adds more. Corners
// past CLIP_CORNERS are dropped (a sliver's worth of area): a write past a GLSL array is undefined.
const int CLIP_CORNERS = 8;

float area_in_pixel(vec2 p0, vec2 p1, vec2 p2, vec2 lo) {
    vec2 hi = lo + 1.0;
    vec2 poly[CLIP_CORNERS];
    vec2 next[CLIP_CORNERS];
    poly[0] = p0;
    poly[1] = p1;
    poly[2] = p2;
    int n = 3;
    for (int side = 0; side < 4; side++) {
        int m = 0;
        for (int i = 0; i < n; i++) {
            vec2 a = poly[i];
            vec2 b = poly[i + 1 < n ? i + 1 : 0];
            float da = side == 0 ? a.x - lo.x : (side == 1 ? hi.x - a.x : (side == 2 ? a.y - lo.y : hi.y - a.y));
            float db = side == 0 ? b.x - lo.x : (side == 1 ? hi.x - b.x : (side == 2 ? b.y - lo.y : hi.y - b.y));
            if (da >= 0.0 && m < CLIP_CORNERS) {
                next[m] = a;
                m++;
            }
            if ((da >= 0.0) != (db >= 0.0) && m < CLIP_CORNERS) {
                next[m] = a + (b - a) * (da / (da - db));
                m++;
            }
        }
        n = m;
        for (int i = 0; i < n; i++) {
            poly[i] = next[i];
        }
    }
    float twice = 0.0;
    for (int i = 0; i < n; i++) {
        vec2 a = poly[i];
        vec2 b = poly[i + 1 < n ? i + 1 : 0];
        twice += a.x * b.y - a.y * b.x;
    }
    return 0.5 * abs(twice);
}

void main() {
    vec2 uv = v_uvw.xy;
    if (any(lessThan(uv, v_bbox.xy)) || any(greaterThan(uv, v_bbox.zw))) {
        discard;
    }
    vec3 n = v_plane.xyz;
    float nw = max(abs(n.z), 1e-6);
    // Depth of the plane at the pixel centre, and its spread over the pixel footprint.
    float w = (v_plane.w - n.x * uv.x - n.y * uv.y) / (n.z == 0.0 ? 1e-6 : n.z);
    float spread = 0.5 * (abs(n.x) + abs(n.y)) / nw;
    float w0 = max(w - spread, v_wrange.x);
    float w1 = min(w + spread, v_wrange.y);
    if (w1 < float(layer) || w0 >= float(layer + 1) || w0 > w1) {
        discard;
    }
    float share = spread > 1e-6
        ? clamp((min(w + spread, float(layer + 1)) - max(w - spread, float(layer))) / (2.0 * spread), 0.0, 1.0)
        : 1.0;
    // A fragment that overlaps the slab keeps a tiny weight at least: occupancy (a > 0) stays conservative.
    float covered = area_in_pixel(v_corners01.xy, v_corners01.zw, v_corner2, floor(uv));
    float weight = max(covered / nw * share, 1e-6);
    out_albedo = vec4(v_albedo * weight, weight);
    out_normal = vec4(v_normal * weight, weight);
    // Alpha: the depth of the surface's part in this slab, from the slab's centre (cells, -0.5..0.5),
    // x weight; the merge turns it into vox_offset (where in its cell a surface lies along each axis).
    float depth = 0.5 * (max(w0, float(layer)) + min(w1, float(layer + 1)));
    out_emission = vec4(v_emission * weight, (depth - float(layer) - 0.5) * weight);
    out_projected = vec4(abs(v_normal) * weight, weight);
}
