// LPV injection: one point per RSM texel (a VPL). The VPL of flux phi (W, per colour) and normal n is a
// Lambertian emitter: radiant intensity I(w) = phi / pi * max(0, n.w) W/sr, whose L1 projection is
// phi / pi * sh_cosine_lobe(n) (integral over the sphere = 2 sqrt(pi) c0 = phi). It is moved half a
// cell along n and added to the cell containing it. This draw fills one z-layer of the SH volumes:
// points of other layers (and empty texels) are sent outside the clip volume.
#include "common/sh.glsl"

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec3 n = texelFetch(rsm_normal, t, 0).xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    vec3 g = (pos.xyz + (0.5 * cell_size) * n - grid_origin) / cell_size;
    ivec3 cell = ivec3(floor(g));
    bool inside = all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, dims));
    if (pos.w == 0.0 || !inside || cell.z != layer) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // clipped
    } else {
        gl_Position = vec4((vec2(cell.xy) + 0.5) / vec2(dims.xy) * 2.0 - 1.0, 0.0, 1.0);
    }
    vec4 lobe = sh_cosine_lobe(n) * (1.0 / SH_A0);
    v_r = phi.r * lobe;
    v_g = phi.g * lobe;
    v_b = phi.b * lobe;
}
