// target := source, texel for texel (passes/copy.py): a compute pass, as zeroing is, because a blit
// is raster work.
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(target)))) {
        return;
    }
    imageStore(target, p, texelFetch(source, p, 0));
}
