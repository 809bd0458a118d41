// One relocation step per probe (docs/PROBES.md, "Relocation"; the numpy twin is
// probe_grid.relocation_step): from the probe's own capture at its current position (grid position +
// probe_offset.xyz), a new offset.
// Inside a solid (no texel misses, back faces over inside_share of the sphere): out through a back face,
// along its plane's normal to clearance_m beyond it, the offset clamped to +-max_offset_m; an exit counts
// if it ends at least min_exit_m beyond the face and within the occupied bounds [bounds_lo_m,
// bounds_hi_m] (a floor slab's probe leaves into the room even where the slab's bottom is nearer); of
// those, the nearest face's; none: no move (part-way leaves it inside). Otherwise: for each texel whose point lies within clearance_m, in
// capture order, a step along its plane's normal to clearance_m in front of it where the probe is
// nearer (projections onto each near half-space in turn). The offset is clamped to +-max_offset_m per
// axis, so the probe stays in the half cells around its grid position. A change below min_step_m is
// float rounding: none. probe_offset.w := 1 where the probe moved (its tile must be captured again), else 0.
#include "probes/probe.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(probe_offset)))) {
        return;
    }
    ivec3 q = ivec3(px.x, px.y % probe_dims.y, px.y / probe_dims.y);
    int p = probe_index(q);
    int n = face_texels;
    vec3 offset = imageLoad(probe_offset, px).xyz;
    vec3 grid_pos = probe_first + vec3(q) * probe_spacing;
    vec3 pos = grid_pos + offset;
    // The back-face share, whether any texel misses, and the exit through the nearest back face that
    // ends outside it and within the bounds.
    float back = 0.0;
    bool open = false;
    float exit_height = 3.0e38;
    vec3 exit_offset = offset;
    for (int face = 0; face < 6; ++face) {
        ivec2 origin = face_origin(p, face);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                vec4 seen = texelFetch(atlas_position, origin + ivec2(i, j), 0);
                if (seen.w == 0.0) {
                    open = true;
                    continue;
                }
                vec4 nrm = texelFetch(atlas_normal, origin + ivec2(i, j), 0);
                if (nrm.w < 0.0) {
                    back += texel_solid_angle(ivec2(i, j));
                    float height = dot(pos - seen.xyz, nrm.xyz);
                    vec3 out_offset = clamp(offset - nrm.xyz * (height + clearance_m), -max_offset_m, max_offset_m);
                    vec3 end = grid_pos + out_offset;
                    if (height < exit_height && dot(end - seen.xyz, -nrm.xyz) >= min_exit_m
                            && all(greaterThanEqual(end, bounds_lo_m)) && all(lessThanEqual(end, bounds_hi_m))) {
                        exit_height = height;
                        exit_offset = out_offset;
                    }
                }
            }
        }
    }
    vec3 step = vec3(0.0);
    if (!open && back > inside_share * 4.0 * 3.14159265) {
        step = exit_offset - offset;  // 0 where no exit counts
    } else {
        for (int face = 0; face < 6; ++face) {
            ivec2 origin = face_origin(p, face);
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    vec4 seen = texelFetch(atlas_position, origin + ivec2(i, j), 0);
                    if (seen.w == 0.0 || distance(seen.xyz, pos) >= clearance_m) {
                        continue;
                    }
                    vec3 nrm = texelFetch(atlas_normal, origin + ivec2(i, j), 0).xyz;
                    float height = dot(pos + step - seen.xyz, nrm);
                    if (height < clearance_m) {
                        step += nrm * (clearance_m - height);
                    }
                }
            }
        }
    }
    vec3 moved = clamp(offset + step, -max_offset_m, max_offset_m);
    vec3 change = abs(moved - offset);
    bool moves = max(change.x, max(change.y, change.z)) > min_step_m;
    imageStore(probe_offset, px, moves ? vec4(moved, 1.0) : vec4(offset, 0.0));
}
