// A coarse accumulation (twice the cell size, same origin, ceil(dims / 2) cells: coarse_dims) read at a
// finer cell's centre in the finer grid's units: trilinear times (h / H)^2 = 1/4 (a fine cell's
// cross-section is a quarter of a coarse one's, so of the flux passing through a coarse cell a quarter
// passes through a fine cell there; the lookup divides by h^2). Fine cell i's centre lies at coarse
// coordinate (i + 0.5) / 2 - 0.5 (coarse centres at j): corners floor of it and the next, weights
// 0.75 / 0.25, clamped to the edge. Shared by the far field (far_field_add) and the octree's merge.

vec4 upsampled(sampler3D coarse, ivec3 fine) {
    vec3 t = (vec3(fine) + 0.5) * 0.5 - 0.5;
    ivec3 i0 = ivec3(floor(t));
    vec3 f = t - vec3(i0);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 c = clamp(i0 + corner, ivec3(0), coarse_dims - 1);
        vec3 wv = mix(1.0 - f, f, vec3(corner));
        sum += (wv.x * wv.y * wv.z) * texelFetch(coarse, c, 0);
    }
    return 0.25 * sum;
}
