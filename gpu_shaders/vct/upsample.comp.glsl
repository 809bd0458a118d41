// Edge-aware upsampling of the gather computed at 1/scale resolution (gather.comp.glsl): every pixel
// blends the 4 x 4 nearest low-resolution texels with a tent two texels wide (the bilinear tent's
// double), each weighted by how well the G-buffer pixel it was gathered at matches this pixel: normal
// agreement max(0, n.n_q)^8 and distance from this pixel's tangent plane, exp(-|n.(p_q - p)| /
// cell_size). Light does not bleed across depth or normal edges; where no neighbour matches (a thin
// feature), the nearest texel is used. The wider tent averages each pixel over 4x the gathers the
// bilinear one did, which the per-pixel cone noise needs: Cornell at 512 px, 6 cones, half resolution
// read rel_rmse_8 0.289 with the 2 x 2 bilinear, 0.256 with this (full resolution 0.201); 128 px 0.184
// -> 0.163 (docs/VCT.md).
#include "vct/source_pixel.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        imageStore(ao, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    ivec2 low_size = textureSize(low_indirect, 0);
    vec2 f = (vec2(px) + 0.5) / float(scale) - 0.5;
    ivec2 base = ivec2(floor(f));
    vec4 light = vec4(0.0);
    vec4 occlusion = vec4(0.0);
    float total = 0.0;
    for (int j = -1; j < 3; j++) {
        for (int i = -1; i < 3; i++) {
            ivec2 q = clamp(base + ivec2(i, j), ivec2(0), low_size - 1);
            ivec2 sp = source_pixel(q);
            vec4 qpos = texelFetch(gbuf_position, sp, 0);
            vec3 qn = normalize(texelFetch(gbuf_normal, sp, 0).xyz);
            vec2 reach = abs(vec2(base + ivec2(i, j)) - f) * 0.5;  // 1 at two texels from f
            float tent = max(1.0 - reach.x, 0.0) * max(1.0 - reach.y, 0.0);
            float facing = pow(max(dot(n, qn), 0.0), 8.0);
            float plane = exp(-abs(dot(n, qpos.xyz - pos.xyz)) / cell_size);
            float w = qpos.w == 0.0 ? 0.0 : tent * facing * plane;
            light += w * texelFetch(low_indirect, q, 0);
            occlusion += w * texelFetch(low_ao, q, 0);
            total += w;
        }
    }
    if (total > 1e-6) {
        imageStore(indirect, px, light / total);
        imageStore(ao, px, occlusion / total);
    } else {
        ivec2 q = clamp(ivec2(floor((vec2(px) + 0.5) / float(scale))), ivec2(0), low_size - 1);
        imageStore(indirect, px, texelFetch(low_indirect, q, 0));
        imageStore(ao, px, texelFetch(low_ao, q, 0));
    }
}
