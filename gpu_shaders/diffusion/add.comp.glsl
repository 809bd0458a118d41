// The light field's total per side: total = bounce (first) or total + bounce, flux in W. With skip_class
// >= 0 (cell.glsl's emitter classes) the sides of that class add nothing: the bounce is that class's
// propagation, whose light cannot reach them.
#include "diffusion/cell.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 p = texelFetch(bounce_plus, c, 0);
    vec4 m = texelFetch(bounce_minus, c, 0);
    if (skip_class != DIFFUSION_EVERY_CLASS) {
        vec3 n = texelFetch(cell_normal, c, 0).xyz;
        p *= float(emitter_class(n) != skip_class);
        m *= float(emitter_class(-n) != skip_class);
    }
    if (first == 0) {
        p += imageLoad(total_plus, c);
        m += imageLoad(total_minus, c);
    }
    imageStore(total_plus, c, p);
    imageStore(total_minus, c, m);
}
