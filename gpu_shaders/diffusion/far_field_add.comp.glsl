// Diffusion far field, add: the light the far grid's surfaces absorbed, by the face it came through
// (far_0..4, diffusion/faces.glsl), shared onto the fine cells' sides and added to the fine grid's
// absorbed flux (passes/diffusion_far_field.py; twin: diffusion_reference.far_add). Light through face f
// travels along its direction d, so the fine planes sort it onto their own sides as a fine step would:
// a far cell holding a wall and the floor of the room behind it gives the wall's lit side what reached
// the wall. A fine side takes, from each of the 8 far cells around its centre that share light through f
// (far_field_weights), its weight for f (diffusion/far_field.glsl) x the trilinear tent x that cell's
// flux / its weights' sum. `dims` are the fine grid's, `far_dims` the far grid's, which starts
// fine_shift fine cells before it (diffusion_far_field.grid_for).
#include "diffusion/cell.glsl"
#include "diffusion/faces.glsl"
#include "diffusion/far_field.glsl"

float far_weight(ivec3 j, int face) {
    return face < 4 ? texelFetch(weight_0, j, 0)[face] : texelFetch(weight_1, j, 0)[face - 4];
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims)) || !diffusion_occupied(texelFetch(cell_block, c, 0))) {
        return;
    }
    vec2 own[6];
    bool any_side = false;
    for (int face = 0; face < 6; ++face) {
        own[face] = diffusion_face_weights(c, face, dims);
        any_side = any_side || own[face].x + own[face].y > 0.0;
    }
    if (!any_side) {
        return;
    }
    vec3 at = (vec3(c + fine_shift) + 0.5) * 0.5 - 0.5;  // the fine cell's centre in far cells
    ivec3 base = ivec3(floor(at));
    vec3 t = at - vec3(base);
    vec3 plus = vec3(0.0), minus = vec3(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 j = base + corner;
        if (any(lessThan(j, ivec3(0))) || any(greaterThanEqual(j, far_dims))) {
            continue;
        }
        vec3 w3 = mix(1.0 - t, t, vec3(corner));
        float tent = w3.x * w3.y * w3.z;
        vec4 p0 = texelFetch(far_0, j, 0), p1 = texelFetch(far_1, j, 0), p2 = texelFetch(far_2, j, 0);
        vec4 p3 = texelFetch(far_3, j, 0), p4 = texelFetch(far_4, j, 0);
        for (int face = 0; face < 6; ++face) {
            float total = far_weight(j, face);
            if (total > 0.0 && own[face].x + own[face].y > 0.0) {
                vec3 per_weight = tent * diffusion_unpack_face(face, p0, p1, p2, p3, p4) / total;
                plus += own[face].x * per_weight;
                minus += own[face].y * per_weight;
            }
        }
    }
    imageStore(acc_plus, c, imageLoad(acc_plus, c) + vec4(plus, 0.0));
    imageStore(acc_minus, c, imageLoad(acc_minus, c) + vec4(minus, 0.0));
}
