// Exact shadow rays against the triangles themselves, through the hierarchy of bvh.py: a complete binary
// tree in heap order (node i's children 2i + 1, 2i + 2), `bvh_leaves` leaves of LEAF_TRIANGLES triangles
// each. Needs the samplers bvh_nodes (node i's low and high corners at texels 2 (i % NODE_ROW) and the one
// beside it, row i / NODE_ROW) and bvh_triangles (leaf order, rsm.occluder_table's layout), the uniform
// bvh_leaves and the defines NODE_ROW, OCCLUDER_ROW and LEAF_TRIANGLES.
#include "common/ray_triangle.glsl"

vec3 bvh_corner(int t, int k) {
    return texelFetch(bvh_triangles, ivec2(3 * (t % OCCLUDER_ROW) + k, t / OCCLUDER_ROW), 0).xyz;
}

// Whether q + s w crosses any triangle for s_min < s < s_max. The tree is complete and in heap order, so
// the traversal needs no stack: from a node the ray misses (or a leaf it has tested) it climbs while the
// node is a right child (even index), then moves to the right sibling; back at the root it is done.
// `hint`: a triangle (leaf-order index) tried first, -1 for none; set to the one crossed. Neighbouring
// rays are mostly blocked by the same triangle (a room's ceiling), which then costs no traversal.
bool bvh_occluded(vec3 q, vec3 w, float s_min, float s_max, inout int hint) {
    if (hint >= 0 && ray_crosses_triangle(bvh_corner(hint, 0), bvh_corner(hint, 1), bvh_corner(hint, 2), q, w, s_min,
                                          s_max)) {
        return true;
    }
    vec3 inv = 1.0 / mix(w, vec3(1e-30), lessThan(abs(w), vec3(1e-30)));
    int first_leaf = bvh_leaves - 1;
    int i = 0;
    bool hit = false;
    bool done = false;
    while (!hit && !done) {
        ivec2 at = ivec2(2 * (i % NODE_ROW), i / NODE_ROW);
        vec3 lo = texelFetch(bvh_nodes, at, 0).xyz;
        vec3 hi = texelFetch(bvh_nodes, at + ivec2(1, 0), 0).xyz;
        vec3 t0 = (lo - q) * inv;
        vec3 t1 = (hi - q) * inv;
        vec3 near3 = min(t0, t1);
        vec3 far3 = max(t0, t1);
        float near = max(max(near3.x, near3.y), near3.z);
        float far = min(min(far3.x, far3.y), far3.z);
        // lo.x > hi.x: a node over no triangle
        bool enters = lo.x <= hi.x && near <= far && far > s_min && near < s_max;
        if (enters && i < first_leaf) {
            i = 2 * i + 1;  // its left child next
        } else {
            if (enters) {
                int first = (i - first_leaf) * LEAF_TRIANGLES;
                for (int j = first; j < first + LEAF_TRIANGLES && !hit; ++j) {
                    hit = ray_crosses_triangle(bvh_corner(j, 0), bvh_corner(j, 1), bvh_corner(j, 2), q, w, s_min,
                                               s_max);
                    hint = hit ? j : hint;
                }
            }
            while (i > 0 && i % 2 == 0) {
                i = (i - 1) / 2;
            }
            done = i == 0;
            i += 1;
        }
    }
    return hit;
}
