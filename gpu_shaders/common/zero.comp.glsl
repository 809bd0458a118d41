// Zeroes IMAGES (1..6) float images of one size: 2D images whole, or with VOLUME the z-layers
// [first_layer, first_layer + layer_count) of 3D images. A compute pass instead of a framebuffer clear
// (passes/zero.py: clears are raster work, slow on compute GPUs).
void main() {
#ifdef VOLUME
    ivec3 p = ivec3(gl_GlobalInvocationID) + ivec3(0, 0, first_layer);
    if (any(greaterThanEqual(p.xy, imageSize(out0).xy)) || p.z >= first_layer + layer_count) {
        return;
    }
#else
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out0)))) {
        return;
    }
#endif
    imageStore(out0, p, vec4(0.0));
#if IMAGES > 1
    imageStore(out1, p, vec4(0.0));
#endif
#if IMAGES > 2
    imageStore(out2, p, vec4(0.0));
#endif
#if IMAGES > 3
    imageStore(out3, p, vec4(0.0));
#endif
#if IMAGES > 4
    imageStore(out4, p, vec4(0.0));
#endif
#if IMAGES > 5
    imageStore(out5, p, vec4(0.0));
#endif
}
