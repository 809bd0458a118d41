// One texel per `factor` x `factor` block of an RSM face: flux summed (W, exactly what the block's
// VPLs carry), surfel area summed (m^2), position and normal averaged with the flux (luminance) as
// weight -- the block becomes one VPL of the same flux. A block whose texels are all empty stays empty
// (position w = 0); one without flux keeps its texels' plain mean position.
void main() {
    ivec2 out_px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(out_px, imageSize(out_flux)))) {
        return;
    }
    vec3 flux = vec3(0.0);
    vec3 pos_weighted = vec3(0.0);
    vec3 pos_plain = vec3(0.0);
    vec3 normal_weighted = vec3(0.0);
    vec3 normal_plain = vec3(0.0);
    float weight = 0.0;
    float area = 0.0;
    float texels = 0.0;
    for (int j = 0; j < factor; j++) {
        for (int i = 0; i < factor; i++) {
            ivec2 t = out_px * factor + ivec2(i, j);
            vec4 p = texelFetch(rsm_position, t, 0);
            if (p.w == 0.0) {
                continue;
            }
            vec4 n = texelFetch(rsm_normal, t, 0);
            vec3 f = texelFetch(rsm_flux, t, 0).rgb;
            float w = dot(f, vec3(0.2126, 0.7152, 0.0722));
            flux += f;
            pos_weighted += w * p.xyz;
            normal_weighted += w * n.xyz;
            pos_plain += p.xyz;
            normal_plain += n.xyz;
            weight += w;
            area += n.w;
            texels += 1.0;
        }
    }
    if (texels == 0.0) {
        imageStore(out_position, out_px, vec4(0.0));
        imageStore(out_normal, out_px, vec4(0.0));
        imageStore(out_flux, out_px, vec4(0.0));
        return;
    }
    vec3 p = weight > 0.0 ? pos_weighted / weight : pos_plain / texels;
    vec3 n = weight > 0.0 ? normal_weighted : normal_plain;
    float len_n = length(n);
    imageStore(out_position, out_px, vec4(p, 1.0));
    imageStore(out_normal, out_px, vec4(len_n > 0.0 ? n / len_n : vec3(0.0, 0.0, 1.0), area));
    imageStore(out_flux, out_px, vec4(flux, 0.0));
}
