// Conservative rasterization without a geometry shader (Hasselgren et al., GPU Gems 2 ch. 42): a
// vertex `a` of triangle (a, b, c) in pixel units moves its two edges outward by the pixel's
// half-extent along each edge normal and becomes their intersection. Every pixel the triangle
// touches is then covered; the caller clips the over-grown corners with the triangle's bounding box
// (grown by half a pixel) in its fragment shader.
vec2 conservative_corner(vec2 a, vec2 b, vec2 c) {
    // Outward edge normals for either winding.
    float orient = sign((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    vec2 e0 = b - a;  // edge a -> b
    vec2 e1 = a - c;  // edge c -> a
    vec2 n0 = orient * normalize(vec2(e0.y, -e0.x) + 1e-12);
    vec2 n1 = orient * normalize(vec2(e1.y, -e1.x) + 1e-12);
    // Each edge line moves by the half-pixel extent along its normal: 0.5 * (|nx| + |ny|).
    float d0 = 0.5 * (abs(n0.x) + abs(n0.y));
    float d1 = 0.5 * (abs(n1.x) + abs(n1.y));
    // Intersection of (x - a).n0 = d0 and (x - a).n1 = d1; parallel edges (degenerate) keep the vertex.
    float det = n0.x * n1.y - n0.y * n1.x;
    vec2 offset = abs(det) > 1e-6 ? vec2(d0 * n1.y - d1 * n0.y, n0.x * d1 - n1.x * d0) / det : vec2(0.0);
    // A sliver's acute corner moves ~0.7 px / sin(angle / 2) along its bisector: a short cap leaves
    // holes (measured in tests/gpu/test_voxelize.py); 1024 px keeps the direction and stops a
    // near-degenerate triangle from covering a whole viewport.
    offset *= min(1.0, 1024.0 / max(length(offset), 1e-12));
    return a + offset;
}
