// Before a moved probe is captured again: every texel of its tile set to 0 (probe_offset.w = 1 marks it,
// probes/relocate.comp.glsl), so a direction that saw geometry from the old position and sees none from
// the new one reads empty. Other probes' tiles are kept: their capture still holds.
#include "probes/probe.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(atlas_position)))) {
        return;
    }
    int p = atlas_probe(px);
    if (p >= probe_count()) {
        return;
    }
    ivec3 q = probe_cell(p);
    if (texelFetch(probe_offset, ivec2(q.x, probe_row(q)), 0).w == 0.0) {
        return;
    }
    imageStore(atlas_position, px, vec4(0.0));
    imageStore(atlas_normal, px, vec4(0.0));
    imageStore(atlas_albedo, px, vec4(0.0));
}
