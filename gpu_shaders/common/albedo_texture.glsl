// A Base Color texture in the albedo atlas (passes/albedo_atlas.py), sampled as Cycles' Image Texture
// node samples it: `rect` = (x0, y0, w, h) of the image in atlas texels, w negative for Closest and h
// negative for Extend (w = 0: no texture).
// Closest reads the texel the UV falls in; Linear blends the four texels around it, whose centres lie at
// (i + 0.5) / w. Repeat wraps the texel indices, Extend clamps them. Done with texelFetch, so no texel of
// a neighbouring image in the atlas is ever read.
ivec2 albedo_texel_index(vec2 i, vec4 rect, bool clamp_edges) {
    vec2 size = abs(rect.zw);
    vec2 inside = clamp_edges ? clamp(i, vec2(0.0), size - 1.0) : mod(i, size);
    return ivec2(rect.xy + inside);
}

vec3 albedo_texture(sampler2D atlas, vec4 rect, vec2 uv) {
    bool clamp_edges = rect.w < 0.0;
    vec2 p = uv * abs(rect.zw);  // texel coordinates: texel i spans [i, i + 1)
    if (rect.z < 0.0) {
        return texelFetch(atlas, albedo_texel_index(floor(p), rect, clamp_edges), 0).rgb;
    }
    vec2 q = p - 0.5;
    vec2 i0 = floor(q);
    vec2 f = q - i0;
    vec3 c00 = texelFetch(atlas, albedo_texel_index(i0, rect, clamp_edges), 0).rgb;
    vec3 c10 = texelFetch(atlas, albedo_texel_index(i0 + vec2(1.0, 0.0), rect, clamp_edges), 0).rgb;
    vec3 c01 = texelFetch(atlas, albedo_texel_index(i0 + vec2(0.0, 1.0), rect, clamp_edges), 0).rgb;
    vec3 c11 = texelFetch(atlas, albedo_texel_index(i0 + vec2(1.0, 1.0), rect, clamp_edges), 0).rgb;
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}
