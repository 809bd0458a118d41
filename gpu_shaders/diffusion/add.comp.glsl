// The light field's total per side: total = bounce (first) or total + bounce, flux in W.
void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 p = texelFetch(bounce_plus, c, 0);
    vec4 m = texelFetch(bounce_minus, c, 0);
    if (first == 0) {
        p += imageLoad(total_plus, c);
        m += imageLoad(total_minus, c);
    }
    imageStore(total_plus, c, p);
    imageStore(total_minus, c, m);
}
