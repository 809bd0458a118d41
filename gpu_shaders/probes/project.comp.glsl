// Shade every texel of a probe and project onto L2 SH (paper 004, eq. 3): one invocation per probe,
// c_i = sum over faces and texels of L(w) Y_i(w) dw, w the texel's centre direction, dw its exact
// solid angle, L its radiance (probes/radiance.glsl).
// Output: texel (i nx + ix, iy + ny iz) rgb = coefficient i of the incoming radiance (W/m^2/sr) by
// direction of arrival (from the probe towards the surface it sees).
#include "common/sh.glsl"
#include "probes/probe.glsl"
#include "probes/radiance.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= probe_dims.x || px.y >= probe_dims.y * probe_dims.z) {
        return;
    }
    ivec3 q = ivec3(px.x, px.y % probe_dims.y, px.y / probe_dims.y);
    int p = probe_index(q);
    int n = face_texels;
    vec3 c[9];
    for (int i = 0; i < 9; ++i) {
        c[i] = vec3(0.0);
    }
    for (int face = 0; face < 6; ++face) {
        ivec2 origin = face_origin(p, face);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                ivec2 ij = ivec2(i, j);
                vec3 radiance = texel_radiance(origin + ij);
                if (all(equal(radiance, vec3(0.0)))) {
                    continue;
                }
                vec3 w = face_direction(face, texel_st(ij));
                vec3 l = radiance * texel_solid_angle(ij);
                for (int k = 0; k < 9; ++k) {
                    c[k] += l * sh2_basis(k, w);
                }
            }
        }
    }
    for (int k = 0; k < 9; ++k) {
        imageStore(sh, ivec2(k * probe_dims.x + q.x, px.y), vec4(c[k], 0.0));
    }
}
