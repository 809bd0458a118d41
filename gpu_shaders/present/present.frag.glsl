// Light added to the viewport, blended (ONE, ONE): albedo x (w_direct E_direct + w_indirect E_indirect)
// x scale. E_* are in Cycles' Diffuse Direct/Indirect units (light / diffuse colour), so multiplying by
// the G-buffer albedo gives reflected radiance; scale = 2^exposure x strength. Where the G-buffer saw no
// geometry its albedo is 0, so nothing is added there. Alpha 0: the viewport's alpha stays as it is.
// use_albedo = 0 shows indirect_tex as it is (the voxel debug view is a colour, not light). glossy_tex
// is reflected radiance already (the vct method's glossy product), added as it is with weight w_glossy.
void main() {
    vec3 albedo = mix(vec3(1.0), texture(albedo_tex, uv).rgb, use_albedo);
    vec3 light = w_direct * texture(direct_tex, uv).rgb + w_indirect * texture(indirect_tex, uv).rgb;
    frag_color = vec4((albedo * light + w_glossy * texture(glossy_tex, uv).rgb) * scale, 0.0);
}
