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
// GEOMETRY_VOLUME: each transfer A -> B is scaled by 1 - blocking, blocking = mean over A and B of
// min(1, surface area in the cell (cells^2) * |n . d|) from the voxelizer's vox_normal.
#include "lpv/transfer.glsl"

// Blocking of cell c for travel along the axis with unit vector e: nv = the cell's vox_normal.
float blocking(vec4 nv, vec3 e) {
#ifdef GEOMETRY_VOLUME
    return min(1.0, nv.w * abs(dot(nv.xyz, e)));
#else
    return 0.0;
#endif
}

vec4 vox_at(ivec3 c) {
#ifdef GEOMETRY_VOLUME
    return texelFetch(vox_normal, c, 0);
#else
    return vec4(0.0);
#endif
}

// Light of neighbour A = B - sgn * e_axis entering B, scaled by the geometry volume's pass-through.
void gather(ivec3 b, vec4 vox_b, int axis, float sgn, inout vec4 out_r, inout vec4 out_g, inout vec4 out_b) {
    ivec3 di = ivec3(0);
    di[axis] = int(sgn);
    ivec3 a = b - di;
    if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, dims))) {
        return;
    }
    vec3 e = vec3(di);
    float pass_through = 1.0 - 0.5 * (blocking(vox_at(a), e) + blocking(vox_b, e));
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
    vec4 vox_b = vox_at(b);
    gather(b, vox_b, 0, 1.0, out_r, out_g, out_b);
    gather(b, vox_b, 0, -1.0, out_r, out_g, out_b);
    gather(b, vox_b, 1, 1.0, out_r, out_g, out_b);
    gather(b, vox_b, 1, -1.0, out_r, out_g, out_b);
    gather(b, vox_b, 2, 1.0, out_r, out_g, out_b);
    gather(b, vox_b, 2, -1.0, out_r, out_g, out_b);
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
