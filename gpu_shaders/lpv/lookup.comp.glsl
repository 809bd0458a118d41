// LPV lookup: trilinear SH (accumulated intensity, W/sr per cell) at the G-buffer position moved half a
// cell along the normal. Intensity over a cell's cross-section h^2 is radiance-like: the irradiance on
// a surface of normal n is E = max(0, c . cosine_lobe(-n)) / h^2 (the grid stores direction of travel,
// so the light arriving at the surface travels along -n). Output: E / pi (Cycles' Diffuse Indirect),
// written, or with ACCUMULATE added to what `indirect` holds.
#include "common/sh.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    vec3 g = (pos.xyz + (lookup_offset_cells * cell_size) * n - grid_origin) / cell_size;
    vec3 uvw = g / vec3(dims);  // texel centres at (i + 0.5) / dims: linear filtering is trilinear SH
    vec4 lobe = sh_cosine_lobe(-n);
    vec3 e = vec3(max(dot(texture(acc_r, uvw), lobe), 0.0),
                  max(dot(texture(acc_g, uvw), lobe), 0.0),
                  max(dot(texture(acc_b, uvw), lobe), 0.0));
    vec3 out_e = e / (cell_size * cell_size * SH_A0);
#ifdef ACCUMULATE
    // One bounce's volume added to the earlier bounces' image: each bounce is clamped on its own, so a
    // later bounce's negative L1 ringing cannot take light away from an earlier one.
    out_e += imageLoad(indirect, px).rgb;
#endif
    imageStore(indirect, px, vec4(out_e, 1.0));
}
