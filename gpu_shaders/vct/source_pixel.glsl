// The G-buffer pixel a reduced-resolution gather texel q stands for (uniform scale; sampler
// gbuf_position): the centre pixel of its scale x scale block, clamped to the image. The gather samples
// there and the upsampling weighs each texel by how well that pixel matches, so both use this one.
ivec2 source_pixel(ivec2 q) {
    return min(q * scale + scale / 2, textureSize(gbuf_position, 0) - 1);
}
