// VCT gather at the camera's pixels: indirect = E / pi (Cycles' Diffuse Indirect units) from the
// diffuse cones about the G-buffer normal; ambient occlusion (the cosine-weighted opacity) in `ao`.
// With scale > 1 the images are 1/scale of the G-buffer's size and each texel gathers at the centre
// pixel of its scale x scale block (upsample.comp.glsl brings them back to full size).
#include "vct/diffuse.glsl"
#include "vct/source_pixel.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    ivec2 src = source_pixel(px);
    vec4 pos = texelFetch(gbuf_position, src, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        imageStore(ao, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, src, 0).xyz);
    uint s = uint(seed) * 2u;
    vec4 e = gather_diffuse(pos.xyz, n, 6.28318531 * random01(uint(px.x), uint(px.y), s),
                            random01(uint(px.x), uint(px.y), s + 1u),
                            random01(uint(px.x), uint(px.y), hash_u32(s ^ DITHER_STREAM)));
    imageStore(indirect, px, vec4(e.rgb, 1.0));
    imageStore(ao, px, vec4(vec3(1.0 - e.a), 1.0));
}
