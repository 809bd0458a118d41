// Specular cones at every camera pixel: the light the glossy lobe reflects towards the camera, in the
// image's own units (Cycles' Glossy Color x Glossy Indirect).
//
// `specular_cones` directions sample the GGX lobe: half vectors from D(h) n.h, stratified in the polar
// variable and turned by a per-pixel random angle, reflected about the view. Each sample weighs
// G2(v, l) v.h / n.h (f cos / pdf without the Fresnel and constant factors) and reads the mean radiance
// of a cone whose solid angle is its share of the lobe, 1 / (N pdf(l)) (filtered importance sampling,
// Krivanek and Colbert 2008; `aperture_scale` multiplies it): a mirror's samples all coincide in one
// cone a voxel wide, a rough lobe's spread over its tails. One cone as wide as the lobe's half maximum
// read 0.6 of Cycles on satin boxes: GGX's tails reach far outside it.
// The weighted mean radiance times the lobe's albedo (F0 A + B) x the multiple-scattering factor
// (addon/engine/brdf.py; split_albedo holds A, B at (n.v, roughness)) is the reflected light. Pixels
// whose F0 is 0 (no glossy lobe) trace nothing.
#include "vct/cone.glsl"
#include "common/pixel_pattern.glsl"

float smith_lambda(float cos_theta, float alpha) {
    float c2 = clamp(cos_theta * cos_theta, 1e-6, 1.0);
    return 0.5 * (sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2) - 1.0);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(glossy)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    vec4 spec = texelFetch(gbuf_specular, px, 0);
    if (pos.w == 0.0 || max(spec.r, max(spec.g, spec.b)) <= 0.0) {
        imageStore(glossy, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    vec3 v = normalize(camera_pos_ws - pos.xyz);
    float n_dot_v = clamp(dot(n, v), 1e-4, 1.0);
    float roughness = clamp(spec.a, 0.0, 1.0);
    float alpha = max(roughness * roughness, 1e-4);
    float a2 = alpha * alpha;
    vec3 tx, ty;
    tangent_frame(n, tx, ty);
    vec3 g0 = (pos.xyz - grid_origin) / cell_size + offset_cells * n;
    // (jitter, rotation, dither): the image's random numbers plus the pixel pattern, as the diffuse
    // gather's (common/pixel_pattern.glsl). A refinement gather comes with a new seed (gather_seed), so
    // its numbers are new for the whole image. cornell-glossy at 128 px, the glossy product's rel_rmse
    // between seeds 2j and 2j + 1 (j < 4, root mean square; over the pixels any seed lights): one
    // update 0.088 -> 0.087 (its light is a few bright reflections), 16 gathers 0.0258 -> 0.0212,
    // against each pixel's own random numbers.
    uint s = uint(seed) * 2u + 1u;
    vec3 image_random = vec3(random01(0u, 0u, s), random01(0u, 0u, s + 1u),
                             random01(0u, 0u, hash_u32(s ^ DITHER_STREAM)));
    vec3 draw = fract(image_random + pixel_pattern(px, 0));
    float jitter = draw.x, rotation = 6.28318531 * draw.y, dither = draw.z;
    float lambda_v = smith_lambda(n_dot_v, alpha);
    vec3 radiance = vec3(0.0);
    float weights = 0.0;
    for (int i = 0; i < specular_cones; i++) {
        float u1 = (float(i) + jitter) / float(specular_cones);
        float tan2_h = a2 * u1 / max(1.0 - u1, 1e-6);
        float cos_h = inversesqrt(1.0 + tan2_h);
        float sin_h = sqrt(max(1.0 - cos_h * cos_h, 0.0));
        float phi = 2.39996323 * float(i) + rotation;
        vec3 h = tx * (sin_h * cos(phi)) + ty * (sin_h * sin(phi)) + n * cos_h;
        float v_dot_h = dot(v, h);
        vec3 l = 2.0 * v_dot_h * h - v;
        float n_dot_l = dot(n, l);
        if (n_dot_l <= 0.0 || v_dot_h <= 0.0) {
            continue;  // below the surface: G2 = 0
        }
        float d_denominator = cos_h * cos_h * (a2 - 1.0) + 1.0;
        float ndf = a2 / (3.14159265 * d_denominator * d_denominator);
        float pdf_l = ndf * cos_h / (4.0 * v_dot_h);
        float solid_angle = aperture_scale / (float(specular_cones) * max(pdf_l, 1e-6));
        // A cone of solid angle w has cos(half angle) = 1 - w / (2 pi); at most 60 degrees.
        float cos_half = max(1.0 - solid_angle / 6.28318531, 0.5);
        float tan_half = sqrt(max(1.0 - cos_half * cos_half, 0.0)) / cos_half;
        float weight = v_dot_h / (cos_h * (1.0 + lambda_v + smith_lambda(n_dot_l, alpha)));
        float u = fract(dither + 0.61803399 * float(i));
        radiance += weight * trace_cone(g0, l, tan_half, n_dot_l, side_cap, u).rgb;
        weights += weight;
    }
    vec3 mean_radiance = weights > 0.0 ? radiance / weights : vec3(0.0);
    vec2 ab = texture(split_albedo, vec2(n_dot_v, roughness)).rg;
    vec3 f0 = spec.rgb;
    float e = max(ab.x + ab.y, 1e-4);
    vec3 reflectance = (f0 * ab.x + ab.y) * (1.0 + f0 * (1.0 - e) / e);
    imageStore(glossy, px, vec4(mean_radiance * reflectance, 1.0));
}
