// LPV far field, source: a coarse cell's snapshot = the sum of its 2 x 2 x 2 fine cells' snapshots
// (radiant intensity is additive: the coarse cell emits what its fine cells emit). Fine cells beyond the
// fine grid (odd dims) hold nothing. Used for bounces after the first, whose light the fine grid's
// re-injection emits; the first bounce's VPLs are injected into the coarse grid directly. Coarse cell c
// holds fine cells 2c - fine_shift + (0 or 1 per axis): lpv's far grid shares the fine grid's origin
// (shift 0); diffusion's may start one fine cell earlier on an axis (diffusion_far_field.grid_for).

vec4 children(sampler3D fine, ivec3 c) {
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 child = 2 * c - fine_shift + ivec3(k & 1, (k >> 1) & 1, k >> 2);
        if (all(greaterThanEqual(child, ivec3(0))) && all(lessThan(child, fine_dims))) {
            sum += texelFetch(fine, child, 0);
        }
    }
    return sum;
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    imageStore(sh_r, c, children(fine_r, c));
    imageStore(sh_g, c, children(fine_g, c));
    imageStore(sh_b, c, children(fine_b, c));
}
