// Per probe atlas texel (the capture's n x n faces): the radiance it brings (probes/radiance.glsl:
// albedo x (direct [+ the previous bounces' indirect]), W/m^2/sr; w = 1 where the texel sees geometry)
// and where its own surface lies along its four corner directions: the distance (m) from the probe to
// the plane through the texel's surface point with its normal, along each corner's direction (order of
// corner_offset). For a planar surface these are the exact corners of the piece the texel sees, so a
// quad rebuilt from them lies on the surface (paper 001's distance correction). Where the plane is seen
// edge-on the intersection runs off: each distance is held within [1 / GRAZING_LIMIT, GRAZING_LIMIT] x
// the texel's own distance.
#include "probes/probe.glsl"
#include "probes/radiance.glsl"
#include "gather/quad.glsl"

// At 8^2 texels a face a texel spans ~11 degrees: a plane within 20 degrees of edge-on stretches its
// far corner past 4 x its centre's distance, where a texel's one normal no longer says where the
// surface is.
const float GRAZING_LIMIT = 4.0;

float plane_distance(vec3 surface_rel, vec3 normal, vec3 dir, float centre) {
    // The normal faces the probe, so along a direction that meets the plane in front of the probe both
    // dot products are negative.
    float along = dot(normal, dir);
    float t = along < 0.0 ? dot(normal, surface_rel) / along : centre * GRAZING_LIMIT;
    return clamp(t, centre / GRAZING_LIMIT, centre * GRAZING_LIMIT);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(fine_radiance)))) {
        return;
    }
    int n = face_texels;
    ivec2 tile = px / ivec2(3 * n, 2 * n);
    int p = tile.x + tiles_per_row * tile.y;
    vec4 pos = texelFetch(atlas_position, px, 0);
    if (p >= probe_count() || pos.w == 0.0) {
        imageStore(fine_radiance, px, vec4(0.0));
        imageStore(fine_corners, px, vec4(0.0));
        return;
    }
    ivec2 in_tile = px - tile * ivec2(3 * n, 2 * n);
    int face = (in_tile.x / n) + 3 * (in_tile.y / n);
    ivec2 ij = px - face_origin(p, face);
    vec3 rel = pos.xyz - probe_position(probe_cell(p));
    vec3 normal = texelFetch(atlas_normal, px, 0).xyz;
    float centre = max(length(rel), 1e-6);
    vec4 corners;
    for (int c = 0; c < 4; ++c) {
        vec3 dir = normalize(corner_point(face, ij + corner_offset(c), n));
        corners[c] = plane_distance(rel, normal, dir, centre);
    }
    imageStore(fine_radiance, px, vec4(texel_radiance(px), 1.0));
    imageStore(fine_corners, px, corners);
}
