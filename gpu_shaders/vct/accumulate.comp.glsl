// sum = (first ? 0 : sum) + next, per travel direction: the later bounces' level-0 colours, summed.
void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    float keep = first != 0 ? 0.0 : 1.0;
    imageStore(sum_px, c, keep * imageLoad(sum_px, c) + texelFetch(next_px, c, 0));
    imageStore(sum_nx, c, keep * imageLoad(sum_nx, c) + texelFetch(next_nx, c, 0));
    imageStore(sum_py, c, keep * imageLoad(sum_py, c) + texelFetch(next_py, c, 0));
    imageStore(sum_ny, c, keep * imageLoad(sum_ny, c) + texelFetch(next_ny, c, 0));
    imageStore(sum_pz, c, keep * imageLoad(sum_pz, c) + texelFetch(next_pz, c, 0));
    imageStore(sum_nz, c, keep * imageLoad(sum_nz, c) + texelFetch(next_nz, c, 0));
}
