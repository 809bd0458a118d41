// Diffusion far field (passes/diffusion_far_field.py), shared by far_field_density and far_field_add:
// how the fine cells share the light a far cell absorbed through one of its faces.

// Fine cell f's weights for light through face `face` (travelling along its direction d), on its (plus,
// minus) side: its surface's absorption on d's axis (cell_block) times the share that lands on that
// side (plus where d.n < 0, half each where d lies in the plane), 0 on a side no light reaches (the
// lookup never reads one), outside the fine grid (fine_dims) or in an empty cell.
vec2 diffusion_face_weights(ivec3 f, int face, ivec3 fine_dims) {
    if (any(lessThan(f, ivec3(0))) || any(greaterThanEqual(f, fine_dims))) {
        return vec2(0.0);
    }
    vec4 block = texelFetch(cell_block, f, 0);
    if (!diffusion_occupied(block)) {
        return vec2(0.0);
    }
    float dn = dot(diffusion_direction(face), texelFetch(cell_normal, f, 0).xyz);
    float to_plus = dn < -DIFFUSION_SIDE_EPSILON ? 1.0 : (dn > DIFFUSION_SIDE_EPSILON ? 0.0 : 0.5);
    vec2 reached = vec2(diffusion_receives(block, true), diffusion_receives(block, false));
    return block[face >> 1] * vec2(to_plus, 1.0 - to_plus) * reached;
}
