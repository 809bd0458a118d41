// One RSM texel's light on a receiver, a Lambertian disk's (rsm/gather.comp.glsl derives it): shared by
// the gather and the view importance of its blocks (rsm/importance.comp.glsl), so both weigh a VPL the
// same way.

const float PI = 3.14159265;
// A drawn VPL's disk: this share of its block's area (gather.comp.glsl says why 1 / 16).
const float DISK_SHARE = 0.0625;

#ifdef VOXEL_VISIBILITY
// 1 if no occupied voxel lies on the segment, skipping its first and last cell: a VPL low on a wall
// sits within a cell of the floor's voxels, which would otherwise hide it from the floor it lights.
float visible(vec3 from_ws, vec3 to_ws) {
    vec3 a = (from_ws - grid_origin) / cell_size;
    vec3 b = (to_ws - grid_origin) / cell_size;
    float len = length(b - a);
    int steps = int(ceil(len * 2.0));
    for (int s = 2; s < steps - 1; ++s) {
        ivec3 c = ivec3(floor(mix(a, b, float(s) / float(steps))));
        if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, grid_dims))
            && texelFetch(occupancy, c, 0).a > 0.5) {
            return 0.0;
        }
    }
    return 1.0;
}
#endif

// The light of the VPL at RSM texel t on receiver x (normal n), unweighted (E, W/m^2 per texel drawn);
// its disk is `disk_share` times the texel's surfel.
vec3 vpl_light(ivec2 t, vec3 x, vec3 n, float disk_share) {
    vec4 vpl_pos = texelFetch(rsm_position, t, 0);
    if (vpl_pos.w == 0.0) {
        return vec3(0.0);
    }
    vec4 vpl_normal = texelFetch(rsm_normal, t, 0);
    vec3 d = vpl_pos.xyz - x;
    float r2 = dot(d, d);
    vec3 w = d * inversesqrt(max(r2, 1e-20));
    float cos_x = dot(n, w);
    float cos_vpl = -dot(vpl_normal.xyz, w);
    if (cos_x <= 0.0 || cos_vpl <= 0.0) {
        return vec3(0.0);
    }
    float disk_m2 = disk_share * vpl_normal.w;
#ifdef VOXEL_VISIBILITY
    float offset_m = offset_cells * cell_size;
    if (visible(x + n * offset_m, vpl_pos.xyz + vpl_normal.xyz * offset_m) == 0.0) {
        return vec3(0.0);
    }
#endif
    return texelFetch(rsm_flux, t, 0).rgb * (cos_x * cos_vpl / (PI * (r2 + disk_m2 / PI)));
}
