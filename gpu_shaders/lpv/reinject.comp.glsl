// LPV re-injection (the next bounce), gather form: every cell A with geometry reflects the light the
// previous bounce brings to its surface, as a Lambertian emitter placed in the neighbours it faces.
// Cell B writes what its 6 neighbours A = B - d send it; one invocation per cell, 6 iterations.
//
// A's surface (voxelizer: mean normal n, area w in cells^2, albedo rho) receives on its side facing m
// (m = n or -n) E_m = max(0, c(p) . cosine_lobe(-m)) / h^2 with c trilinear at p = centre + 0.5 h m
// over the corners that do not block along m (see arriving(); lookup.comp.glsl weighs its corners the
// same way): a cell's own light is mostly what its surface sent away, not light arriving at it.
// Voxel normals of one-sided meshes do not say which side is lit, so A reflects from the side that
// receives more (the inside of a closed solid and the outside of a room stay dark; L1 reads ~0 behind
// a one-sided field). It reflects
// phi = rho * E_m * w h^2 = rho * w * max(0, c . cosine_lobe(-m)) watts (h^2 cancels), emitted as
// phi / pi * cosine_lobe(m) (flux 2 sqrt(pi) c0 = phi, as inject.vert.glsl does for a VPL), split over
// the neighbours B = A + d by max(0, m.d) / |m|_1 (a partition of unity over the 6 axes: phi is kept).
// Not in A itself: A's own geometry volume would block half of it on the first step out.
// Emitter classes (docs/LPV.md): OWN_PASS runs once per class with that class's light alone in acc_*
// and writes, at the cells whose side n (own_front) or -n (own_back) is of class `emitter`, the signed
// reading arriving() makes there before its clamp; OWN_LIGHT subtracts those from the total's reading
// before the clamp, so a surface's re-emission counts no light from surfaces facing its way (a lit
// floor's own upward light no longer cancels the light arriving at it).
#include "common/sh.glsl"
#ifdef OWN_PASS
#include "lpv/emitter_class.glsl"
#endif

// E_m * h^2 per colour: the previous bounce's light arriving at cell c's surface on the side facing m.
// Trilinear at c's centre + m / 2 over the corners that do not block along m (1 - min(1, projected
// area along m)), renormalised: c's own surface blocks, so c's own light -- mostly what its surface
// emitted the other way -- is not read as arriving; 0 where every corner blocks (inside a solid).
vec3 arriving_signed(ivec3 c, vec3 m) {
    vec3 t = vec3(c) + 0.5 * m;  // cell-index space: centres at integers
    ivec3 i0 = ivec3(floor(t));
    vec3 f = t - vec3(i0);
    vec4 lobe = sh_cosine_lobe(-m);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        vec3 wv = mix(1.0 - f, f, vec3(corner));
        float w = wv.x * wv.y * wv.z;
        if (w == 0.0) {
            continue;
        }
        ivec3 q = clamp(i0 + corner, ivec3(0), dims - 1);
        float through = 1.0 - min(1.0, dot(texelFetch(vox_projected, q, 0).xyz, abs(m)));
        sum += (w * through) * vec3(dot(texelFetch(acc_r, q, 0), lobe), dot(texelFetch(acc_g, q, 0), lobe),
                                    dot(texelFetch(acc_b, q, 0), lobe));
        weight += w * through;
    }
    return weight > 1e-4 ? sum / weight : vec3(0.0);
}

#ifndef OWN_PASS
// arriving_signed less `own` (the reading of the surfaces facing the same way), clamped at 0.
vec3 arriving(ivec3 c, vec3 m, vec3 own) {
    return max(arriving_signed(c, m) - own, vec3(0.0));
}


// The flux (W, rgb) cell a reflects and the side m it reflects to; zero without a surface: empty cells
// have w = 0, and opposite faces in one cell cancel to n = 0.
vec3 reflected(ivec3 a, out vec3 m) {
    vec4 nv = texelFetch(vox_normal, a, 0);
    m = vec3(0.0);
    if (nv.w <= 0.0 || dot(nv.xyz, nv.xyz) == 0.0) {
        return vec3(0.0);
    }
#ifdef OWN_LIGHT
    vec3 own_f = texelFetch(own_front, a, 0).rgb;
    vec3 own_b = texelFetch(own_back, a, 0).rgb;
#else
    vec3 own_f = vec3(0.0);
    vec3 own_b = vec3(0.0);
#endif
    vec3 e_front = arriving(a, nv.xyz, own_f);
    vec3 e_back = arriving(a, -nv.xyz, own_b);
    bool front = dot(e_front, vec3(1.0)) >= dot(e_back, vec3(1.0));
    m = front ? nv.xyz : -nv.xyz;
    return texelFetch(vox_albedo, a, 0).rgb * nv.w * (front ? e_front : e_back);
}

void main() {
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, dims))) {
        return;
    }
    vec4 out_r = vec4(0.0);
    vec4 out_g = vec4(0.0);
    vec4 out_b = vec4(0.0);
    for (int k = 0; k < 6; ++k) {
        ivec3 d = ivec3(0);
        d[k / 2] = (k % 2 == 0) ? 1 : -1;
        ivec3 a = b - d;
        if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, dims))) {
            continue;
        }
        vec3 m;
        vec3 phi = reflected(a, m);
        if (phi == vec3(0.0)) {
            continue;  // also m = 0, where the share below would divide by zero
        }
        float share = max(dot(m, vec3(d)), 0.0) / dot(abs(m), vec3(1.0));
        vec4 lobe = sh_cosine_lobe(m) * (share / SH_A0);
        out_r += phi.r * lobe;
        out_g += phi.g * lobe;
        out_b += phi.b * lobe;
    }
    imageStore(sh_r, b, out_r);
    imageStore(sh_g, b, out_g);
    imageStore(sh_b, b, out_b);
}
#else
void main() {
    ivec3 a = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(a, dims))) {
        return;
    }
    vec4 nv = texelFetch(vox_normal, a, 0);
    if (nv.w <= 0.0 || dot(nv.xyz, nv.xyz) == 0.0) {
        return;  // no surface: never read
    }
    if (emitter_class(nv.xyz) == emitter) {
        imageStore(own_front, a, vec4(arriving_signed(a, nv.xyz), 0.0));
    }
    if (emitter_class(-nv.xyz) == emitter) {
        imageStore(own_back, a, vec4(arriving_signed(a, -nv.xyz), 0.0));
    }
}
#endif
