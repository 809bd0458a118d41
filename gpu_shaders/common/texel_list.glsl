// The texel an invocation shades. With TEXEL_LIST: entry gl_GlobalInvocationID.xy of the list
// `texel_list` (xy: a probe atlas texel, w: 1; the list's tail is 0; probe_capture.texel_list), so that
// a pass runs only where the list says (llvmpipe runs every branch of an invocation, so one that would
// return at once still costs). Else the invocation's own
// pixel of an image `size` large. False: none (past the list's end or the image's edge).
bool invocation_texel(ivec2 size, out ivec2 px) {
#ifdef TEXEL_LIST
    ivec2 entry = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(entry, textureSize(texel_list, 0)))) {
        return false;
    }
    vec4 listed = texelFetch(texel_list, entry, 0);
    px = ivec2(listed.xy);
    return listed.w != 0.0;
#else
    px = ivec2(gl_GlobalInvocationID.xy);
    return all(lessThan(px, size));
#endif
}
