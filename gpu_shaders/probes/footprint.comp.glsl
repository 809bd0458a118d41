// Where a probe atlas texel's footprint on its surface is long (the surface seen at a grazing angle),
// what the direct pass needs to shade points along it (direct/shade.comp.glsl, AREA_SAMPLES), once per
// geometry change so that the per-light pass needs no grid uniforms:
//   footprint_origin = (the probe's position (m), t_lo), footprint_step = (step, t_hi),
//   footprint_neighbours = (the atlas offset of the neighbour nearer the probe, of the one farther)
// step: the change of the texel's unnormalised ray direction (forward + s right + t up) across the
// texel along the face axis that turns the ray against the surface's plane most (0 where the texel does
// not graze, |n . w| >= GRAZING_COS, or sees nothing). Its two neighbours along that axis bound how far
// the plane may be followed: t_lo, t_hi (m) are the least and greatest distances they and the texel see.
// A neighbour that sees nothing, or lies on another face, bounds nothing (offset (0, 0)): the plane
// stops at the texel's own distance on that side.
#include "probes/probe.glsl"

const float GRAZING_COS = 0.25;  // |n . w| below which a texel's footprint is over 4 texels long

// The distance from probe position o to the surface atlas texel t sees (0 where it sees none).
float seen_distance(ivec2 t, vec3 o) {
    vec4 q = texelFetch(atlas_position, t, 0);
    return q.w > 0.0 ? length(q.xyz - o) : 0.0;
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(footprint_origin)))) {
        return;
    }
    int probe = atlas_probe(px);
    vec4 pos = texelFetch(atlas_position, px, 0);
    if (probe >= probe_count() || pos.w == 0.0) {
        imageStore(footprint_origin, px, vec4(0.0));
        imageStore(footprint_step, px, vec4(0.0));
        imageStore(footprint_neighbours, px, vec4(0.0));
        return;
    }
    ivec2 local = px - tile_origin(probe, 0, face_texels);
    int face = local.x / face_texels + 3 * (local.y / face_texels);
    ivec2 ij = local % face_texels;
    vec3 o = probe_position(probe_cell(probe));
    vec3 n = texelFetch(atlas_normal, px, 0).xyz;
    float t_centre = length(pos.xyz - o);
    vec3 step = vec3(0.0);
    float t_lo = t_centre;
    float t_hi = t_centre;
    ivec2 near = ivec2(0);
    ivec2 far = ivec2(0);
    if (abs(dot(face_direction(face, texel_st(ij)), n)) < GRAZING_COS) {
        vec3 f, r, u;
        face_frame(face, f, r, u);
        bool along_t = abs(dot(u, n)) > abs(dot(r, n));
        ivec2 axis = along_t ? ivec2(0, 1) : ivec2(1, 0);
        step = (along_t ? u : r) * (2.0 / float(face_texels));
        for (int side = -1; side <= 1; side += 2) {
            ivec2 k = ij + side * axis;
            if (all(greaterThanEqual(k, ivec2(0))) && all(lessThan(k, ivec2(face_texels)))) {
                float d = seen_distance(px + side * axis, o);
                if (d > 0.0 && d < t_lo) {
                    t_lo = d;
                    near = side * axis;
                }
                if (d > t_hi) {
                    t_hi = d;
                    far = side * axis;
                }
            }
        }
    }
    imageStore(footprint_origin, px, vec4(o, t_lo));
    imageStore(footprint_step, px, vec4(step, t_hi));
    imageStore(footprint_neighbours, px, vec4(vec2(near), vec2(far)));
}
