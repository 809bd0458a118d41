// LPV cascades: the light that enters a finer cascade through its interior faces from the next coarser
// one (propagated first), added to the finer cascade's injected snapshot before it propagates.
// The ghost cell A = B - d just outside face cell B lies in parent cell pc (the faces are parent-cell
// aligned, ratio 2). The light that passed through A over the whole propagation is the parent's
// accumulation un-weighted, acc / step_weight + (1 - source_weight / step_weight) * S0 (improved does not
// accumulate S0), times (h / H)^2 = 1/4: a fine cell sees a quarter of a parent cell's cross-section.
// B receives what one propagation step moves from A along d, M_d G_A (transfer.glsl); what travels away
// from the finer cascade (its own light leaving it) is not moved in. The sum over the propagation is
// what matters, so entering at step 0 instead of when it arrives changes nothing once the steps cover
// the finer grid.
#include "lpv/transfer.glsl"

vec4 ghost(sampler3D acc, sampler3D s0, ivec3 pc) {
    return 0.25 * (texelFetch(acc, pc, 0) * inv_step_weight + source_keep * texelFetch(s0, pc, 0));
}

void inflow(ivec3 b, int axis, float sgn, inout vec4 out_r, inout vec4 out_g, inout vec4 out_b) {
    ivec3 di = ivec3(0);
    di[axis] = int(sgn);
    ivec3 a = b - di;
    bool open_lo = a[axis] < 0 && interior_lo[axis] != 0;
    bool open_hi = a[axis] >= dims[axis] && interior_hi[axis] != 0;
    if (!(open_lo || open_hi)) {
        return;
    }
    ivec3 pc = parent_offset + ivec3(floor((vec3(a) + 0.5) * 0.5));
    if (any(lessThan(pc, ivec3(0))) || any(greaterThanEqual(pc, parent_dims))) {
        return;  // a face on the parent's own interior face: inside both bands, the grandparent answers there
    }
    transfer(ghost(parent_acc_r, parent_s0_r, pc), axis, sgn, out_r);
    transfer(ghost(parent_acc_g, parent_s0_g, pc), axis, sgn, out_g);
    transfer(ghost(parent_acc_b, parent_s0_b, pc), axis, sgn, out_b);
}

void main() {
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, dims))) {
        return;
    }
    vec4 in_r = vec4(0.0);
    vec4 in_g = vec4(0.0);
    vec4 in_b = vec4(0.0);
    inflow(b, 0, 1.0, in_r, in_g, in_b);
    inflow(b, 0, -1.0, in_r, in_g, in_b);
    inflow(b, 1, 1.0, in_r, in_g, in_b);
    inflow(b, 1, -1.0, in_r, in_g, in_b);
    inflow(b, 2, 1.0, in_r, in_g, in_b);
    inflow(b, 2, -1.0, in_r, in_g, in_b);
    imageStore(sh_r, b, imageLoad(sh_r, b) + in_r);
    imageStore(sh_g, b, imageLoad(sh_g, b) + in_g);
    imageStore(sh_b, b, imageLoad(sh_b, b) + in_b);
}
