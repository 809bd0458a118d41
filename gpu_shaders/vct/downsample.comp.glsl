// One pyramid level from the level below, per travel direction t: the 2x2x2 children are composited
// in pairs along t's axis, front to back as a ray travelling along -t meets them (the child further
// along t is in front): c = c_near + (1 - a_near) c_far, a = a_near + (1 - a_near) a_far. Colours
// are premultiplied, so they are not multiplied by opacity again. The four pairs are averaged (they
// share the cross-section). Children outside the level below are empty. The level below is read
// through samplers of the same textures (src_*): this dispatch writes only level `level`'s texels.
#include "vct/pyramid.glsl"

vec4 child(sampler3D src, ivec3 c) {
    ivec3 src_dims = level_dims(dims, level - 1);
    if (any(greaterThanEqual(c, src_dims))) {
        return vec4(0.0);
    }
    return texelFetch(src, c + ivec3(level_offset(dims, level - 1), 0, 0), 0);
}

vec4 over(vec4 near, vec4 far) {
    return vec4(near.rgb + (1.0 - near.a) * far.rgb, near.a + (1.0 - near.a) * far.a);
}

// axis 0, 1, 2; positive: t points along +axis (the near child has the larger coordinate).
vec4 reduce(sampler3D src, ivec3 base, int axis, bool positive) {
    vec4 sum = vec4(0.0);
    for (int u = 0; u < 2; u++) {
        for (int v = 0; v < 2; v++) {
            ivec3 lo = axis == 0 ? ivec3(0, u, v) : (axis == 1 ? ivec3(u, 0, v) : ivec3(u, v, 0));
            ivec3 hi = lo;
            hi[axis] = 1;
            vec4 a = child(src, base + lo);
            vec4 b = child(src, base + hi);
            sum += positive ? over(b, a) : over(a, b);
        }
    }
    return 0.25 * sum;
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, level_dims(dims, level)))) {
        return;
    }
    ivec3 base = 2 * c;
    ivec3 dst = c + ivec3(level_offset(dims, level), 0, 0);
    imageStore(pyr_px, dst, reduce(src_px, base, 0, true));
    imageStore(pyr_nx, dst, reduce(src_nx, base, 0, false));
    imageStore(pyr_py, dst, reduce(src_py, base, 1, true));
    imageStore(pyr_ny, dst, reduce(src_ny, base, 1, false));
    imageStore(pyr_pz, dst, reduce(src_pz, base, 2, true));
    imageStore(pyr_nz, dst, reduce(src_nz, base, 2, false));
}
