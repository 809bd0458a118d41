// indirect += bounce_image (rgb; alpha stays 1): one later bounce's cascade-blended lookup added to the
// earlier bounces' image. Each bounce was clamped at 0 on its own by its lookup.
void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    vec3 sum = imageLoad(indirect, px).rgb + texelFetch(bounce_image, px, 0).rgb;
    imageStore(indirect, px, vec4(sum, 1.0));
}
