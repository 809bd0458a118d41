// The edge-aware weights of a G-buffer neighbourhood: the denoise filter's (common/denoise.comp.glsl,
// whose header explains them), and how much of its surface it finds around a pixel (surface_support,
// for passes/surface_support.py). Needs samplers
// gbuf_position, gbuf_normal and uniforms normal_power, plane_sigma, position_sigma.

// The B3 spline (1, 4, 6, 4, 1) / 16 at tap k in -2..2; denoise.KERNEL is the same. A function, not a
// const array: Blender translates bodies for Metal and Vulkan, and no other body here uses const arrays.
float b3(int k) {
    return k == 0 ? 0.375 : (abs(k) == 1 ? 0.25 : 0.0625);
}

bool covered(ivec2 q, ivec2 size) {
    return all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size)) && texelFetch(gbuf_position, q, 0).w != 0.0;
}

// Distance (m) to the nearer covered neighbour along `axis`, or -1 where neither side is covered.
float axis_footprint(ivec2 px, vec3 p, ivec2 axis, ivec2 size) {
    float nearest = -1.0;
    for (int side = -1; side <= 1; side += 2) {
        ivec2 q = px + side * axis;
        if (covered(q, size)) {
            float d = distance(texelFetch(gbuf_position, q, 0).xyz, p);
            nearest = nearest < 0.0 ? d : min(nearest, d);
        }
    }
    return nearest;
}

// The G-buffer weight of the tap at `offset` from the pixel (position p, normal n, footprint f).
float geometry_weight(ivec2 q, ivec2 offset, vec3 p, vec3 n, float footprint) {
    vec3 d = texelFetch(gbuf_position, q, 0).xyz - p;
    float facing = pow(max(dot(n, texelFetch(gbuf_normal, q, 0).xyz), 0.0), normal_power);
    float plane = abs(dot(n, d)) / (plane_sigma * footprint);
    float expected = length(vec2(offset)) * footprint;
    float excess = max(length(d) - expected, 0.0) / (position_sigma * expected);
    return facing * exp(-(plane * plane + excess * excess));
}

// How much of the filter's 5 x 5 kernel at tap spacing `step_px` lies on the pixel's own surface: the
// B3-weighted mean of the 24 neighbours' G-buffer weights (uncovered ones 0), 1 on a flat plane facing
// the camera. Where it is small (a thin column, a leaf, a corner's last pixels) the filter has little
// to average and the pixel keeps its own gather's noise. -1 for an isolated pixel.
float surface_support(ivec2 px, vec3 p, vec3 n, int step_px) {
    ivec2 size = textureSize(gbuf_position, 0);
    float footprint = max(axis_footprint(px, p, ivec2(1, 0), size), axis_footprint(px, p, ivec2(0, 1), size));
    if (footprint <= 0.0) {
        return -1.0;
    }
    float sum = 0.0;
    for (int j = -2; j <= 2; j++) {
        for (int i = -2; i <= 2; i++) {
            ivec2 q = px + ivec2(i, j) * step_px;
            if ((i != 0 || j != 0) && covered(q, size)) {
                sum += b3(i) * b3(j) * geometry_weight(q, ivec2(i, j) * step_px, p, n, footprint);
            }
        }
    }
    return sum / (1.0 - 0.375 * 0.375);  // the kernel's weight off its centre
}
