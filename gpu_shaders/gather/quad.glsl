// The quads of method `gather` (paper 001; docs/GATHER.md): texel corners on a probe's cube faces.
// Needs probes/probe.glsl. A face of n x n texels has (n + 1)^2 corners; corner (k, l) lies at the
// face-plane point forward + s right + t up with s = (2k - n) / n, t = (2l - n) / n. Written so, the
// coordinates are exact negatives of each other where two faces share an edge, and a corner gets the
// same direction from every face that holds it.

// Corner c (0..3) of a texel, counter-clockwise about the face's forward axis (right x up = forward):
// (0, 0), (1, 0), (1, 1), (0, 1) in (column, row) offsets from the texel's own index.
ivec2 corner_offset(int c) {
    return ivec2((c == 1 || c == 2) ? 1 : 0, c >= 2 ? 1 : 0);
}

// The corner index of offset o in {0, 1}^2 (the inverse of corner_offset).
int corner_of_offset(ivec2 o) {
    return o.y == 0 ? o.x : 3 - o.x;
}

// The unnormalised direction of corner k of a face of n texels a side: a point on the cube [-1, 1]^3.
vec3 corner_point(int face, ivec2 k, int n) {
    vec3 f, r, u;
    face_frame(face, f, r, u);
    return f + (float(2 * k.x - n) / float(n)) * r + (float(2 * k.y - n) / float(n)) * u;
}
