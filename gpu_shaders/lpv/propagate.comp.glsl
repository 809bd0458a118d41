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
#include "common/sh.glsl"

const float FRONT_SOLID_ANGLE = 0.4006696846;
const float SIDE_SOLID_ANGLE = 0.4234313544;

// SH coefficient order (1, y, z, x): the index of axis a's coefficient.
int coeff_of_axis(int a) {
    return a == 0 ? 3 : a;
}

float blocking(ivec3 c, vec3 d) {
#ifdef GEOMETRY_VOLUME
    vec4 nv = texelFetch(vox_normal, c, 0);
    return min(1.0, nv.w * abs(dot(nv.xyz, d)));
#else
    return 0.0;
#endif
}

void main() {
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, dims))) {
        return;
    }
    vec4 out_r = vec4(0.0);
    vec4 out_g = vec4(0.0);
    vec4 out_b = vec4(0.0);
    for (int k = 0; k < 6; ++k) {
        int axis = k / 2;
        float sgn = (k % 2 == 0) ? 1.0 : -1.0;
        ivec3 di = ivec3(0);
        di[axis] = int(sgn);
        vec3 d = vec3(di);
        ivec3 a = b - di;
        if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, dims))) {
            continue;
        }
        vec4 ca_r = texelFetch(src_r, a, 0);
        vec4 ca_g = texelFetch(src_g, a, 0);
        vec4 ca_b = texelFetch(src_b, a, 0);
        float pass_through = 1.0 - 0.5 * (blocking(a, d) + blocking(b, d));
#ifdef IMPROVED
        // M_d c: linear, so apply it per channel through a 4x4 matrix built from the symmetric form.
        int ia = coeff_of_axis(axis);
        mat4 m = mat4(0.0);  // m[col][row]
        m[0][0] = 1.0 / 6.0;
        for (int i = 1; i < 4; ++i) {
            m[i][i] = m_side;
        }
        m[ia][ia] = m_along;
        m[0][ia] = sgn * m_cross;
        m[ia][0] = sgn * m_cross;
        out_r += pass_through * (m * ca_r);
        out_g += pass_through * (m * ca_g);
        out_b += pass_through * (m * ca_b);
#else
        for (int f = 0; f < 6; ++f) {
            int faxis = f / 2;
            float fsgn = (f % 2 == 0) ? 1.0 : -1.0;
            vec3 fn = vec3(0.0);
            fn[faxis] = fsgn;
            if (dot(fn, d) < -0.5) {
                continue;  // the face B shares with A
            }
            bool front = dot(fn, d) > 0.5;
            vec3 w = front ? d : normalize(d + 0.5 * fn);
            float omega = front ? FRONT_SOLID_ANGLE : SIDE_SOLID_ANGLE;
            vec4 basis = sh_basis(w);
            vec4 lobe = sh_cosine_lobe(fn) * (pass_through * omega / SH_A0);
            out_r += dot(ca_r, basis) * lobe;
            out_g += dot(ca_g, basis) * lobe;
            out_b += dot(ca_b, basis) * lobe;
        }
#endif
    }
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
