// One more diffuse bounce at the voxels: every occupied cell gathers E / pi on both sides of its
// surface (normal n; where both sides of a thin wall share the cell and n cancels, the axis of its
// largest projected area) and re-emits albedo * E / pi from each side. Premultiplied radiance leaving
// along travel direction t (as level0.comp.glsl): albedo * (E_side / pi) * projected area along t's
// axis / h^2, from the side facing t. Outputs the next bounce's level-0 colours (a unused, 0).
#include "vct/diffuse.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 albedo = texelFetch(vox_albedo, c, 0);
    vec3 proj = min(texelFetch(vox_projected, c, 0).xyz, vec3(1.0));
    vec3 e_pos = vec3(0.0);
    vec3 e_neg = vec3(0.0);
    vec3 n = texelFetch(vox_normal, c, 0).xyz;
    if (albedo.a > 0.0) {
        if (dot(n, n) < 0.25) {
            n = proj.x >= max(proj.y, proj.z) ? vec3(1.0, 0.0, 0.0)
              : (proj.y >= proj.z ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
        }
        n = normalize(n);
        vec3 p = grid_origin + (vec3(c) + 0.5) * cell_size;
        uint s = uint(c.z) ^ (uint(seed) * 131072u);
        float turn = 6.28318531 * random01(uint(c.x), uint(c.y), s);
        float jitter = random01(uint(c.x), uint(c.y), s ^ 65536u);
        float dither = random01(uint(c.x), uint(c.y), hash_u32(s ^ DITHER_STREAM));
        e_pos = albedo.rgb * gather_diffuse(p, n, turn, jitter, dither, 0, 1).rgb;
        e_neg = albedo.rgb * gather_diffuse(p, -n, turn, jitter, dither, 0, 1).rgb;
    }
    // Light leaving along +axis comes from the side whose normal has a positive component on it.
    imageStore(next_px, c, vec4((n.x >= 0.0 ? e_pos : e_neg) * proj.x, 0.0));
    imageStore(next_nx, c, vec4((n.x >= 0.0 ? e_neg : e_pos) * proj.x, 0.0));
    imageStore(next_py, c, vec4((n.y >= 0.0 ? e_pos : e_neg) * proj.y, 0.0));
    imageStore(next_ny, c, vec4((n.y >= 0.0 ? e_neg : e_pos) * proj.y, 0.0));
    imageStore(next_pz, c, vec4((n.z >= 0.0 ? e_pos : e_neg) * proj.z, 0.0));
    imageStore(next_nz, c, vec4((n.z >= 0.0 ? e_neg : e_pos) * proj.z, 0.0));
}
