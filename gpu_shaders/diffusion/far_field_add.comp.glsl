// Diffusion far field, add: the flux the coarse grid absorbed (per side of a coarse cell's plane) shared
// out to the sides of its fine cells, added to the fine grid's absorbed flux (passes/diffusion_far_field.py;
// twin: diffusion_reference.far_add). A fine side takes from the coarse side its normal agrees with (as
// far_field_source.comp.glsl pairs them), in proportion to its receiving area, and only if light can
// reach it at all (the lookup never reads a side it cannot reach): share = area / max(coarse area, sum of
// the receiving areas of the fine sides paired with that coarse side), areas in fine cells^2 (a coarse
// cell^2 is 4). So the fine sides read the coarse irradiance (flux / area) where their areas agree, never
// more, and never take more than the coarse side absorbed. `dims` are the fine grid's.
#include "diffusion/cell.glsl"

// The receiving areas of fine cell f's sides paired with the coarse plus and minus sides, whose normal is
// coarse_n: (to plus, to minus); 0 for an empty cell or a side no light reaches.
vec2 paired_areas(ivec3 f, vec3 coarse_n) {
    vec4 block = texelFetch(cell_block, f, 0);
    if (!diffusion_inside(f) || !diffusion_occupied(block)) {
        return vec2(0.0);
    }
    vec4 normal = texelFetch(cell_normal, f, 0);
    vec2 own = vec2(diffusion_receives(block, true) ? normal.w : 0.0, diffusion_receives(block, false) ? normal.w : 0.0);
    return dot(normal.xyz, coarse_n) >= 0.0 ? own : own.yx;
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    ivec3 j = c / 2;
    vec4 coarse = texelFetch(coarse_normal, j, 0);
    vec2 own = paired_areas(c, coarse.xyz);
    if (own.x + own.y <= 0.0) {
        return;
    }
    vec2 paired = vec2(0.0);
    for (int k = 0; k < 8; ++k) {
        paired += paired_areas(2 * j + ivec3(k & 1, (k >> 1) & 1, k >> 2), coarse.xyz);
    }
    vec2 share = own / max(vec2(4.0 * coarse.w), paired);  // paired >= own > 0 where own > 0
    vec3 from_plus = texelFetch(far_plus, j, 0).rgb * share.x;
    vec3 from_minus = texelFetch(far_minus, j, 0).rgb * share.y;
    bool agrees = dot(texelFetch(cell_normal, c, 0).xyz, coarse.xyz) >= 0.0;
    vec3 plus = agrees ? from_plus : from_minus;
    vec3 minus = agrees ? from_minus : from_plus;
    imageStore(acc_plus, c, imageLoad(acc_plus, c) + vec4(plus, 0.0));
    imageStore(acc_minus, c, imageLoad(acc_minus, c) + vec4(minus, 0.0));
}
