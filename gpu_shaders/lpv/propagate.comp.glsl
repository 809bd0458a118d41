// One LPV propagation step in gather form: cell B reads its 6 face neighbours A = B - d (light of A
// travelling along d enters B), writes the new snapshot to dst_* and adds it to the accumulation.
// Cells hold L1 SH of radiant intensity (W/sr) by direction of travel; a cell's flux is 2 sqrt(pi) c0.
//
// classic (CLPV, Kaplanyan & Dachsbacher 2010): for each of B's 5 faces not facing A, the flux A sends
// through it is I_A(w_f) * omega_f (w_f: from A's centre to the face centre; omega_f = 0.4006696846 sr
// for the front face, 0.4234313544 sr for a side face), re-emitted in B as a clamped-cosine lobe
// along the face's normal (phi / pi * cosine lobe).
// IMPROVED: B receives M_d c_A, the L1 projection of I_A(w) * max(0, w.d) / |w|_1. The weights
// max(0, w.d) / |w|_1 sum to 1 over the 6 axes, so sum_d M_d = identity (flux and flux vector kept) and
// light moves on average along its own direction, w / |w|_1 cells per step; re-emission keeps the
// direction it had instead of turning it to the side faces' normals. By symmetry M_+x has only
// M00 = 1/6, M0x = Mx0 = m_cross, Mxx = m_along, Myy = Mzz = m_side (uniforms, computed in Python).
// GEOMETRY_VOLUME: each transfer A -> B along d is scaled by 1 - b_A s_A - b_B (1 - s_B): b = a cell's
// blocking along d's axis, min(1, the area its surfaces project along it, cells^2; the voxelizer's
// vox_projected: both faces of a closed wall thinner than a cell count once, where a mean normal
// cancels), s = the share of it on the transfer leaving the cell along d. SURFACE_OFFSETS: s = 0.5 +
// (the surfaces' mean offset from the cell's centre along d, cells; vox_offset), clamped to 0..1: a
// surface blocks the half-cell transfers on its own side of the centre (fully at a face, half each at
// the centre), so a VPL in front of its own surface, in the same cell, leaves unblocked, and the
// light no longer depends on how walls align with cells (docs/LPV.md). Without it s = 0.5.
#include "lpv/transfer.glsl"

// Blocking of cell c along `axis`, and the share of it on the transfer leaving c along sgn * axis.
float blocking(ivec3 c, int axis) {
#ifdef GEOMETRY_VOLUME
    return min(1.0, texelFetch(vox_projected, c, 0)[axis]);
#else
    return 0.0;
#endif
}

float leaving_share(ivec3 c, int axis, float sgn) {
#ifdef SURFACE_OFFSETS
    return clamp(0.5 + sgn * texelFetch(vox_offset, c, 0)[axis], 0.0, 1.0);
#else
    return 0.5;
#endif
}

// Light of neighbour A = B - sgn * e_axis entering B, scaled by the geometry volume's pass-through.
void gather(ivec3 b, int axis, float sgn, inout vec4 out_r, inout vec4 out_g, inout vec4 out_b) {
    ivec3 di = ivec3(0);
    di[axis] = int(sgn);
    ivec3 a = b - di;
    if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, dims))) {
        return;
    }
    float pass_through = 1.0;
#ifdef GEOMETRY_VOLUME
    // Each share is <= 1 and each blocking <= 1, but both cells may block fully: clamp at 0.
    pass_through = max(0.0, 1.0 - blocking(a, axis) * leaving_share(a, axis, sgn)
                                - blocking(b, axis) * (1.0 - leaving_share(b, axis, sgn)));
#endif
    vec4 r = vec4(0.0);
    vec4 g = vec4(0.0);
    vec4 bl = vec4(0.0);
    transfer(texelFetch(src_r, a, 0), axis, sgn, r);
    transfer(texelFetch(src_g, a, 0), axis, sgn, g);
    transfer(texelFetch(src_b, a, 0), axis, sgn, bl);
    out_r += pass_through * r;
    out_g += pass_through * g;
    out_b += pass_through * bl;
}

void main() {
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, dims))) {
        return;
    }
    vec4 out_r = vec4(0.0);
    vec4 out_g = vec4(0.0);
    vec4 out_b = vec4(0.0);
    gather(b, 0, 1.0, out_r, out_g, out_b);
    gather(b, 0, -1.0, out_r, out_g, out_b);
    gather(b, 1, 1.0, out_r, out_g, out_b);
    gather(b, 1, -1.0, out_r, out_g, out_b);
    gather(b, 2, 1.0, out_r, out_g, out_b);
    gather(b, 2, -1.0, out_r, out_g, out_b);
    imageStore(dst_r, b, out_r);
    imageStore(dst_g, b, out_g);
    imageStore(dst_b, b, out_b);
    vec4 acc_r0, acc_g0, acc_b0;
    if (first_step != 0) {
        acc_r0 = source_weight * texelFetch(src_r, b, 0);
        acc_g0 = source_weight * texelFetch(src_g, b, 0);
        acc_b0 = source_weight * texelFetch(src_b, b, 0);
    } else {
        acc_r0 = imageLoad(acc_r, b);
        acc_g0 = imageLoad(acc_g, b);
        acc_b0 = imageLoad(acc_b, b);
    }
    imageStore(acc_r, b, acc_r0 + step_weight * out_r);
    imageStore(acc_g, b, acc_g0 + step_weight * out_g);
    imageStore(acc_b, b, acc_b0 + step_weight * out_b);
}
