// total += one bounce's accumulation, per cell and colour (SH coefficients are linear in the light).
void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    imageStore(acc_r, c, imageLoad(acc_r, c) + texelFetch(bounce_r, c, 0));
    imageStore(acc_g, c, imageLoad(acc_g, c) + texelFetch(bounce_g, c, 0));
    imageStore(acc_b, c, imageLoad(acc_b, c) + texelFetch(bounce_b, c, 0));
}
