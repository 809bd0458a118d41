// Backend self-test: dst = src * scale + the cell's own coordinates, so every texel is distinct
// and a transposed or mis-strided read-back shows up.
#include "common/sh.glsl"

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p, size_cells))) {
        return;
    }
    vec4 v = texelFetch(src, p, 0) * scale + vec4(p, sh_irradiance(vec4(1.0, 0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0)));
    imageStore(dst, p, v);
}
