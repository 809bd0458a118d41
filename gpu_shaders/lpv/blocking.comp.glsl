// The geometry volume's blocking per cell, split by the side of the transfer it falls on, computed once
// per voxelization so that a propagation step reads one texel per neighbour (propagate.comp.glsl):
// block_plus[axis] = b s(+), the share of the cell's blocking on light leaving it along +axis;
// block_minus[axis] = b s(-), along -axis. b = min(1, projected area along the axis, cells^2); s = 0.5
// + sgn * (the surfaces' mean offset from the centre along the axis) clamped to 0..1 with
// SURFACE_OFFSETS, else 0.5. Light entering a cell along +axis is blocked by b (1 - s(+)) = b s(-).

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec3 b = min(texelFetch(vox_projected, c, 0).xyz, vec3(1.0));
#ifdef SURFACE_OFFSETS
    vec3 o = texelFetch(vox_offset, c, 0).xyz;
    vec3 s_plus = clamp(0.5 + o, 0.0, 1.0);
    vec3 s_minus = clamp(0.5 - o, 0.0, 1.0);
#else
    vec3 s_plus = vec3(0.5);
    vec3 s_minus = vec3(0.5);
#endif
    imageStore(block_plus, c, vec4(b * s_plus, 0.0));
    imageStore(block_minus, c, vec4(b * s_minus, 0.0));
}
