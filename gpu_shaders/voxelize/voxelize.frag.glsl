// Writes the fragment into layer `layer` of the axis volume if the triangle's depth range over this
// pixel overlaps the layer's slab [layer, layer + 1). Additive: value x weight and weight, divided out by
// the merge. The weight approximates the surface area in the cell: a pixel is a whole cell, so a
// triangle smaller than a pixel weighs its own projected area, a larger one one pixel; / |n_w| turns
// projected area into surface area; x the share of the plane's depth range over the pixel that lies in
// this slab (a tilted surface spans two slabs per pixel: weighing each 1 gave the slab it barely
// touches a whole cell of opacity, a dark occluder in front of its lit VPLs in VCT, and the Cornell
// box's surfaces 27 % too much area).
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
    float weight = max(min(v_wrange.z, 1.0) / nw * share, 1e-6);
    out_albedo = vec4(v_albedo * weight, weight);
    out_normal = vec4(v_normal * weight, weight);
    out_emission = vec4(v_emission * weight, weight);
    out_projected = vec4(abs(v_normal) * weight, weight);
}
