// Per probe face, its n x n captured texels merged into M x M quads (M = face_quads, dividing n; paper
// 001's down-sampling), one invocation per quad. A quad is whole where the surface it covers is
// continuous: at every texel corner inside it or on its border, every texel touching that corner (on
// any cube face: corner_candidates) sees geometry, and their planes (texels.comp.glsl) meet that
// corner's direction, not too near edge-on (plane_corner), within DEPTH_EDGE of each other. A whole quad (kind 1) is one light: radiance
// the solid-angle-weighted mean of its texels', corners at the mean of their candidates' distances,
// which is a function of the corner's direction alone, so quads on either side of a cube edge share
// their corners (no seams). Otherwise (kind 2) it straddles a depth edge or a hole: averaged, it would
// float between the near and the far surface, so the gather uses its texels one by one, each on its
// own plane; a quad whose texels see nothing, or bring no light, is kind 0 (skipped).
// Outputs (the capture's tile layout with M-texel faces): quad_radiance rgb (W/m^2/sr), a = kind;
// quad_corners = the four corners' distances (m) from the probe, in corner_offset order.
#include "probes/probe.glsl"
#include "gather/quad.glsl"

// Two planes that meet a corner's direction more than 10 % apart are a depth edge, not a crease: a
// crease's two planes meet the corner's direction together, and a flat surface's texels agree exactly.
const float DEPTH_EDGE = 0.1;

// Over every texel of probe p that touches corner k of face `face` (4 of them; 3 at a cube corner),
// on every face that holds that corner: the least, the greatest and the mean distance their planes
// give its direction; false where one of them sees no geometry.
bool corner_candidates(int p, int face, ivec2 k, out float lo, out float hi, out float mean) {
    int n = face_texels;
    vec3 c = corner_point(face, k, n);
    vec3 dir = normalize(c);
    lo = 1e30;
    hi = 0.0;
    float sum = 0.0;
    float count = 0.0;
    bool whole = true;
    for (int g = 0; g < 6; ++g) {
        vec3 f, r, u;
        face_frame(g, f, r, u);
        // The corner lies on face g where its coordinate along g's forward axis is 1 (exactly: the
        // cube point's components are 1 or (2k - n) / n, at most 1 - 2 / n inside a face).
        if (dot(c, f) < 1.0 - 1.0 / float(n)) {
            continue;
        }
        ivec2 kg = ivec2(round((vec2(dot(c, r), dot(c, u)) + 1.0) * (0.5 * float(n))));
        for (int dj = -1; dj <= 0; ++dj) {
            for (int di = -1; di <= 0; ++di) {
                ivec2 ij = kg + ivec2(di, dj);
                if (any(lessThan(ij, ivec2(0))) || any(greaterThanEqual(ij, ivec2(n)))) {
                    continue;
                }
                ivec2 t = face_origin(p, g) + ij;
                if (texelFetch(fine_radiance, t, 0).w == 0.0) {
                    whole = false;
                    continue;
                }
                bool clipped;
                float d = length(plane_corner(texelFetch(fine_plane, t, 0), face_direction(g, texel_st(ij)), dir,
                                              clipped));
                whole = whole && !clipped;
                lo = min(lo, d);
                hi = max(hi, d);
                sum += d;
                count += 1.0;
            }
        }
    }
    mean = count > 0.0 ? sum / count : 0.0;
    return whole && count > 0.0;
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(quad_radiance)))) {
        return;
    }
    int m = face_quads;
    int n = face_texels;
    int k = n / m;  // texels a quad side
    ivec2 tile = px / ivec2(3 * m, 2 * m);
    int p = tile.x + tiles_per_row * tile.y;
    if (p >= probe_count()) {
        imageStore(quad_radiance, px, vec4(0.0));
        imageStore(quad_corners, px, vec4(0.0));
        return;
    }
    ivec2 in_tile = px - tile * ivec2(3 * m, 2 * m);
    int face = (in_tile.x / m) + 3 * (in_tile.y / m);
    ivec2 quad = in_tile - ivec2(m * (face % 3), m * (face / 3));
    ivec2 first = quad * k;  // the quad's first texel in its face
    ivec2 origin = face_origin(p, face);

    vec3 light = vec3(0.0);
    float solid_angle = 0.0;
    bool any_geometry = false;
    for (int j = 0; j < k; ++j) {
        for (int i = 0; i < k; ++i) {
            ivec2 ij = first + ivec2(i, j);
            vec4 l = texelFetch(fine_radiance, origin + ij, 0);
            float dw = texel_solid_angle(ij);
            light += l.rgb * dw;
            solid_angle += dw;
            any_geometry = any_geometry || l.w > 0.0;
        }
    }
    if (!any_geometry || all(equal(light, vec3(0.0)))) {
        imageStore(quad_radiance, px, vec4(0.0));
        imageStore(quad_corners, px, vec4(0.0));
        return;
    }
    bool whole = true;
    vec4 corners = vec4(0.0);
    for (int b = 0; b <= k && whole; ++b) {
        for (int a = 0; a <= k && whole; ++a) {
            float lo, hi, mean;
            whole = corner_candidates(p, face, first + ivec2(a, b), lo, hi, mean) && hi - lo <= DEPTH_EDGE * lo;
            if ((a == 0 || a == k) && (b == 0 || b == k)) {
                corners[corner_of_offset(ivec2(a / k, b / k))] = mean;
            }
        }
    }
    imageStore(quad_radiance, px, vec4(light / solid_angle, whole ? 1.0 : 2.0));
    imageStore(quad_corners, px, whole ? corners : vec4(0.0));
}
