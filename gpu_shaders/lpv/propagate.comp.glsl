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
// GEOMETRY_VOLUME: each transfer A -> B along d is scaled by 1 - b_A s_A - b_B (1 - s_B), clamped at 0:
// b = a cell's blocking along d's axis, min(1, the area its surfaces project along it), s = the share
// of it on the transfer leaving the cell along d (0.5, or with surface offsets by where its surfaces
// lie: docs/LPV.md). blocking.comp.glsl stores b s per direction: block_plus (+x, +y, +z) and
// block_minus (-x, -y, -z); light entering B along d meets b_B (1 - s_B(d)) = b_B s_B(-d).
#include "lpv/transfer.glsl"

// Light of neighbour A = B - sgn * e_axis entering B, scaled by the geometry volume's pass-through.
// plus_b / minus_b: B's own block_plus and block_minus (fetched once per cell by main).
void gather(ivec3 b, int axis, float sgn, vec3 plus_b, vec3 minus_b, inout vec4 out_r, inout vec4 out_g,
            inout vec4 out_b) {
    ivec3 di = ivec3(0);
    di[axis] = int(sgn);
    ivec3 a = b - di;
    if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, dims))) {
        return;
    }
    float pass_through = 1.0;
#ifdef GEOMETRY_VOLUME
    // A's share on light leaving it along d, B's on light entering along d (= leaving along -d). Each
    // is <= 1, but both cells may block fully: clamp at 0.
    float leave_a = (sgn > 0.0 ? texelFetch(block_plus, a, 0) : texelFetch(block_minus, a, 0))[axis];
    float enter_b = (sgn > 0.0 ? minus_b : plus_b)[axis];
    pass_through = max(0.0, 1.0 - leave_a - enter_b);
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
    vec3 plus_b = vec3(0.0);
    vec3 minus_b = vec3(0.0);
#ifdef GEOMETRY_VOLUME
    plus_b = texelFetch(block_plus, b, 0).xyz;
    minus_b = texelFetch(block_minus, b, 0).xyz;
#endif
    gather(b, 0, 1.0, plus_b, minus_b, out_r, out_g, out_b);
    gather(b, 0, -1.0, plus_b, minus_b, out_r, out_g, out_b);
    gather(b, 1, 1.0, plus_b, minus_b, out_r, out_g, out_b);
    gather(b, 1, -1.0, plus_b, minus_b, out_r, out_g, out_b);
    gather(b, 2, 1.0, plus_b, minus_b, out_r, out_g, out_b);
    gather(b, 2, -1.0, plus_b, minus_b, out_r, out_g, out_b);
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
