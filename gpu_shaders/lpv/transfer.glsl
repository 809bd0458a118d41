// The LPV transfer of one propagation step along one axis (propagate.comp.glsl documents both variants;
// lpv_propagate.py computes the improved variant's uniforms m_side, m_along, m_cross). Shared by the
// propagation step and the cascades' boundary inflow (inflow.comp.glsl).
#include "common/sh.glsl"

const float FRONT_SOLID_ANGLE = 0.4006696846;
const float SIDE_SOLID_ANGLE = 0.4234313544;

// The coefficient slot of each axis in the order (1, y, z, x), as a unit vec4.
const vec4 SLOT[3] = vec4[3](vec4(0.0, 0.0, 0.0, 1.0), vec4(0.0, 1.0, 0.0, 0.0), vec4(0.0, 0.0, 1.0, 0.0));
const vec4 DC = vec4(1.0, 0.0, 0.0, 0.0);

// What neighbour A sends into B along d = sgn * e (axis `axis`, unit vector e): M_d c_A per colour.
// Written per direction with constant indices (the 6 directions are unrolled by the caller): dynamic
// indexing into a mat4 or ivec3 spills to local memory on some GPUs.
void transfer(vec4 ca, int axis, float sgn, inout vec4 acc_out) {
#ifdef IMPROVED
    // M_d c = m_side c + (1/6 - m_side) c0 e0 + (m_along - m_side) c_a e_a + sgn m_cross (c_a e0 + c0 e_a)
    vec4 slot = SLOT[axis];
    float c0 = ca.x;
    float c_a = dot(ca, slot);
    acc_out += m_side * ca + ((1.0 / 6.0 - m_side) * c0 + sgn * m_cross * c_a) * DC
               + ((m_along - m_side) * c_a + sgn * m_cross * c0) * slot;
#else
    vec3 d = vec3(0.0);
    d[axis] = sgn;
    for (int f = 0; f < 6; ++f) {
        vec3 fn = vec3(0.0);
        fn[f / 2] = (f % 2 == 0) ? 1.0 : -1.0;
        if (dot(fn, d) < -0.5) {
            continue;  // the face B shares with A
        }
        bool front = dot(fn, d) > 0.5;
        vec3 w = front ? d : normalize(d + 0.5 * fn);
        float omega = front ? FRONT_SOLID_ANGLE : SIDE_SOLID_ANGLE;
        acc_out += dot(ca, sh_basis(w)) * sh_cosine_lobe(fn) * (omega / SH_A0);
    }
#endif
}
