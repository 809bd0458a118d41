// Running mean of a product's gathers (progressive refinement): mean += (sample - mean) * weight, with
// weight = 1 / n for the n-th sample, so after n samples `mean` is their plain average.
void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(mean)))) {
        return;
    }
    vec4 m = imageLoad(mean, px);
    imageStore(mean, px, m + (texelFetch(sample_tex, px, 0) - m) * weight);
}
