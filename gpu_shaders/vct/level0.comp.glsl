// Level 0 of the radiance pyramid from the flux atlas (and, with ADD, plus premultiplied radiance
// from later bounces): per cell and travel direction t,
//   colour  c_t = atlas_weight * flux_t / (pi h^2) + add_t
//   opacity a_t = min(1, projected area of the cell's surface along t's axis / h^2).
// A Lambertian surfel of flux phi has radiance phi / (pi A); seen along t it covers A |n.t| of the
// cell's h^2 cross-section, so its premultiplied radiance is phi |n.t| / (pi h^2): what the atlas
// summed (phi max(0, n.t)) over pi h^2. ISOTROPIC gives every direction one radiance, the cell's
// premultiplied colours summed over the opacities they were premultiplied by, and premultiplies it
// again by each direction's opacity: the six colours keep their sum (no energy made or lost), and a
// direction that sees no surface stays empty (a floor seen edge-on has no colour to give a cone).
// A cell with light but no surface (seen = 0) keeps its six colours. Stored x radiance_scale (vct_pyramid.radiance_scale: the first bounce's colours
// stay below HALF_BOUND), clamped to half_clamp so that later bounces' light, whose bound is not
// proven, cannot overflow the half floats.
#include "common/atlas.glsl"
#include "vct/pyramid.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    ivec2 at = atlas_texel(c);
    float to_radiance = atlas_weight / (3.14159265 * cell_size * cell_size);
    vec3 col[6];
    col[0] = texelFetch(flux_px, at, 0).rgb * to_radiance;
    col[1] = texelFetch(flux_nx, at, 0).rgb * to_radiance;
    col[2] = texelFetch(flux_py, at, 0).rgb * to_radiance;
    col[3] = texelFetch(flux_ny, at, 0).rgb * to_radiance;
    col[4] = texelFetch(flux_pz, at, 0).rgb * to_radiance;
    col[5] = texelFetch(flux_nz, at, 0).rgb * to_radiance;
#ifdef ADD
    col[0] += texelFetch(add_px, c, 0).rgb;
    col[1] += texelFetch(add_nx, c, 0).rgb;
    col[2] += texelFetch(add_py, c, 0).rgb;
    col[3] += texelFetch(add_ny, c, 0).rgb;
    col[4] += texelFetch(add_pz, c, 0).rgb;
    col[5] += texelFetch(add_nz, c, 0).rgb;
#endif
    vec3 opacity = min(texelFetch(vox_projected, c, 0).xyz, vec3(1.0));
#ifdef ISOTROPIC
    float seen = 2.0 * (opacity.x + opacity.y + opacity.z);
    if (seen > 0.0) {  // else no surface to spread over: the colours stay as injected
        vec3 radiance = (col[0] + col[1] + col[2] + col[3] + col[4] + col[5]) / seen;
        for (int i = 0; i < 6; i++) {
            col[i] = radiance * opacity[i / 2];
        }
    }
#endif
    for (int i = 0; i < 6; i++) {
        col[i] = min(col[i] * radiance_scale, vec3(half_clamp));
    }
    imageStore(pyr_px, c, vec4(col[0], opacity.x));
    imageStore(pyr_nx, c, vec4(col[1], opacity.x));
    imageStore(pyr_py, c, vec4(col[2], opacity.y));
    imageStore(pyr_ny, c, vec4(col[3], opacity.y));
    imageStore(pyr_pz, c, vec4(col[4], opacity.z));
    imageStore(pyr_nz, c, vec4(col[5], opacity.z));
}
