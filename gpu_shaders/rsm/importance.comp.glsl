// View importance of an RSM face's blocks, step 1 of 3: for each of receivers_per_side^2 receivers spread
// over the G-buffer (pixels, or lightmap texels in a bake), the share of its light that each block of the
// strata_per_side^2 split holds, estimated from 2 x 2 texels per block and normalised to sum 1 per
// receiver; 0 everywhere for a receiver this face does not light (or no geometry): it has no say.
// Normalising per receiver gives a dim receiver the same say as a bright one: noise is judged
// relative to each pixel's light. Output: block_share (block index, receiver index).

#include "rsm/vpl.glsl"

void main() {
    ivec2 r = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(r, ivec2(receivers_per_side)))) {
        return;
    }
    int receiver = r.y * receivers_per_side + r.x;
    int blocks = strata_per_side * strata_per_side;
    ivec2 gbuf_size = textureSize(gbuf_position, 0);
    ivec2 px = min(ivec2((vec2(r) + 0.5) * vec2(gbuf_size) / float(receivers_per_side)), gbuf_size - 1);
    vec4 pos = texelFetch(gbuf_position, px, 0);
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
    ivec2 rsm_size = textureSize(rsm_flux, 0);
    vec2 block = vec2(rsm_size) / float(strata_per_side);
    float disk_share = DISK_SHARE * block.x * block.y;
    float total = 0.0;
    for (int b = 0; b < blocks; ++b) {
        vec2 corner = vec2(b % strata_per_side, b / strata_per_side) * block;
        vec3 e = vec3(0.0);
        if (pos.w != 0.0) {
            for (int q = 0; q < 4; ++q) {
                vec2 at = corner + (vec2(q % 2, q / 2) * 0.5 + 0.25) * block;
                e += vpl_light(min(ivec2(at), rsm_size - 1), pos.xyz, n, disk_share);
            }
        }
        float light = dot(e, vec3(1.0 / 3.0));
        imageStore(block_share, ivec2(b, receiver), vec4(light));
        total += light;
    }
    for (int b = 0; b < blocks; ++b) {
        float share = total > 0.0 ? imageLoad(block_share, ivec2(b, receiver)).x / total : 0.0;
        imageStore(block_share, ivec2(b, receiver), vec4(share));
    }
}
