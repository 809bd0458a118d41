// The diffusion transport's cells and face cones (addon/engine/diffusion_reference.py is the twin).
// Faces f = 0..5 are +x -x +y -y +z -z. cell_block (diffusion/cells.comp.glsl): xyz = per axis the share
// of a face's inflow the cell's surface absorbs, w = 0 for an empty cell, else 1 + the mask of the faces
// light may leave it by (bit f) and of the sides light can reach (bit 6 plus, 7 minus).

const float DIFFUSION_FLUX_PER_C0 = 3.54490770;   // 2 sqrt(pi): W per unit of c0
const float DIFFUSION_TRANSFER_NORM = 0.47746483; // 3 / (2 pi): 1 / a face cone's solid angle
const float DIFFUSION_CONE_C0 = 0.59081795;       // Y00 x 2 pi / 3
const float DIFFUSION_CONE_C1 = 0.85057855;       // Y1 x 2 sqrt(2) atan(1 / sqrt(2))
const float DIFFUSION_SIDE_EPSILON = 1e-3;

vec3 diffusion_direction(int f) {
    float s = (f & 1) == 0 ? 1.0 : -1.0;
    int axis = f >> 1;
    return axis == 0 ? vec3(s, 0.0, 0.0) : (axis == 1 ? vec3(0.0, s, 0.0) : vec3(0.0, 0.0, s));
}

// T_f, the L1 projection of the indicator of face f's cone (order 1, y, z, x).
vec4 diffusion_cone(int f) {
    vec3 d = diffusion_direction(f);
    return vec4(DIFFUSION_CONE_C0, DIFFUSION_CONE_C1 * d.y, DIFFUSION_CONE_C1 * d.z, DIFFUSION_CONE_C1 * d.x);
}

bool diffusion_occupied(vec4 block) {
    return block.w > 0.0;
}

bool diffusion_face_open(vec4 block, int f) {
    return block.w <= 0.0 || ((int(block.w) - 1) >> f & 1) != 0;
}

const int DIFFUSION_RECEIVES_PLUS = 64;
const int DIFFUSION_RECEIVES_MINUS = 128;

// Whether light can reach the plus (or minus) side of an occupied cell's plane at all.
bool diffusion_receives(vec4 block, bool plus) {
    return ((int(block.w) - 1) & (plus ? DIFFUSION_RECEIVES_PLUS : DIFFUSION_RECEIVES_MINUS)) != 0;
}

bool diffusion_inside(ivec3 c) {
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, dims));
}

// Emitter classes (DiffusionConfig.emitter_class_passes, docs/DIFFUSION.md "Emitter classes"): a side of a
// cell's plane belongs to lpv's emitter_class of its normal (its dominant signed axis, numbered as the
// faces). Light is propagated once per class, and a side takes in what every class but its own brought
// it: a surface cannot light another that faces its way, but light leaving a plane diffuses back onto it.
#include "lpv/emitter_class.glsl"
const int DIFFUSION_EVERY_CLASS = -1;
