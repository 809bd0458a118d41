// Copies a 3D texture into a 2D atlas, layer z at rows [z * h, (z + 1) * h): Blender's
// GPUTexture.read() returns only one layer of a 3D texture, so 3D read-back goes through this.
void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    ivec3 size = textureSize(volume, 0);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    imageStore(atlas, ivec2(p.x, p.z * size.y + p.y), texelFetch(volume, p, 0));
}
