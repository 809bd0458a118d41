// Diffusion far field, weights (once per voxelization): per far cell and face, the total weight of the
// fine sides it shares the flux it absorbed through that face among (passes/diffusion_far_field.py;
// twin: diffusion_reference.far_weights). A far cell shares its light over the fine cells whose centres
// lie within one far cell of its own centre (4 per axis; far cell c's own are 2c - fine_shift + 0 or 1,
// diffusion_far_field.grid_for), each side by its weight for the face
// (diffusion/far_field.glsl) times the trilinear tent at its centre (0.25, 0.75, 0.75, 0.25 per axis):
// the tents of neighbouring far cells sum to 1 at every fine cell, so a plane lit evenly reads evenly
// with no steps at the far cells' borders, and the cell's sides together take exactly its flux
// (far_field_add divides by this sum). Only a far cell whose light through the face came straight from
// open space (the cell it comes from is in the grid and empty) shares it; elsewhere 0. A far cell on the
// edge where a wall meets a floor, reached only through the cells beside it, absorbs little, and its
// fine sides take their light from those neighbours' tents. Faces 0-3 in weight_0, 4-5 in weight_1.xy;
// `dims` are the far grid's.
#include "diffusion/cell.glsl"
#include "diffusion/far_field.glsl"

const float DIFFUSION_TENT[4] = float[4](0.25, 0.75, 0.75, 0.25);

float face_weight(ivec3 c, int face) {
    ivec3 from = c - ivec3(diffusion_direction(face));
    if (!diffusion_occupied(texelFetch(far_block, c, 0)) || !diffusion_inside(from)
        || diffusion_occupied(texelFetch(far_block, from, 0))) {
        return 0.0;
    }
    float sum = 0.0;
    for (int i = 0; i < 64; ++i) {
        ivec3 k = ivec3(i & 3, (i >> 2) & 3, i >> 4);
        vec2 w = diffusion_face_weights(2 * c - fine_shift - 1 + k, face, fine_dims);
        sum += DIFFUSION_TENT[k.x] * DIFFUSION_TENT[k.y] * DIFFUSION_TENT[k.z] * (w.x + w.y);
    }
    return sum;
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    imageStore(weight_0, c, vec4(face_weight(c, 0), face_weight(c, 1), face_weight(c, 2), face_weight(c, 3)));
    imageStore(weight_1, c, vec4(face_weight(c, 4), face_weight(c, 5), 0.0, 0.0));
}
