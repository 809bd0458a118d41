// Diffusion far field, source: each coarse cell's emitted flux per side of its plane, the sum of its
// 2 x 2 x 2 fine cells' (passes/diffusion_far_field.py; twin: diffusion_reference.far_source). A fine
// side's flux goes to the coarse side its normal agrees with (the plus side where the two normals are
// at most 90 degrees apart); an empty fine cell's (a VPL whose surface fell in no occupied cell) half to
// each, as the coarse emit turns an empty cell's into isotropic light anyway. ATLAS: the fine flux is
// the injection atlas (the first bounce: reflected light already), else volumes of absorbed flux times
// the fine voxels' albedo. `dims` are the fine grid's (atlas_texel and diffusion_inside read them); the
// dispatch covers coarse_dims; fine cells beyond the fine grid (odd dims) hold nothing.
#include "diffusion/cell.glsl"
#ifdef ATLAS
#include "common/atlas.glsl"
#endif

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, coarse_dims))) {
        return;
    }
    vec3 coarse_n = texelFetch(coarse_normal, c, 0).xyz;
    vec3 plus = vec3(0.0), minus = vec3(0.0);
    for (int k = 0; k < 8; ++k) {
        ivec3 f = 2 * c + ivec3(k & 1, (k >> 1) & 1, k >> 2);
        if (!diffusion_inside(f)) {
            continue;
        }
#ifdef ATLAS
        ivec2 at = atlas_texel(f);
        vec3 fp = texelFetch(flux_plus, at, 0).rgb;
        vec3 fm = texelFetch(flux_minus, at, 0).rgb;
#else
        vec3 albedo = texelFetch(vox_albedo, f, 0).rgb;
        vec3 fp = texelFetch(flux_plus, f, 0).rgb * albedo;
        vec3 fm = texelFetch(flux_minus, f, 0).rgb * albedo;
#endif
        if (diffusion_occupied(texelFetch(cell_block, f, 0))) {
            bool agrees = dot(texelFetch(cell_normal, f, 0).xyz, coarse_n) >= 0.0;
            plus += agrees ? fp : fm;
            minus += agrees ? fm : fp;
        } else {
            plus += 0.5 * (fp + fm);
            minus += 0.5 * (fp + fm);
        }
    }
    imageStore(coarse_plus, c, vec4(plus, 0.0));
    imageStore(coarse_minus, c, vec4(minus, 0.0));
}
