// The radiance (W/m^2/sr) a probe's atlas texel t brings it: albedo x (direct + indirect), the light a
// Lambertian surface reflects (direct = irradiance / pi from the direct pass; indirect, with BOUNCE, the
// previous bounce's irradiance / pi read from the probe field); 0 where the texel sees no geometry
// (the world's light is direct light, not a bounce). Samplers: atlas_albedo, atlas_direct
// [, atlas_indirect].
vec3 texel_radiance(ivec2 t) {
    vec4 albedo = texelFetch(atlas_albedo, t, 0);
    if (albedo.w == 0.0) {
        return vec3(0.0);
    }
    vec3 light = texelFetch(atlas_direct, t, 0).rgb;
#ifdef BOUNCE
    light += texelFetch(atlas_indirect, t, 0).rgb;
#endif
    return albedo.rgb * light;
}
