// One diffusion step, gather form (diffusion_reference.step; Mavridis et al., seeds 000, with the face
// transfer normalised by 3 / (2 pi)). Each neighbour's flux through the face it shares with this cell
// is its field's flux through that face's cone, clamped at 0, kept on its open faces and scaled so its
// faces carry its whole flux (`outflow`). This cell's surface (if any) absorbs block[axis] of each face's
// inflow, on the side the light travels into; the rest is carried on as a uniform intensity over the
// face's cone: dst = 3 / (2 pi) x sum_f carried_f T_f. Absorbed flux (W, per side) goes to acc_plus /
// acc_minus (first_step: written, else added). Six neighbours x six faces, unrolled by the compiler.
#include "diffusion/cell.glsl"

vec3 outflow(ivec3 i, int face) {
    if (!diffusion_inside(i)) {
        return vec3(0.0);
    }
    vec4 r = texelFetch(src_r, i, 0);
    vec4 g = texelFetch(src_g, i, 0);
    vec4 b = texelFetch(src_b, i, 0);
    vec4 block = texelFetch(cell_block, i, 0);
    vec3 through = vec3(0.0);
    vec3 sum = vec3(0.0);
    for (int f = 0; f < 6; f++) {
        vec4 t = diffusion_cone(f);
        vec3 v = diffusion_face_open(block, f) ? max(vec3(dot(r, t), dot(g, t), dot(b, t)), vec3(0.0)) : vec3(0.0);
        sum += v;
        through = f == face ? v : through;
    }
    vec3 total = max(DIFFUSION_FLUX_PER_C0 * vec3(r.x, g.x, b.x), vec3(0.0));
    return mix(vec3(0.0), through * (total / max(sum, vec3(1e-30))), greaterThan(sum, vec3(0.0)));
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 block = texelFetch(cell_block, c, 0);
    bool occupied = diffusion_occupied(block);
    vec3 n = texelFetch(cell_normal, c, 0).xyz;
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    vec3 plus = vec3(0.0), minus = vec3(0.0);
    for (int f = 0; f < 6; f++) {
        vec3 d = diffusion_direction(f);
        vec3 a = outflow(c - ivec3(d), f);
        float absorb = occupied ? block[f >> 1] : 0.0;
        vec3 absorbed = a * absorb;
        vec3 carried = a - absorbed;
        float dn = dot(d, n);
        float to_plus = dn < -DIFFUSION_SIDE_EPSILON ? 1.0 : (dn > DIFFUSION_SIDE_EPSILON ? 0.0 : 0.5);
        plus += absorbed * to_plus;
        minus += absorbed * (1.0 - to_plus);
        vec4 t = diffusion_cone(f) * DIFFUSION_TRANSFER_NORM;
        r += carried.r * t;
        g += carried.g * t;
        b += carried.b * t;
    }
    imageStore(dst_r, c, r);
    imageStore(dst_g, c, g);
    imageStore(dst_b, c, b);
    if (first_step == 0) {
        plus += imageLoad(acc_plus, c).rgb;
        minus += imageLoad(acc_minus, c).rgb;
    }
    imageStore(acc_plus, c, vec4(plus, 0.0));
    imageStore(acc_minus, c, vec4(minus, 0.0));
}
