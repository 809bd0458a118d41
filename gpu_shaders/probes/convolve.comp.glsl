// The irradiance encoding (ProbesConfig.encoding = "irradiance"): per probe a cube map of irradiance
// (W/m^2) at 6 m^2 normals, m = irradiance_texels, each texel the exact clamped-cosine integral of the
// probe's captured radiance: E(n) = sum over the probe's atlas texels t of L_t max(0, n . w_t) dw_t
// (probes/radiance.glsl; w_t its centre direction, dw_t its exact solid angle). No SH ringing: a bright
// patch on one side of a probe gives nothing to normals facing away from it.
//
// One work group per probe, one invocation per irradiance texel (local size 3m x 2m: the probe's tile).
// Each of the probe's 6 n^2 atlas texels is read, shaded and weighed by its solid angle once, by one
// invocation, into shared memory, CHUNK texels at a time; every invocation then sums the chunk for its
// normal. Reading and weighing a texel per product instead (3 fetches, 4 atan) made this pass 13x the
// SH projection's cost on llvmpipe.
#include "probes/probe.glsl"
#include "probes/radiance.glsl"

const int CHUNK = int(gl_WorkGroupSize.x * gl_WorkGroupSize.y);
shared vec3 chunk_light[CHUNK];      // L_t dw_t (W/m^2)
shared vec3 chunk_direction[CHUNK];  // w_t

void main() {
    int m = irradiance_texels;
    int p = int(gl_WorkGroupID.x) + tiles_per_row * int(gl_WorkGroupID.y);
    // Uniform across the group, so every invocation reaches the same barriers.
    if (p >= probe_count()) {
        return;
    }
    ivec2 in_tile = ivec2(gl_LocalInvocationID.xy);
    int out_face = (in_tile.x / m) + 3 * (in_tile.y / m);
    vec2 st = (vec2(in_tile - ivec2(m * (out_face % 3), m * (out_face / 3))) + 0.5) * (2.0 / float(m)) - 1.0;
    vec3 normal = face_direction(out_face, st);
    int n = face_texels;
    int texels = 6 * n * n;
    int lane = int(gl_LocalInvocationIndex);
    vec3 e = vec3(0.0);
    for (int first = 0; first < texels; first += CHUNK) {
        int t = first + lane;
        vec3 light = vec3(0.0);
        vec3 w = vec3(0.0);
        if (t < texels) {
            int face = t / (n * n);
            ivec2 ij = ivec2(t % n, (t / n) % n);
            w = face_direction(face, texel_st(ij));
            light = texel_radiance(face_origin(p, face) + ij) * texel_solid_angle(ij);
        }
        chunk_light[lane] = light;
        chunk_direction[lane] = w;
        barrier();
        for (int k = 0; k < CHUNK; ++k) {
            e += chunk_light[k] * max(dot(normal, chunk_direction[k]), 0.0);
        }
        barrier();
    }
    imageStore(irradiance, ivec2(gl_WorkGroupID.xy) * ivec2(3 * m, 2 * m) + in_tile, vec4(e, 0.0));
}
