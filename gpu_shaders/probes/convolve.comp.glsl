// The irradiance encoding (ProbesConfig.encoding = "irradiance"): per probe a cube map of irradiance
// (W/m^2) at 6 m^2 normals, m = irradiance_texels, each texel the exact clamped-cosine integral of the
// probe's captured radiance: E(n) = sum over the probe's atlas texels t of L_t max(0, n . w_t) dw_t
// (probes/radiance.glsl; w_t its centre direction, dw_t its exact solid angle). One invocation per
// irradiance texel; the irradiance atlas has the capture atlas's layout with m-texel faces. No SH
// ringing: a bright patch on one side of a probe gives nothing to normals facing away from it.
#include "probes/probe.glsl"
#include "probes/radiance.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(irradiance)))) {
        return;
    }
    int m = irradiance_texels;
    ivec2 tile = px / ivec2(3 * m, 2 * m);
    int p = tile.x + tiles_per_row * tile.y;
    if (p >= probe_count()) {
        return;
    }
    ivec2 in_tile = px - tile * ivec2(3 * m, 2 * m);
    int out_face = (in_tile.x / m) + 3 * (in_tile.y / m);
    vec2 st = (vec2(in_tile - ivec2(m * (out_face % 3), m * (out_face / 3))) + 0.5) * (2.0 / float(m)) - 1.0;
    vec3 normal = face_direction(out_face, st);
    int n = face_texels;
    vec3 e = vec3(0.0);
    for (int face = 0; face < 6; ++face) {
        ivec2 origin = face_origin(p, face);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                ivec2 ij = ivec2(i, j);
                vec3 w = face_direction(face, texel_st(ij));
                float cosine = dot(normal, w);
                if (cosine <= 0.0) {
                    continue;
                }
                e += texel_radiance(origin + ij) * (cosine * texel_solid_angle(ij));
            }
        }
    }
    imageStore(irradiance, px, vec4(e, 0.0));
}
