// LPV injection, second half: the injection atlas (z-layer z is tile (z % tiles_x, z / tiles_x), one
// texel per cell) copied into the 3D snapshot volumes that propagation reads; from the atlas's copy of
// the grid whose first layer is first_layer (one emitter class's block, or 0).
#include "common/atlas.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    ivec2 at = atlas_texel(c + ivec3(0, 0, first_layer));
    imageStore(sh_r, c, texelFetch(atlas_r, at, 0));
    imageStore(sh_g, c, texelFetch(atlas_g, at, 0));
    imageStore(sh_b, c, texelFetch(atlas_b, at, 0));
}
