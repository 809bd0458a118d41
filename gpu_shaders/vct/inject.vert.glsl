// VCT injection: one point per RSM texel (a VPL of reflected flux phi, W, and normal n) splatted into
// the tile of the flux atlas that holds its cell's z-layer (vct_inject.py: layer z is tile
// (z % tiles_x, z / tiles_x), one texel per cell). Six outputs, one per axis direction t of travel
// (+x, -x, +y, -y, +z, -z): phi * max(0, n.t), the part of the Lambertian VPL's light leaving along t
// (its projection on the axis lobes; level0.comp.glsl turns it into premultiplied radiance).
void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec3 n = texelFetch(rsm_normal, t, 0).xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    ivec3 cell = ivec3(floor((pos.xyz - grid_origin) / cell_size));
    bool inside = all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, dims));
    if (pos.w == 0.0 || !inside) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // clipped
    } else {
        ivec2 tile = ivec2(cell.z % tiles_x, cell.z / tiles_x);
        vec2 px = vec2(tile * dims.xy + cell.xy) + 0.5;
        gl_Position = vec4(px / vec2(atlas_size) * 2.0 - 1.0, 0.0, 1.0);
    }
    v_pos = phi * max(n.x, 0.0);
    v_neg = phi * max(-n.x, 0.0);
    v_pos_y = phi * max(n.y, 0.0);
    v_neg_y = phi * max(-n.y, 0.0);
    v_pos_z = phi * max(n.z, 0.0);
    v_neg_z = phi * max(-n.z, 0.0);
}
