// One diffusion step, gather form (diffusion_reference.step; Mavridis et al., seeds 000). Each
// neighbour's raw flux through the face it shares with this cell (cone: its field's flux through the
// face's cone, the paper's transfer; DIRECTIONAL: the flux of M_d L, LPV's improved transfer) is clamped
// at 0, kept on its open faces and scaled so its faces carry its whole flux (`outflow`). This cell's
// surface (if any) absorbs block[axis] of each face's inflow, on the side the light travels into; the
// rest is carried on in the transfer's shape: cone, a uniform intensity over the face's cone, 3 / (2 pi)
// T_f per W (the normalisation that keeps a uniform field unchanged); DIRECTIONAL, M_d L per W of it.
// Absorbed flux (W) goes to acc_plus / acc_minus, per side of the plane (first_step: written, else
// added); FACES (the far field's grid): to acc_0..4, per face it came through, whose direction the fine
// grid's planes then sort onto their own sides (diffusion/far_field_add.comp.glsl).
// CONES (cone_fields.py): the field is one face cone's (light heading through that cube face), four
// coefficients of the L1 basis restricted to the cone; its face fluxes are cone_raw[f] . c, its flux
// cone_flux . c, and face f carries cone_moved[f] c (the cone's constants, compiled in): the
// partition of its directions over the faces (cone_fields.PARTITION_EXPONENT), the light kept in its
// cone.
#ifdef CONES
const mat4 cone_moved[6] = CONE_MOVED;
const vec4 cone_raw[6] = CONE_RAW;
const vec4 cone_flux = CONE_FLUX;
#endif
#include "diffusion/cell.glsl"
#ifdef FACES
#include "diffusion/faces.glsl"
#endif

#ifdef DIRECTIONAL
// M_d L for face f (lpv/transfer.glsl's symmetric form: M00 = 1/6, m_cross from c0 to the face axis's
// coefficient, m_along on it, m_side on the two others; the flux's row weighs the axis's coefficient by
// flux_cross, diffusion_propagate.flux_cross: exact for a Lambertian lobe's flux).
vec4 directional(vec4 c, int f) {
    int slot = (f >> 1) == 0 ? 3 : (f >> 1);  // x, y, z -> coefficient 3, 1, 2 of (1, y, z, x)
    float s = (f & 1) == 0 ? 1.0 : -1.0;
    vec4 m = m_side * c;
    m.x = c.x / 6.0 + s * flux_cross * c[slot];
    m[slot] = s * m_cross * c.x + m_along * c[slot];
    return m;
}
#endif

// The raw flux of channel c through the six faces, as two vec3 (+x +y +z, -x -y -z): both transfers'
// are k0 c0 +- k1 c_axis (cone: <L, T_d> = c0 sqrt(pi) / 3 +- c1 c_axis; directional: 2 sqrt(pi) x
// (M_d L)_0 = 2 sqrt(pi) (c0 / 6 +- flux_cross c_axis)).
#ifdef DIRECTIONAL
#define RAW_K0 (DIFFUSION_FLUX_PER_C0 / 6.0)
#define RAW_K1 (DIFFUSION_FLUX_PER_C0 * flux_cross)
#else
#define RAW_K0 DIFFUSION_CONE_C0
#define RAW_K1 DIFFUSION_CONE_C1
#endif

// Of one channel's field c: the flux sent through `face` once clamped, masked by the open faces and
// scaled to the cell's flux (returned, W); `carried` = the SH that flux arrives as (the transfer's shape
// times the flux; DIRECTIONAL: M_d c x scale plus the face's share of the residual, below).
float channel_outflow(vec4 c, vec3 open_plus, vec3 open_minus, int face, out vec4 carried) {
    vec3 along = c.wyz;  // the coefficients of x, y, z
#ifdef CONES
    vec3 raw_plus = vec3(dot(cone_raw[0], c), dot(cone_raw[2], c), dot(cone_raw[4], c));
    vec3 raw_minus = vec3(dot(cone_raw[1], c), dot(cone_raw[3], c), dot(cone_raw[5], c));
    float total = max(dot(cone_flux, c), 0.0);
#else
    vec3 raw_plus = RAW_K0 * c.x + RAW_K1 * along;
    vec3 raw_minus = RAW_K0 * c.x - RAW_K1 * along;
    float total = max(DIFFUSION_FLUX_PER_C0 * c.x, 0.0);
#endif
    vec3 plus = max(raw_plus, vec3(0.0)) * open_plus;
    vec3 minus = max(raw_minus, vec3(0.0)) * open_minus;
    float sum = dot(plus + minus, vec3(1.0));
    int axis = face >> 1;
    bool positive = (face & 1) == 0;
    float through = positive ? plus[axis] : minus[axis];
    float scale = sum > 0.0 ? total / sum : 0.0;
#ifdef CONES
    // As DIRECTIONAL's below, with the cone's matrices: the faces together carry c.
    vec3 kp = vec3(greaterThan(plus, vec3(0.0)));
    vec3 km = vec3(greaterThan(minus, vec3(0.0)));
    vec4 residual = c - (kp.x * (cone_moved[0] * c) + km.x * (cone_moved[1] * c) + kp.y * (cone_moved[2] * c)
                         + km.y * (cone_moved[3] * c) + kp.z * (cone_moved[4] * c) + km.z * (cone_moved[5] * c));
    carried = through > 0.0 && total > 0.0 ? cone_moved[face] * c + (through / sum) * residual : vec4(0.0);
#elif defined(DIRECTIONAL)
    // A face that carries light (raw > 0, open) carries M_f c, plus its share (by flux) of the residual
    // c - sum over carrying faces of M_f c: what the clamped and closed faces' M_f c held (their lobes
    // have flux <= 0 but still direction). So the faces together carry c itself and the light keeps its
    // direction; the flux is through x scale either way (diffusion_reference.carried_shapes).
    vec3 kp = vec3(greaterThan(plus, vec3(0.0)));
    vec3 km = vec3(greaterThan(minus, vec3(0.0)));
    vec3 k_axis = kp + km;
    float kept = dot(k_axis, vec3(1.0));
    vec4 residual;  // c - sum over the carrying faces of M_f c, in closed form (`directional`)
    residual.x = c.x * (1.0 - kept / 6.0) - flux_cross * dot(kp - km, along);
    residual.wyz = along * (1.0 - m_side * kept - (m_along - m_side) * k_axis) - m_cross * c.x * (kp - km);
    carried = through > 0.0 && total > 0.0 ? directional(c, face) + (through / sum) * residual : vec4(0.0);
#else
    carried = (through * scale * DIFFUSION_TRANSFER_NORM) * diffusion_cone(face);
#endif
    return through * scale;
}

// The flux neighbour i sends through `face` (per colour, W) and, per colour, the SH it arrives as.
vec3 outflow(ivec3 i, int face, out vec4 carried_r, out vec4 carried_g, out vec4 carried_b) {
    carried_r = carried_g = carried_b = vec4(0.0);
    if (!diffusion_inside(i)) {
        return vec3(0.0);
    }
    vec4 block = texelFetch(cell_block, i, 0);
    int mask = block.w <= 0.0 ? 63 : int(block.w) - 1;
    vec3 open_plus = vec3(notEqual(ivec3(mask & 1, mask & 4, mask & 16), ivec3(0)));
    vec3 open_minus = vec3(notEqual(ivec3(mask & 2, mask & 8, mask & 32), ivec3(0)));
    return vec3(channel_outflow(texelFetch(src_r, i, 0), open_plus, open_minus, face, carried_r),
                channel_outflow(texelFetch(src_g, i, 0), open_plus, open_minus, face, carried_g),
                channel_outflow(texelFetch(src_b, i, 0), open_plus, open_minus, face, carried_b));
}

// Face f's inflow into cell c: returned, the flux c's surface absorbs (per colour, W); the rest carried on.
// Called with a constant f for each face (main): the indices into vectors then fold at compile time,
// where a loop over f indexed them at run time (llvmpipe: the step took 1.3x lpv's; docs/DIFFUSION.md).
vec3 inflow(ivec3 c, int f, bool occupied, vec4 block, inout vec4 r, inout vec4 g, inout vec4 b) {
    vec3 d = diffusion_direction(f);
    vec4 carried_r, carried_g, carried_b;
    vec3 a = outflow(c - ivec3(d), f, carried_r, carried_g, carried_b);
    float absorb = occupied ? block[f >> 1] : 0.0;
    r += (1.0 - absorb) * carried_r;
    g += (1.0 - absorb) * carried_g;
    b += (1.0 - absorb) * carried_b;
    return a * absorb;
}

#ifndef FACES
// The side of the plane (normal n) that light absorbed through face f lands on: plus when it travels
// against n.
void to_sides(int f, vec3 absorbed, vec3 n, inout vec3 plus, inout vec3 minus) {
    float dn = dot(diffusion_direction(f), n);
    float to_plus = dn < -DIFFUSION_SIDE_EPSILON ? 1.0 : (dn > DIFFUSION_SIDE_EPSILON ? 0.0 : 0.5);
    plus += absorbed * to_plus;
    minus += absorbed * (1.0 - to_plus);
}
#endif

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 block = texelFetch(cell_block, c, 0);
    bool occupied = diffusion_occupied(block);
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    vec3 a0 = inflow(c, 0, occupied, block, r, g, b);
    vec3 a1 = inflow(c, 1, occupied, block, r, g, b);
    vec3 a2 = inflow(c, 2, occupied, block, r, g, b);
    vec3 a3 = inflow(c, 3, occupied, block, r, g, b);
    vec3 a4 = inflow(c, 4, occupied, block, r, g, b);
    vec3 a5 = inflow(c, 5, occupied, block, r, g, b);
    imageStore(dst_r, c, r);
    imageStore(dst_g, c, g);
    imageStore(dst_b, c, b);
#ifdef FACES
    // The flux absorbed by the face it came through (diffusion/faces.glsl packs the 18 numbers).
    vec4 p0, p1, p2, p3, p4;
    diffusion_pack_faces(a0, a1, a2, a3, a4, a5, p0, p1, p2, p3, p4);
    if (first_step == 0) {
        p0 += imageLoad(acc_0, c);
        p1 += imageLoad(acc_1, c);
        p2 += imageLoad(acc_2, c);
        p3 += imageLoad(acc_3, c);
        p4 += imageLoad(acc_4, c);
    }
    imageStore(acc_0, c, p0);
    imageStore(acc_1, c, p1);
    imageStore(acc_2, c, p2);
    imageStore(acc_3, c, p3);
    imageStore(acc_4, c, p4);
#else
    vec3 n = texelFetch(cell_normal, c, 0).xyz;
    vec3 plus = vec3(0.0), minus = vec3(0.0);
    to_sides(0, a0, n, plus, minus);
    to_sides(1, a1, n, plus, minus);
    to_sides(2, a2, n, plus, minus);
    to_sides(3, a3, n, plus, minus);
    to_sides(4, a4, n, plus, minus);
    to_sides(5, a5, n, plus, minus);
    if (first_step == 0) {
        plus += imageLoad(acc_plus, c).rgb;
        minus += imageLoad(acc_minus, c).rgb;
    }
    imageStore(acc_plus, c, vec4(plus, 0.0));
    imageStore(acc_minus, c, vec4(minus, 0.0));
#endif
}
