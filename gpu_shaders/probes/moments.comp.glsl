// Per atlas texel: the mean and mean square of the distance (m) from its probe to the surfaces seen
// over a (2 r + 1)^2 window of its own face (clamped at the face's edges), r = moment_radius texels.
// Distances are clamped at max_distance_m, and directions that see no geometry count as that: no
// receiver that reads this probe lies farther (it is within one grid cell), and an unclamped sky
// distance beside a near wall would make a variance so large that the wall stops nothing. The lookup's
// Chebyshev test reads these (DDGI's distance moments; the window makes the variance that softens the
// test at depth edges).
#include "probes/probe.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(moments)))) {
        return;
    }
    int n = face_texels;
    int p = atlas_probe(px);
    if (p >= probe_count()) {
        return;
    }
    ivec2 in_tile = px - tile_origin(p, 0, n);
    int face = (in_tile.x / n) + 3 * (in_tile.y / n);
    ivec2 origin = face_origin(p, face);
    ivec2 ij = px - origin;
    vec3 center = probe_position(probe_cell(p));
    float sum = 0.0;
    float sum_sq = 0.0;
    float count = 0.0;
    for (int dy = -moment_radius; dy <= moment_radius; ++dy) {
        for (int dx = -moment_radius; dx <= moment_radius; ++dx) {
            ivec2 q = ij + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(n)))) {
                continue;
            }
            vec4 pos = texelFetch(atlas_position, origin + q, 0);
            float d = pos.w > 0.0 ? min(distance(pos.xyz, center), max_distance_m) : max_distance_m;
            sum += d;
            sum_sq += d * d;
            count += 1.0;
        }
    }
    imageStore(moments, px, vec4(sum / count, sum_sq / count, 0.0, 0.0));
}
