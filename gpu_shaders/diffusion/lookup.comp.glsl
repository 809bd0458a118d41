// Diffusion reconstruction (diffusion_reference.lookup): at each G-buffer point, over the 8 cells whose
// centres surround it, every occupied one whose side facing the normal light can reach (cell.glsl's
// diffusion_receives) gives the irradiance of that side, flux /
// (area x h^2), weighted by its trilinear weight x |n . n_cell| and renormalised; with those weights all 0
// the trilinear weights of the occupied cells alone; with no occupied cell 0. Written as E / pi:
// Cycles' Diffuse Indirect.
#include "diffusion/cell.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(indirect);
    if (any(greaterThanEqual(px, size))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    vec3 g = (pos.xyz - grid_origin) / cell_size - 0.5;
    vec3 base = floor(g);
    vec3 frac = g - base;
    vec3 num = vec3(0.0), num_t = vec3(0.0);
    float den = 0.0, den_t = 0.0;
    for (int k = 0; k < 8; k++) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 c = ivec3(base) + o;
        if (!diffusion_inside(c)) {
            continue;
        }
        vec4 block = texelFetch(cell_block, c, 0);
        vec4 plane = texelFetch(cell_normal, c, 0);
        float dn = dot(n, plane.xyz);
        if (!diffusion_occupied(block) || !diffusion_receives(block, dn >= 0.0)) {
            continue;  // no surface, or its side facing n no light can reach (a room's edge cell)
        }
        vec3 w3 = mix(1.0 - frac, frac, vec3(o));
        // Raised by 1e-3 (diffusion_reference.LOOKUP_WEIGHT_FLOOR): at a cell's centre whose own cell
        // cannot receive (a room's corner) its neighbours, whose trilinear weights are 0, still count.
        float t = w3.x * w3.y * w3.z + 1e-3;
        vec3 flux = dn >= 0.0 ? texelFetch(flux_plus, c, 0).rgb : texelFetch(flux_minus, c, 0).rgb;
        vec3 e = flux / (max(plane.w, 1e-6) * cell_size * cell_size);
        float w = t * abs(dn);
        num += w * e;
        den += w;
        num_t += t * e;
        den_t += t;
    }
    vec3 value = den > 0.0 ? num / den : (den_t > 0.0 ? num_t / den_t : vec3(0.0));
    imageStore(indirect, px, vec4(value * 0.31830989, 1.0));
}
