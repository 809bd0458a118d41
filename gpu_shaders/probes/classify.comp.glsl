// Per probe: the share of its sphere (by exact texel solid angle) that sees the back of a surface. A
// probe inside a closed object, or buried in a wall, sees back faces in most directions; it is switched
// off (state.x = 0) when that share exceeds backface_share, and the lookup gives it no weight.
// state = (active 0/1, back-face share, 0, 0) at (ix, iy + ny iz).
#include "probes/probe.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(state)))) {
        return;
    }
    ivec3 q = ivec3(px.x, px.y % probe_dims.y, px.y / probe_dims.y);
    int p = probe_index(q);
    int n = face_texels;
    float back = 0.0;
    for (int face = 0; face < 6; ++face) {
        ivec2 origin = face_origin(p, face);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                vec4 nrm = texelFetch(atlas_normal, origin + ivec2(i, j), 0);
                if (nrm.w < 0.0) {
                    back += texel_solid_angle(ivec2(i, j));
                }
            }
        }
    }
    float share = back / (4.0 * 3.14159265);
    // backface_share = 1 switches nothing off (fp32 sums of a share of 1 may exceed it).
    bool inside = backface_share < 1.0 && share > backface_share;
    imageStore(state, px, vec4(inside ? 0.0 : 1.0, share, 0.0, 0.0));
}
