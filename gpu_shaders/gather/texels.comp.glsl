// Per probe atlas texel (the capture's n x n faces): the radiance it brings (probes/radiance.glsl:
// albedo x (direct [+ the previous bounces' indirect]), W/m^2/sr; w = 1 where the texel sees geometry
// that faces the probe by more than EDGE_ON) and the plane of the surface it sees, relative to the
// probe: (unit normal towards the probe, n . (surface point - probe)). Where the surface is flat, that
// plane cut by the texel's four corner directions (gather/quad.glsl, plane_corner) is exactly the piece
// of it the texel sees: paper 001's distance correction, per texel.
#include "probes/probe.glsl"
#include "probes/radiance.glsl"
#include "gather/quad.glsl"

// A surface seen within 0.06 degrees of edge-on has no area to speak of from the probe, and its plane
// offset (~0) cannot place it.
const float EDGE_ON = 1e-3;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(fine_radiance)))) {
        return;
    }
    int p = atlas_probe(px);
    vec4 pos = texelFetch(atlas_position, px, 0);
    vec3 rel = pos.xyz - (p < probe_count() ? probe_position(probe_cell(p)) : vec3(0.0));
    vec3 normal = texelFetch(atlas_normal, px, 0).xyz;
    // Written so that a surface at the probe itself (rel = 0, which the face's near plane should not
    // let through) fails the test too, instead of a NaN passing it.
    if (p >= probe_count() || pos.w == 0.0 || !(dot(normal, rel) < -EDGE_ON * length(rel))) {
        imageStore(fine_radiance, px, vec4(0.0));
        imageStore(fine_plane, px, vec4(0.0));
        return;
    }
    imageStore(fine_radiance, px, vec4(texel_radiance(px), 1.0));
    imageStore(fine_plane, px, vec4(normal, dot(normal, rel)));
}
